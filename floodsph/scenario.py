"""The scenario: one TOML file, read into frozen, validated dataclasses.

``load_scenario(path)`` parses the file (stdlib ``tomllib``), rejects unknown keys, wrong types
and impossible values with one message naming the file and the key path, resolves relative
paths against the scenario file's folder and fills the defaults of the contract
(``docs``: ``scenario-format.md``). Nothing else in floodsph reads the TOML; everything reads
the :class:`Scenario`.

Coordinates stay in the DEM's CRS here; they are shifted to the terrain's local origin only
when the model is built (``floodsph.run``).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, fields
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING

from floodsph.checks.elevation import ELEVATION_LIMIT_M
from floodsph.checks.roughness import N_DEFAULT, N_STRICKLER, strickler_text
from floodsph.errors import InputError
from floodsph.numerics import SCENARIO_KEYS as NUMERICS_KEYS
from floodsph.numerics import Numerics, NumericsError
from floodsph.scenario_schema import Reader, describe, join

if TYPE_CHECKING:
    from floodsph.breach.params import BreachParams

Point = tuple[float, float]


class Edges(Enum):
    """What happens at the DEM border: water leaves (``open``) or is reflected (``closed``)."""

    OPEN = "open"
    CLOSED = "closed"


class OutputFormat(Enum):
    """Map file formats written at the end of a run."""

    GEOTIFF = "geotiff"
    NETCDF = "netcdf"


@dataclass(frozen=True)
class ScenarioInfo:
    """``[scenario]``: the name (also the default output folder) and the simulated time [s]."""

    name: str
    end_time_s: float
    description: str = ""


@dataclass(frozen=True)
class TerrainConfig:
    """``[terrain]``: the DEM and the bed roughness (a uniform n, an n raster or land cover).

    ``manning`` is None when the roughness comes from ``landcover`` (+ ``manning_table``: a
    CSV path, or ``"worldcover"`` for the shipped ESA WorldCover table).
    """

    dem: Path
    crs: str | None = None
    dem_variable: str | None = None
    manning: float | Path | None = N_DEFAULT
    landcover: Path | None = None
    manning_table: Path | str | None = None
    extent: tuple[float, float, float, float] | None = None
    edges: Edges = Edges.OPEN
    closed_sides: tuple[str, ...] = ()

    @property
    def nodata_walled(self) -> bool:
        """True when the DEM's nodata border is a wall: edges closed, or any side kept closed
        (``floodsph.model.FloodModel`` walls nodata unless every edge is open)."""
        return self.edges is Edges.CLOSED or bool(self.closed_sides)


@dataclass(frozen=True)
class InitialWater:
    """``[[initial_water]]``: a free-surface level inside a polygon, or a depth raster.

    The polygons may come from a vector ``file`` (+ ``layer``, ``crs``) instead of
    ``polygon`` (``floodsph.io.vector``); ``feature`` names the feature of such a file a
    body was read from (``floodsph.vector_inputs``).
    """

    level_m: float | None = None
    polygon: tuple[Point, ...] | None = None
    depth: Path | None = None
    file: Path | None = None
    layer: str | None = None
    crs: str | None = None
    feature: str | None = None


@dataclass(frozen=True)
class Wall:
    """``[[walls]]``: a polyline water cannot cross (closed: a solid footprint), or the lines
    and polygon outlines of a vector ``file`` (+ ``layer``, ``crs``; see InitialWater)."""

    polyline: tuple[Point, ...] | None = None
    file: Path | None = None
    layer: str | None = None
    crs: str | None = None
    feature: str | None = None

    @property
    def closed(self) -> bool:
        return self.polyline[0] == self.polyline[-1]


@dataclass(frozen=True)
class Inflow:
    """``[[inflows]]``: a breach section with a discharge hydrograph Q(t) [m3/s].

    ``hydrograph`` is the CSV of Q(t) (read by ``floodsph.inputs``, as every file the scenario
    names); ``breach`` the validated ``[inflows.breach]`` table of a parametric breach
    (``floodsph.breach.params.BreachParams``, file paths absolute), routed into Q(t) there.

    ``direction`` (optional) is the flow direction [dx, dy]; by default water enters normal
    to ``line`` towards lower ground.
    """

    line: tuple[Point, Point]
    hydrograph: Path | None = None
    breach: BreachParams | None = None
    direction: Point | None = None


@dataclass(frozen=True)
class Sink:
    """``[[sinks]]``: a polygon where water leaves the model (counted as outflow), or the
    polygons of a vector ``file`` (+ ``layer``, ``crs``; see InitialWater)."""

    polygon: tuple[Point, ...] | None = None
    file: Path | None = None
    layer: str | None = None
    crs: str | None = None
    feature: str | None = None


@dataclass(frozen=True)
class Gauges:
    """``[gauges]``: a CSV of points (id, x, y), or a vector file of points (+ ``layer``,
    ``crs``, and ``id_field``, the attribute naming each gauge), sampled every
    ``interval_s`` seconds."""

    file: Path
    interval_s: float = 10.0
    layer: str | None = None
    crs: str | None = None
    id_field: str | None = None


@dataclass(frozen=True)
class OutputConfig:
    """``[output]``: where and what to write. ``directory = None`` means ``out/<name>``.

    ``checkpoint_interval_s`` [s of simulated time] > 0 writes a checkpoint at the first step
    at or after each multiple of it (``floodsph.checkpoint``); 0 writes none on a schedule
    (a stop signal still writes one).
    """

    directory: Path | None = None
    resolution_m: float | None = None
    wet_threshold_m: float = 0.01
    formats: tuple[OutputFormat, ...] = (OutputFormat.GEOTIFF, OutputFormat.NETCDF)
    snapshot_interval_s: float = 0.0
    mass_balance_interval_s: float = 10.0
    checkpoint_interval_s: float = 0.0


@dataclass(frozen=True)
class Scenario:
    """One validated scenario; ``path`` is the (absolute) scenario file it came from."""

    path: Path
    scenario: ScenarioInfo
    terrain: TerrainConfig
    initial_water: tuple[InitialWater, ...] = ()
    walls: tuple[Wall, ...] = ()
    inflows: tuple[Inflow, ...] = ()
    sinks: tuple[Sink, ...] = ()
    gauges: Gauges | None = None
    numerics: Numerics = Numerics()
    output: OutputConfig = OutputConfig()

    @property
    def name(self) -> str:
        return self.scenario.name

    @property
    def end_time_s(self) -> float:
        return self.scenario.end_time_s

    @property
    def output_directory(self) -> Path:
        """The run folder: ``output.directory`` or ``<scenario folder>/out/<name>``."""
        if self.output.directory is not None:
            return self.output.directory
        return self.path.parent / "out" / self.name

    def input_files(self) -> tuple[Path, ...]:
        """The scenario file and every file it reads (a run never writes over them)."""
        t = self.terrain
        files = [self.path, t.dem, t.landcover,
                 t.manning_table if isinstance(t.manning_table, Path) else None,
                 t.manning if isinstance(t.manning, Path) else None,
                 *(w.depth for w in self.initial_water),
                 *(entry.file for entry in (*self.initial_water, *self.walls, *self.sinks)),
                 *(i.hydrograph for i in self.inflows),
                 None if self.gauges is None else self.gauges.file]
        return tuple(f for f in files if f is not None)

    def to_dict(self) -> dict:
        """The resolved scenario as plain JSON/TOML-able data (paths absolute, defaults filled).

        ``None`` values are left out, so the result reloads into an equal :class:`Scenario`.
        """
        out = {f.name: _plain(getattr(self, f.name)) for f in fields(self) if f.name != "path"}
        out["output"]["directory"] = str(self.output_directory)
        return {k: v for k, v in out.items() if v is not None and v != []}

    def __repr__(self) -> str:
        return (
            f"Scenario({self.name!r}, end_time_s={self.end_time_s:g}, "
            f"dem={self.terrain.dem.name!r}, "
            f"initial_water={len(self.initial_water)}, walls={len(self.walls)}, "
            f"inflows={len(self.inflows)}, sinks={len(self.sinks)})"
        )


def _plain(value):
    """Dataclasses, enums, paths and tuples to dicts, strings and lists; drops ``None`` and the
    fields that are no scenario keys (``metadata["scenario"]`` False)."""
    if hasattr(value, "__dataclass_fields__"):
        items = ((f.name, _plain(getattr(value, f.name))) for f in fields(value)
                 if f.metadata.get("scenario", True))
        return {k: v for k, v in items if v is not None}
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


# ---------------------------------------------------------------------------------------------
# Loading and validation
# ---------------------------------------------------------------------------------------------

TOP_KEYS = (
    "scenario",
    "terrain",
    "initial_water",
    "walls",
    "inflows",
    "sinks",
    "gauges",
    "numerics",
    "output",
)


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file.

    Raises
    ------
    floodsph.errors.InputError
        For a missing or unreadable file, invalid TOML (with line and column) or any invalid
        key or value; the message names the file and the key path.
    """
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise InputError(f"{source}: scenario file not found")
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{source}: invalid TOML: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{source}: cannot read the scenario file: {exc}") from None
    return scenario_from_dict(data, source=source, base_dir=path.resolve().parent)


