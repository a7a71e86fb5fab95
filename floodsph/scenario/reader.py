"""Reading a scenario TOML file into the validated dataclasses of ``floodsph.scenario.config``.

``load_scenario(path)`` parses the file (stdlib ``tomllib``), rejects unknown keys, wrong types
and impossible values with one message naming the file and the key path, resolves relative
paths against the scenario file's folder and fills the defaults of the contract
(``docs/scenario-reference.md``). Nothing else in floodsph reads the TOML; everything reads
the :class:`~floodsph.scenario.config.Scenario`.
"""

from __future__ import annotations

from dataclasses import fields, replace
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING

from floodsph.checks.elevation import ELEVATION_LIMIT_M
from floodsph.io.roughness import N_DEFAULT, N_STRICKLER, strickler_text
from floodsph.scenario.config import (
    SIDES,
    TOP_KEYS,
    BreachGrowth,
    Edges,
    FluxLine,
    Gauges,
    Inflow,
    InitialWater,
    LevelBoundary,
    OutputConfig,
    OutputFormat,
    Scenario,
    ScenarioInfo,
    Sink,
    TerrainConfig,
    Wall,
    WallBreach,
)
from floodsph.scenario.numerics import SCENARIO_KEYS as NUMERICS_KEYS
from floodsph.scenario.numerics import Numerics, NumericsError
from floodsph.scenario.schema import Reader, describe, join, read_toml

