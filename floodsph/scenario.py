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
from dataclasses import dataclass, field, fields
from enum import Enum
from pathlib import Path

from floodsph.checks.elevation import ELEVATION_LIMIT_M
from floodsph.checks.roughness import N_STRICKLER, strickler_text
from floodsph.errors import InputError
from floodsph.refinement import Refinement as RefinementSettings
from floodsph.scenario_schema import Reader, describe, join

Point = tuple[float, float]
REFINE_DEFAULTS = RefinementSettings()


class Edges(Enum):
    """What happens at the DEM border: water leaves (``open``) or is reflected (``closed``)."""

    OPEN = "open"
    CLOSED = "closed"


class Refinement(Enum):
    """Dynamic particle refinement (Vacondio et al. 2013): splitting and coalescing."""

    SPLIT_COALESCE = "split+coalesce"
    SPLIT = "split"
    NONE = "none"


class TimeStepping(Enum):
    """One time step for every particle, or each at its own (``floodsph.sph.local_steps``)."""

    GLOBAL = "global"
    LOCAL = "local"


class Stabilisation(Enum):
    """Numerical dissipation of the momentum equation."""

    LAX_FRIEDRICHS = "lax-friedrichs"
    RIEMANN = "riemann"


class WallModel(Enum):
    """How walls hold water: mirror images, or the boundary integral of
    ``floodsph.walls.shadow``."""

    MIRROR = "mirror"
    INTEGRAL = "integral"


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

    ``manning`` is None when the roughness comes from ``landcover`` (+ ``manning_table``).
    """

    dem: Path
    crs: str | None = None
    dem_variable: str | None = None
    manning: float | Path | None = 0.035
    landcover: Path | None = None
    manning_table: Path | None = None
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
    """``[[initial_water]]``: a free-surface level inside a polygon, or a depth raster."""

    level_m: float | None = None
    polygon: tuple[Point, ...] | None = None
    depth: Path | None = None


@dataclass(frozen=True)
class Wall:
    """``[[walls]]``: a polyline water cannot cross (closed: a solid footprint)."""

    polyline: tuple[Point, ...]

    @property
    def closed(self) -> bool:
        return self.polyline[0] == self.polyline[-1]


@dataclass(frozen=True)
class Breach:
    """``[inflows.breach]``: a parametric breach turned into a hydrograph (``floodsph.breach``).

    ``method`` names the breach model; ``parameters`` holds its other keys as given, with file
    paths made absolute (they are validated by ``floodsph.breach.params.BreachParams``, which
    owns their meaning).
    """

    method: str
    parameters: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Inflow:
    """``[[inflows]]``: a breach section with a discharge hydrograph Q(t) [m3/s].

    ``direction`` (optional) is the flow direction [dx, dy]; by default water enters normal
    to ``line`` towards lower ground.
    """

    line: tuple[Point, Point]
    hydrograph: Path | None = None
    breach: Breach | None = None
    direction: Point | None = None


@dataclass(frozen=True)
class Sink:
    """``[[sinks]]``: a polygon where water leaves the model (counted as outflow)."""

    polygon: tuple[Point, ...]


@dataclass(frozen=True)
class Gauges:
    """``[gauges]``: a CSV of points (id, x, y) sampled every ``interval_s`` seconds."""

    file: Path
    interval_s: float = 10.0


@dataclass(frozen=True)
class NumericsConfig:
    """``[numerics]``: the solver's tunables (see ``floodsph.model.Numerics``).

    ``particle_spacing_m = None`` means the DEM cell size; ``threads = 0`` means all cores.
    ``refine_*`` are the splitting and coalescing thresholds of ``floodsph.refinement``
    (areas in units of particle_spacing_m^2, the split depth floor in m, the generations).
    ``time_stepping = "local"`` lets each particle step at its own power-of-two multiple of the
    finest step, up to 2^step_levels of them (``floodsph.sph.local_steps``).
    """

    particle_spacing_m: float | None = None
    cfl: float = 0.3
    refinement: Refinement = Refinement.SPLIT_COALESCE
    threads: int = 0
    kappa: float = 1.2
    stabilisation: Stabilisation = Stabilisation.LAX_FRIEDRICHS
    density_tol: float = 1e-3
    friction_depth_floor_m: float = 0.01
    max_slope: float = 1.0
    refine_area_max: float = REFINE_DEFAULTS.area_max
    refine_area_min: float = REFINE_DEFAULTS.area_min
    refine_d_min_m: float = REFINE_DEFAULTS.d_min
    refine_max_level: int = REFINE_DEFAULTS.max_level
    time_stepping: TimeStepping = TimeStepping.GLOBAL
    step_levels: int = 3
    wall_model: WallModel = WallModel.MIRROR


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
    numerics: NumericsConfig = NumericsConfig()
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
        files = [self.path, t.dem, t.landcover, t.manning_table,
                 t.manning if isinstance(t.manning, Path) else None,
                 *(w.depth for w in self.initial_water),
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
    """Dataclasses, enums, paths and tuples to dicts, strings and lists; drops ``None``."""
    if hasattr(value, "__dataclass_fields__"):
        items = ((f.name, _plain(getattr(value, f.name))) for f in fields(value))
        out = {k: v for k, v in items if v is not None}
        if isinstance(value, Breach):
            out = {"method": value.method, **value.parameters}
        return out
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
    manning_table = r.existing_file(t, p, "manning_table", None)
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
    r.check_keys(t, p, ("level_m", "polygon", "depth"))
    if "depth" in t:
        if "level_m" in t or "polygon" in t:
            raise r.fail(join(p, "depth"), "give either depth or level_m + polygon, not both")
        return InitialWater(depth=r.existing_file(t, p, "depth"))
    if "level_m" not in t:
        raise r.fail(p, "expected level_m (with polygon) or depth")
    if "polygon" not in t:
        raise r.fail(join(p, "polygon"), "required with level_m (the area to fill)")
    level = r.number(t, p, "level_m")
    if abs(level) > ELEVATION_LIMIT_M:
        raise r.fail(join(p, "level_m"), f"{level:g} m is beyond +-{ELEVATION_LIMIT_M:g} m, no "
                                         "water surface on Earth")
    return InitialWater(level_m=level, polygon=r.polygon(t, p, "polygon"))


def _wall(r: Reader, t: dict, p: str) -> Wall:
    r.check_keys(t, p, ("polyline",))
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
    if hydrograph is not None:
        _check_hydrograph(hydrograph, join(p, "hydrograph"), r)
    return Inflow(line=line, hydrograph=hydrograph, breach=breach, direction=direction)


def _check_hydrograph(path: Path, where: str, r: Reader) -> None:
    """Read the hydrograph CSV now, so a bad table stops the run before it starts."""
    from floodsph.hydrograph import read_hydrograph

    read_hydrograph(path, f"{r.source}: {where}")


def _breach(r: Reader, value, where: str) -> Breach:
    """Validate ``[inflows.breach]`` with the breach module; keep it with absolute paths."""
    from floodsph.breach.params import BreachParams

    table = r.table(value, where)
    checked = BreachParams.from_mapping(table, where, r.base_dir, source=r.source)
    params = {}
    for key, given in table.items():
        value = getattr(checked, key)
        if isinstance(value, Path):
            given = str(r.file_value(str(value), join(where, key)))
        if key != "method":
            params[key] = given
    return Breach(method=table.get("method", "froehlich2008"), parameters=params)


def _sink(r: Reader, t: dict, p: str) -> Sink:
    r.check_keys(t, p, ("polygon",))
    return Sink(polygon=r.polygon(t, p, "polygon"))


def _gauges(r: Reader, data: dict) -> Gauges | None:
    if "gauges" not in data:
        return None
    t = r.sub_table(data, "", "gauges", ("file", "interval_s"))
    return Gauges(
        file=r.existing_file(t, "gauges", "file"),
        interval_s=r.number(t, "gauges", "interval_s", Gauges.interval_s, gt=0.0),
    )


def _numerics(r: Reader, data: dict) -> NumericsConfig:
    p = "numerics"
    keys = tuple(f.name for f in fields(NumericsConfig))
    t = r.sub_table(data, "", p, keys)
    d = NumericsConfig()
    out = NumericsConfig(
        particle_spacing_m=r.number(t, p, "particle_spacing_m", None, gt=0.0),
        cfl=r.number(t, p, "cfl", d.cfl, gt=0.0, le=1.0),
        refinement=r.choice(t, p, "refinement", Refinement, d.refinement),
        threads=r.integer(t, p, "threads", d.threads, ge=0),
        kappa=r.number(t, p, "kappa", d.kappa, gt=0.0),
        stabilisation=r.choice(t, p, "stabilisation", Stabilisation, d.stabilisation),
        density_tol=r.number(t, p, "density_tol", d.density_tol, gt=0.0),
        friction_depth_floor_m=r.number(
            t, p, "friction_depth_floor_m", d.friction_depth_floor_m, gt=0.0
        ),
        max_slope=r.number(t, p, "max_slope", d.max_slope, gt=0.0),
        refine_area_max=r.number(t, p, "refine_area_max", d.refine_area_max, gt=0.0),
        refine_area_min=r.number(t, p, "refine_area_min", d.refine_area_min, gt=0.0),
        refine_d_min_m=r.number(t, p, "refine_d_min_m", d.refine_d_min_m, ge=0.0),
        refine_max_level=r.integer(t, p, "refine_max_level", d.refine_max_level, ge=0),
        time_stepping=r.choice(t, p, "time_stepping", TimeStepping, d.time_stepping),
        step_levels=r.integer(t, p, "step_levels", d.step_levels, ge=0, le=6),
        wall_model=r.choice(t, p, "wall_model", WallModel, d.wall_model),
    )
    if not out.refine_area_min < out.refine_area_max / 2.0:
        raise r.fail(join(p, "refine_area_min"),
                     f"must be below refine_area_max / 2 = {out.refine_area_max / 2.0:g} so "
                     f"that a merged pair is not split again at once; got "
                     f"{out.refine_area_min:g}")
    return out


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
    from floodsph.toml_writer import dumps

    header = (
        f"# Resolved copy of {scenario.path}\n"
        "# (absolute paths and every default filled in; loads back into the same scenario)\n\n"
    )
    Path(path).write_text(header + dumps(scenario.to_dict()), encoding="utf-8")