def scenario_from_dict(data: dict, *, source: str, base_dir: Path) -> Scenario:
    """Validate parsed TOML ``data``.

    ``source`` names the file in messages; relative paths resolve against ``base_dir``.
    """
    r = Reader(source, Path(base_dir))
    r.check_keys(data, "", TOP_KEYS)
    return Scenario(
        path=(Path(base_dir) / Path(source).name).resolve(),
        scenario=_info(r, data),
        terrain=_terrain(r, data),
        initial_water=tuple(
            _initial_water(r, t, join("initial_water", i))
            for i, t in enumerate(r.table_array(data, "initial_water"))
        ),
        walls=tuple(
            _wall(r, t, join("walls", i)) for i, t in enumerate(r.table_array(data, "walls"))
        ),
        inflows=tuple(
            _inflow(r, t, join("inflows", i)) for i, t in enumerate(r.table_array(data, "inflows"))
        ),
        sinks=tuple(
            _sink(r, t, join("sinks", i)) for i, t in enumerate(r.table_array(data, "sinks"))
        ),
        gauges=_gauges(r, data),
        numerics=_numerics(r, data),
        output=_output(r, data),
    )


def _info(r: Reader, data: dict) -> ScenarioInfo:
    if "scenario" not in data:
        raise r.fail("scenario", "required table [scenario] is missing")
    t = r.sub_table(data, "", "scenario", ("name", "end_time_s", "description"))
    name = r.string(t, "scenario", "name")
    problem = name_problem(name)
    if problem is not None:
        raise r.fail("scenario.name", problem)
    return ScenarioInfo(
        name=name,
        end_time_s=r.number(t, "scenario", "end_time_s", gt=0.0),
        description=r.string(t, "scenario", "description", ""),
    )