if TYPE_CHECKING:
    from floodsph.breach.params import BreachParams


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file.

    Raises
    ------
    floodsph.errors.InputError
        For a missing or unreadable file, invalid TOML (with line and column) or any invalid
        key or value; the message names the file and the key path.
    """
    path = Path(path)
    data = read_toml(path, "scenario")
    return scenario_from_dict(data, source=str(path), base_dir=path.resolve().parent)


def scenario_from_dict(data: dict, *, source: str, base_dir: Path) -> Scenario:
    """Validate parsed TOML ``data``.

    ``source`` names the file in messages; relative paths resolve against ``base_dir``.
    """
    r = Reader(source, Path(base_dir))
    r.check_keys(data, "", TOP_KEYS)
    info = _info(r, data)
    return Scenario(
        path=(Path(base_dir) / Path(source).name).resolve(),
        scenario=info,
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
        level_boundaries=_level_boundaries(r, data),
        gauges=_gauges(r, data),
        flux_lines=_flux_lines(r, data),
        numerics=_numerics(r, data),
        output=_output(r, data, info.end_time_s),
    )


def _info(r: Reader, data: dict) -> ScenarioInfo:
    if "scenario" not in data:
        raise r.fail("scenario", "required table [scenario] is missing")
    t = r.sub_table(data, "", "scenario",
                    ("name", "end_time_s", "description", "start", "crs"))
    name = r.string(t, "scenario", "name")
    problem = name_problem(name)
    if problem is not None:
        raise r.fail("scenario.name", problem)
    crs = r.string(t, "scenario", "crs", None)
    if crs is not None:
        from floodsph.io.raster import parse_crs

        parse_crs(crs, f"{r.source}: scenario.crs")
    return ScenarioInfo(
        name=name,
        end_time_s=r.number(t, "scenario", "end_time_s", gt=0.0),
        description=r.string(t, "scenario", "description", ""),
        start=r.instant(t, "scenario", "start"),
        crs=crs,
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
        manning = r.number(t, p, "manning", N_DEFAULT, gt=0.0)
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
        xmin, ymin, xmax, ymax = (r.number({"v": v}, join(where, k), "v")
                                  for k, v in enumerate(ext))
        extent = (xmin, ymin, xmax, ymax)
        if not (xmin < xmax and ymin < ymax):
            raise r.fail(where, f"expected xmin < xmax and ymin < ymax, got {list(extent)}")
    if landcover is not None:
        manning = None
    edges = r.choice(t, p, "edges", Edges, TerrainConfig.edges)
    return TerrainConfig(
        dem=_dem(r, t, p),
        crs=r.string(t, p, "crs", None),
        dem_variable=r.string(t, p, "dem_variable", None),
        manning=manning,
        landcover=landcover,
        manning_table=manning_table,
        extent=extent,
        edges=edges,
        closed_sides=_closed_sides(r, t, p, edges),
    )


def _dem(r: Reader, t: dict, p: str) -> Path | tuple[Path, ...]:
    """``terrain.dem``: one file, a list of tile files, or a glob pattern (``*``, ``?``,
    ``[...]``) of tiles, relative to the scenario's folder; several files are a tuple in the
    order given (a glob's in sorted order), one file a path."""
    where = join(p, "dem")
    if "dem" not in t:
        raise r.fail(where, "required key is missing")
    value = t["dem"]
    if isinstance(value, list):
        if not value or not all(isinstance(v, str) for v in value):
            raise r.fail(where, f"expected a path or a list of paths, got {describe(value)}")
        files = tuple(r.file_value(v, join(where, i)) for i, v in enumerate(value))
    elif isinstance(value, str) and any(c in value for c in "*?["):
        pattern = r.resolve(value, where)
        files = tuple(sorted(f for f in pattern.parent.glob(pattern.name) if f.is_file()))
        if not files:
            raise r.fail(where, f"no file matches {pattern}")
    else:
        return r.existing_file(t, p, "dem")
    if len(set(files)) != len(files):
        raise r.fail(where, "a tile is named twice")
    return files[0] if len(files) == 1 else files


def _manning_table(r: Reader, t: dict, p: str) -> Path | str | None:
    """``terrain.manning_table``: a CSV file, or ``"worldcover"`` for the table shipped with
    floodsph (ESA WorldCover classes, ``floodsph.io.manning``); the name wins over a file
    of that name."""
    from floodsph.io.manning import WORLDCOVER

    if t.get("manning_table") == WORLDCOVER:
        return WORLDCOVER
    return r.existing_file(t, p, "manning_table", None)




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


CREST_KEYS = ("crest_m", "discharge_coefficient", "breach")
"""Keys of a wall with a crest that water passes over (``floodsph.boundaries.weir``)."""
WALL_BREACH_KEYS = ("centre_m", "invert_m", "bottom_width_m", "formation_s", "side_slope",
                    "start_s", "growth", "froehlich", "reservoir_volume_m3")
"""Keys of ``[walls.breach]`` (``floodsph.scenario.config.WallBreach``)."""


def _wall(r: Reader, t: dict, p: str) -> Wall:
    r.check_keys(t, p, ("polyline", *VECTOR_KEYS, *CREST_KEYS))
    source = r.vector_source(t, p, "polyline")
    crest = _crest(r, t, p, None if source else len(r.points(t, p, "polyline", at_least=2)))
    coefficient = r.number(t, p, "discharge_coefficient", None, gt=0.0)
    breach = _wall_breach(r, t, p, crest)
    if crest is None:
        for key in ("discharge_coefficient", "breach"):
            if key in t:
                raise r.fail(join(p, key), "needs crest_m (a wall without a crest is "
                                           "infinitely high)")
    wall = Wall(**source) if source else Wall(polyline=r.polyline(t, p, "polyline"))
    return replace(wall, crest_m=crest, discharge_coefficient=coefficient, breach=breach)


def _crest(r: Reader, t: dict, p: str, vertices: int | None) -> float | tuple[float, ...] | None:
    """``walls[i].crest_m``: one elevation [m], or one per vertex of an inline polyline."""
    if "crest_m" not in t:
        return None
    value = t["crest_m"]
    where = join(p, "crest_m")
    crest: float | tuple[float, ...]
    if not isinstance(value, list):
        crest = r.number(t, p, "crest_m")
        values: tuple[float, ...] = (crest,)
    else:
        if vertices is None:
            raise r.fail(where, "a list of elevations needs an inline polyline (a wall read "
                                "from a file takes one number)")
        if len(value) != vertices:
            raise r.fail(where, f"has {len(value)} elevations but the polyline has {vertices} "
                                "vertices; give one per vertex, or one number")
        values = tuple(r.number({"v": v}, join(where, k), "v") for k, v in enumerate(value))
        crest = values
    for v in values:
        if abs(v) > ELEVATION_LIMIT_M:
            raise r.fail(where, f"{v:g} m is beyond +-{ELEVATION_LIMIT_M:g} m, no crest on Earth")
    return crest


def _wall_breach(r: Reader, t: dict, p: str, crest) -> WallBreach | None:
    """``[walls.breach]``: a breach opening in a crest wall; the checks that need the wall's
    length and the DEM are ``floodsph.boundaries.crest``'s."""
    if "breach" not in t:
        return None
    where = join(p, "breach")
    b = r.table(t["breach"], where)
    r.check_keys(b, where, WALL_BREACH_KEYS)
    froehlich = b.get("froehlich", False)
    if not isinstance(froehlich, bool):
        raise r.fail(join(where, "froehlich"), f"expected true or false, got {describe(froehlich)}")
    invert = r.number(b, where, "invert_m")
    if crest is not None and not isinstance(crest, tuple) and invert >= crest:
        raise r.fail(join(where, "invert_m"), f"{invert:g} m is not below the crest "
                                              f"({crest:g} m): the breach would open nothing")
    if froehlich:
        for key in ("bottom_width_m", "formation_s"):
            if key in b:
                raise r.fail(join(where, key), "give it or froehlich = true (which computes "
                                               "it), not both")
        if "reservoir_volume_m3" not in b:
            raise r.fail(join(where, "reservoir_volume_m3"), "required with froehlich = true "
                                                              "(V_w of Froehlich 2008)")
    else:
        for key in ("bottom_width_m", "formation_s"):
            if key not in b:
                raise r.fail(join(where, key), "required key is missing (or set froehlich = "
                                               "true)")
        if "reservoir_volume_m3" in b:
            raise r.fail(join(where, "reservoir_volume_m3"), "only used with froehlich = true")
    return WallBreach(
        centre_m=r.number(b, where, "centre_m", ge=0.0),
        invert_m=invert,
        bottom_width_m=r.number(b, where, "bottom_width_m", None, ge=0.0),
        formation_s=r.number(b, where, "formation_s", None, gt=0.0),
        side_slope=r.number(b, where, "side_slope", WallBreach.side_slope, ge=0.0),
        start_s=r.number(b, where, "start_s", WallBreach.start_s, ge=0.0),
        growth=r.choice(b, where, "growth", BreachGrowth, WallBreach.growth),
        froehlich=froehlich,
        reservoir_volume_m3=r.number(b, where, "reservoir_volume_m3", None, gt=0.0),
    )


def _inflow(r: Reader, t: dict, p: str) -> Inflow:
    r.check_keys(t, p, ("line", "hydrograph", "breach", "direction"))
    a, b = r.points(t, p, "line", at_least=2, exactly=2)
    line = (a, b)
    if a == b:
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
    checked to exist (they are read when the breach is routed, ``floodsph.inputs.prepare``)."""
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


LEVEL_KEYS = ("name", "side", "line", "direction", "level_m", "file")
"""Keys of a ``[[level_boundaries]]`` entry (``floodsph.scenario.config.LevelBoundary``)."""


def _level_boundaries(r: Reader, data: dict) -> tuple[LevelBoundary, ...]:
    """``[[level_boundaries]]``: each a unique ``name``, a ``side`` (not a closed one, nor one
    taken by another entry) or a two-point ``line`` (+ ``direction``), and the constant
    ``level_m`` or a CSV ``file``; the checks that need the DEM are
    ``floodsph.checks.levels``'."""
    closed = data.get("terrain", {}).get("closed_sides", [])
    out: list[LevelBoundary] = []
    for i, t in enumerate(r.table_array(data, "level_boundaries")):
        p = join("level_boundaries", i)
        r.check_keys(t, p, LEVEL_KEYS)
        name = r.string(t, p, "name")
        if not name.strip():
            raise r.fail(join(p, "name"), "must be a non-empty name (it labels the boundary in "
                                          "run.json)")
        if name in (b.name for b in out):
            raise r.fail(join(p, "name"), f"{name!r} names an earlier level boundary too; each "
                                          "needs its own name")
        if ("side" in t) == ("line" in t):
            raise r.fail(p, "expected exactly one of side (a side of the DEM) or line (two "
                            "points)")
        side = line = direction = None
        if "side" in t:
            side = r.string(t, p, "side")
            if side not in SIDES:
                raise r.fail(join(p, "side"), f"unknown side {side!r}; expected one of "
                                              f"{list(SIDES)}")
            if isinstance(closed, list) and side in closed:
                raise r.fail(join(p, "side"), f"{side!r} is listed in terrain.closed_sides too; "
                                              "a side is either closed or a level boundary")
            if side in (b.side for b in out):
                raise r.fail(join(p, "side"), f"{side!r} is the side of an earlier level "
                                              "boundary too")
            if "direction" in t:
                raise r.fail(join(p, "direction"), "only applies with line (a side's water "
                                                   "lies on the DEM)")
        else:
            a, b = r.points(t, p, "line", at_least=2, exactly=2)
            if a == b:
                raise r.fail(join(p, "line"), "the two end points are the same")
            line = (a, b)
            if "direction" in t:
                direction = r.point(t["direction"], join(p, "direction"))
                if direction == (0.0, 0.0):
                    raise r.fail(join(p, "direction"), "must not be the zero vector")
        if ("level_m" in t) == ("file" in t):
            raise r.fail(p, "expected exactly one of level_m (a constant level) or file (a "
                            "time_s,level_m CSV)")
        level = r.number(t, p, "level_m", None)
        if level is not None and abs(level) > ELEVATION_LIMIT_M:
            raise r.fail(join(p, "level_m"), f"{level:g} m is beyond +-{ELEVATION_LIMIT_M:g} m, "
                                             "no water surface on Earth")
        out.append(LevelBoundary(name=name, side=side, line=line, direction=direction,
                                 level_m=level, file=r.existing_file(t, p, "file", None)))
    return tuple(out)


def _gauges(r: Reader, data: dict) -> Gauges | None:
    """``[gauges]``: ``file`` is a CSV table (``.csv``, ``.tsv``, ``.txt``), or a vector file
    with the optional ``layer``, ``crs`` and ``id_field``."""
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


def _flux_lines(r: Reader, data: dict) -> tuple[FluxLine, ...]:
    """``[[flux_lines]]``: each a unique ``name`` and a ``polyline`` of at least two points and
    a non-zero length (it may cross itself: a crossing is then counted once per passage)."""
    lines: list[FluxLine] = []
    for i, t in enumerate(r.table_array(data, "flux_lines")):
        p = join("flux_lines", i)
        r.check_keys(t, p, ("name", "polyline"))
        name = r.string(t, p, "name")
        problem = flux_name_problem(name)
        if problem is not None:
            raise r.fail(join(p, "name"), problem)
        if name in (line.name for line in lines):
            raise r.fail(join(p, "name"), f"{name!r} names an earlier flux line too; each "
                                          "needs its own name (it heads a column of flux.csv)")
        points = r.points(t, p, "polyline", at_least=2)
        length = sum(((x1 - x0) ** 2 + (y1 - y0) ** 2) ** 0.5
                     for (x0, y0), (x1, y1) in zip(points[:-1], points[1:], strict=True))
        if not length > 0.0:
            raise r.fail(join(p, "polyline"), f"the line has zero length (all its points are "
                                              f"{list(points[0])}); give two distinct points")
        lines.append(FluxLine(name=name, polyline=points))
    return tuple(lines)


def flux_name_problem(name: str) -> str | None:
    """Why ``name`` cannot name a flux line (a column ``<name>_m3s`` of flux.csv), or None."""
    if not name.strip():
        return "must be a non-empty name"
    bad = [c for c in name if c in ",\"\n\r" or ord(c) < 32 or ord(c) == 127]
    if bad:
        return (f"must be a name without commas, quotes or control characters (it heads a "
                f"column of flux.csv), got {describe(name)}")
    return None


def _numerics(r: Reader, data: dict) -> Numerics:
    """``[numerics]`` straight into :class:`~floodsph.scenario.numerics.Numerics`: each key read as
    the type of its field, then checked by ``Numerics`` itself (bounds, the refinement rule)."""
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


def _snapshot_times(r: Reader, t: dict, p: str, end_time_s: float) -> tuple[float, ...]:
    """``output.snapshot_times_s``: times [s] from 0 to the end time, strictly increasing."""
    if "snapshot_times_s" not in t:
        return ()
    where = join(p, "snapshot_times_s")
    value = t["snapshot_times_s"]
    if not isinstance(value, list):
        raise r.fail(where, f"expected an array of times in seconds, got {describe(value)}")
    times = tuple(r.number({"v": v}, join(where, k), "v") for k, v in enumerate(value))
    for k, time in enumerate(times):
        if time < 0.0:
            raise r.fail(join(where, k), f"{time:g} s is before the start of the run (0 s)")
        if time > end_time_s:
            raise r.fail(join(where, k), f"{time:g} s is beyond the end of the run, "
                                         f"scenario.end_time_s = {end_time_s:g} s")
        if k and time <= times[k - 1]:
            raise r.fail(join(where, k), f"{time:g} s does not follow {times[k - 1]:g} s; the "
                                         "times must be strictly increasing")
    return times


def _output(r: Reader, data: dict, end_time_s: float) -> OutputConfig:
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
        snapshot_times_s=_snapshot_times(r, t, p, end_time_s),
        mass_balance_interval_s=r.number(
            t, p, "mass_balance_interval_s", d.mass_balance_interval_s, gt=0.0
        ),
        checkpoint_interval_s=r.number(t, p, "checkpoint_interval_s",
                                       d.checkpoint_interval_s, ge=0.0),
    )