NAME_MAX_BYTES = 255
"""The longest file or folder name most file systems allow (ext4, NTFS, APFS) [bytes]."""


def name_problem(name: str) -> str | None:
    """Why ``name`` cannot be the default run folder's name, or None.

    It must be non-empty, not ``.`` or ``..``, free of path separators (``/ \\ :``) and
    control characters, and at most ``NAME_MAX_BYTES`` bytes in UTF-8.
    """
    if not name.strip() or name in (".", ".."):
        return f"must be a non-empty folder name, got {name!r}"
    bad = [c for c in name if c in "/\\:" or ord(c) < 32 or ord(c) == 127]
    if bad:
        return (f"must be a non-empty folder name without / \\ : or control characters, got "
                f"{describe(name)} (holds {bad[0]!r})")
    size = len(name.encode("utf-8"))
    if size > NAME_MAX_BYTES:
        return (f"is {size} bytes long in UTF-8, but it names the default output folder and a "
                f"folder name holds at most {NAME_MAX_BYTES}; shorten it")
    return None


def _terrain(r: Reader, data: dict) -> TerrainConfig:
    if "terrain" not in data:
        raise r.fail("terrain", "required table [terrain] is missing")
    p = "terrain"
    allowed = ("dem", "crs", "dem_variable", "manning", "landcover", "manning_table", "extent")
    t = r.sub_table(data, "", p, allowed + ("edges", "closed_sides"))
    manning = t.get("manning", TerrainConfig.manning)
    if isinstance(manning, str):
        manning = r.file_value(manning, join(p, "manning"))
    else:
        manning = r.number(t, p, "manning", TerrainConfig.manning, gt=0.0)
        if manning >= N_STRICKLER:
            raise r.fail(join(p, "manning"), strickler_text(manning))
    landcover = r.existing_file(t, p, "landcover", None)
    manning_table = _manning_table(r, t, p)
    if landcover is not None and "manning" in t:
        raise r.fail(join(p, "landcover"), "give either manning or landcover, not both")
    if manning_table is not None and landcover is None:
        raise r.fail(join(p, "manning_table"), "needs terrain.landcover (the class raster)")
    extent = None
    if "extent" in t:
        ext = t["extent"]
        where = join(p, "extent")
        if not isinstance(ext, list) or len(ext) != 4:
            raise r.fail(where, "expected [xmin, ymin, xmax, ymax]")
        extent = tuple(r.number({"v": v}, join(where, k), "v") for k, v in enumerate(ext))
        if not (extent[0] < extent[2] and extent[1] < extent[3]):
            raise r.fail(where, f"expected xmin < xmax and ymin < ymax, got {list(extent)}")
    if landcover is not None:
        manning = None
    edges = r.choice(t, p, "edges", Edges, TerrainConfig.edges)
    return TerrainConfig(
        dem=r.existing_file(t, p, "dem"),
        crs=r.string(t, p, "crs", None),
        dem_variable=r.string(t, p, "dem_variable", None),
        manning=manning,
        landcover=landcover,
        manning_table=manning_table,
        extent=extent,
        edges=edges,
        closed_sides=_closed_sides(r, t, p, edges),
    )


def _manning_table(r: Reader, t: dict, p: str) -> Path | str | None:
    """``terrain.manning_table``: a CSV file, or ``"worldcover"`` for the table shipped with
    floodsph (ESA WorldCover classes, ``floodsph.io.manning``); the name wins over a file
    of that name."""
    from floodsph.io.manning import WORLDCOVER

    if t.get("manning_table") == WORLDCOVER:
        return WORLDCOVER
    return r.existing_file(t, p, "manning_table", None)


SIDES = ("west", "east", "south", "north")


def _closed_sides(r: Reader, t: dict, p: str, edges: Edges) -> tuple[str, ...]:
    """``terrain.closed_sides``: sides of the DEM rectangle that stay walls when edges are open
    (e.g. the closed west edge of the EA floodplain tests); nodata borders are then walls too."""
    if t.get("closed_sides", []) == []:
        return ()
    where = join(p, "closed_sides")
    value = t["closed_sides"]
    if edges is not Edges.OPEN:
        raise r.fail(where, 'only applies with edges = "open" (closed edges close every side)')
    if not isinstance(value, list) or not all(side in SIDES for side in value):
        raise r.fail(where, f"expected a list of sides from {list(SIDES)}, got "
                            f"{describe(value)}")
    return tuple(side for side in SIDES if side in value)


def _initial_water(r: Reader, t: dict, p: str) -> InitialWater:
    r.check_keys(t, p, ("level_m", "polygon", "depth", *VECTOR_KEYS))
    if "depth" in t:
        if "level_m" in t or "polygon" in t or "file" in t:
            raise r.fail(join(p, "depth"), "give either depth or level_m + polygon, not both")
        r.vector_source(t, p, "depth")
        return InitialWater(depth=r.existing_file(t, p, "depth"))
    if "level_m" not in t:
        raise r.fail(p, "expected level_m (with polygon or file) or depth")
    level = r.number(t, p, "level_m")
    if abs(level) > ELEVATION_LIMIT_M:
        raise r.fail(join(p, "level_m"), f"{level:g} m is beyond +-{ELEVATION_LIMIT_M:g} m, no "
                                         "water surface on Earth")
    source = r.vector_source(t, p, "polygon")
    if source:
        return InitialWater(level_m=level, **source)
    if "polygon" not in t:
        raise r.fail(join(p, "polygon"), "required with level_m (the area to fill), or file")
    return InitialWater(level_m=level, polygon=r.polygon(t, p, "polygon"))


VECTOR_KEYS = ("file", "layer", "crs")
"""Keys of a geometry read from a vector file (``Reader.vector_source``)."""


def _wall(r: Reader, t: dict, p: str) -> Wall:
    r.check_keys(t, p, ("polyline", *VECTOR_KEYS))
    source = r.vector_source(t, p, "polyline")
    if source:
        return Wall(**source)
    return Wall(polyline=r.polyline(t, p, "polyline"))


def _inflow(r: Reader, t: dict, p: str) -> Inflow:
    r.check_keys(t, p, ("line", "hydrograph", "breach", "direction"))
    line = r.points(t, p, "line", at_least=2, exactly=2)
    if line[0] == line[1]:
        raise r.fail(join(p, "line"), "the two end points are the same")
    if ("hydrograph" in t) == ("breach" in t):
        raise r.fail(p, "expected exactly one of hydrograph (a CSV file) or [breach]")
    direction = None
    if "direction" in t:
        direction = r.point(t["direction"], join(p, "direction"))
        if direction == (0.0, 0.0):
            raise r.fail(join(p, "direction"), "must not be the zero vector")
    breach = _breach(r, t["breach"], join(p, "breach")) if "breach" in t else None
    hydrograph = r.existing_file(t, p, "hydrograph", None)
    return Inflow(line=line, hydrograph=hydrograph, breach=breach, direction=direction)


def _breach(r: Reader, value, where: str) -> BreachParams:
    """``[inflows.breach]`` validated by the breach module, its files made absolute and
    checked to exist (they are read when the breach is routed, ``floodsph.inputs``)."""
    from dataclasses import replace

    from floodsph.breach.params import BreachParams

    params = BreachParams.from_mapping(r.table(value, where), where, r.base_dir,
                                       source=r.source)
    files = {f.name: r.file_value(str(getattr(params, f.name)), join(where, f.name))
             for f in fields(params) if isinstance(getattr(params, f.name), Path)}
    return replace(params, **files)


def _sink(r: Reader, t: dict, p: str) -> Sink:
    r.check_keys(t, p, ("polygon", *VECTOR_KEYS))
    source = r.vector_source(t, p, "polygon")
    if source:
        return Sink(**source)
    return Sink(polygon=r.polygon(t, p, "polygon"))


def _gauges(r: Reader, data: dict) -> Gauges | None:
    """``[gauges]``: ``file`` is a CSV table, or a vector file (by its extension) with the
    optional ``layer``, ``crs`` and ``id_field``."""
    from floodsph.io.vector import is_vector_file

    if "gauges" not in data:
        return None
    p = "gauges"
    t = r.sub_table(data, "", p, ("file", "interval_s", "layer", "crs", "id_field"))
    file = r.existing_file(t, p, "file")
    vector = is_vector_file(file)
    for key in ("layer", "crs", "id_field"):
        if key in t and not vector:
            raise r.fail(join(p, key), f"applies only to a vector file of points, but "
                                       f"gauges.file {file.name} is a CSV table")
    source = r.vector_source(t, p, None) if vector else {}
    return Gauges(
        file=file,
        interval_s=r.number(t, p, "interval_s", Gauges.interval_s, gt=0.0),
        layer=source.get("layer"),
        crs=source.get("crs"),
        id_field=r.string(t, p, "id_field", None),
    )


def _numerics(r: Reader, data: dict) -> Numerics:
    """``[numerics]`` straight into :class:`~floodsph.numerics.Numerics`: each key read as the
    type of its field, then checked by ``Numerics`` itself (bounds, the refinement rule)."""
    p = "numerics"
    t = r.sub_table(data, "", p, NUMERICS_KEYS)
    values = {}
    for f in fields(Numerics):
        if f.name not in t:
            continue
        kind = f.metadata["kind"]
        if issubclass(kind, Enum):
            values[f.name] = r.choice(t, p, f.name, kind, f.default)
        elif kind is int:
            values[f.name] = r.integer(t, p, f.name)
        else:
            values[f.name] = r.number(t, p, f.name)
    try:
        return Numerics(**values)
    except NumericsError as exc:
        raise r.fail(join(p, exc.key), exc.problem) from None


def _output(r: Reader, data: dict) -> OutputConfig:
    p = "output"
    keys = tuple(f.name for f in fields(OutputConfig))
    t = r.sub_table(data, "", p, keys)
    d = OutputConfig()
    directory = r.string(t, p, "directory", None)
    formats = d.formats
    if "formats" in t:
        value = t["formats"]
        where = join(p, "formats")
        if not isinstance(value, list):
            raise r.fail(where, "expected an array of strings, e.g. [\"geotiff\", \"netcdf\"]")
        formats = tuple(r.as_choice(v, join(where, k), OutputFormat) for k, v in enumerate(value))
        if len(set(formats)) != len(formats):
            raise r.fail(where, "lists a format twice")
    return OutputConfig(
        directory=None if directory is None else r.resolve(directory, join(p, "directory")),
        resolution_m=r.number(t, p, "resolution_m", None, gt=0.0),
        wet_threshold_m=r.number(t, p, "wet_threshold_m", d.wet_threshold_m, ge=0.0),
        formats=formats,
        snapshot_interval_s=r.number(t, p, "snapshot_interval_s", d.snapshot_interval_s, ge=0.0),
        mass_balance_interval_s=r.number(
            t, p, "mass_balance_interval_s", d.mass_balance_interval_s, gt=0.0
        ),
        checkpoint_interval_s=r.number(t, p, "checkpoint_interval_s",
                                       d.checkpoint_interval_s, ge=0.0),
    )


def write_resolved(scenario: Scenario, path: Path) -> None:
    """Write the resolved scenario (absolute paths, defaults filled) as TOML to ``path``."""
    from tomli_w import dumps

    header = (
        f"# Resolved copy of {scenario.path}\n"
        "# (absolute paths and every default filled in; loads back into the same scenario)\n\n"
    )
    Path(path).write_text(header + dumps(scenario.to_dict()), encoding="utf-8")
