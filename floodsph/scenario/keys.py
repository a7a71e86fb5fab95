"""What each key of the scenario file means: type, units, default and meaning, as named data.

The parser (``floodsph.scenario.config``) decides which keys are accepted and checks their values;
this module says what they are for. ``docs/scenario-reference.md`` is generated from
:data:`TABLES` by ``python workflows/scenario_reference.py``, and
``tests/scenario/test_scenario_reference.py`` fails when a key the parser accepts has no
:class:`KeyDoc` here, when a key here is refused by the parser, or when the page is stale.

Defaults are not repeated here: they are read from the dataclass that the parser fills
(:attr:`TableDoc.config`), so the page shows the value a run really uses. A key whose absence
means something other than a value (``particle_spacing_m``: the DEM cell size) says so in
:attr:`KeyDoc.absent`.

Adding a key to the parser: add its :class:`KeyDoc` to the table below, then re-run
``python workflows/scenario_reference.py``.
"""

from __future__ import annotations

import json
from dataclasses import MISSING, dataclass, fields
from enum import Enum

from floodsph.breach.params import BreachParams
from floodsph.scenario.config import (
    SIDES,
    BreachGrowth,
    Edges,
    FluxLine,
    Gauges,
    Inflow,
    InitialWater,
    LevelBoundary,
    OutputConfig,
    OutputFormat,
    ScenarioInfo,
    Sink,
    TerrainConfig,
    Wall,
    WallBreach,
)
from floodsph.scenario.numerics import (
    Momentum,
    Numerics,
    Refinement,
    Stabilisation,
    TimeStepping,
    WallModel,
)

POINTS = "array of [x, y]"
"""The type of a list of points in the inline coordinates' CRS (the DEM file's, or
``[scenario] crs``)."""


@dataclass(frozen=True)
class KeyDoc:
    """One key of a table.

    name : the key as written in the TOML file.
    type : the TOML type (``number``, ``integer``, ``string``, ``path``, ``array of [x, y]``).
    meaning : what the key does, in a sentence or two.
    units : SI units of the value ("" when it has none: a name, a count, a ratio).
    required : the parser refuses the table without it.
    absent : what leaving the key out means, when that is not its dataclass default.
    choices : the enum whose values the key takes (shown in the type).
    """

    name: str
    type: str
    meaning: str
    units: str = ""
    required: bool = False
    absent: str | None = None
    choices: type[Enum] | None = None


@dataclass(frozen=True)
class TableDoc:
    """One table of the scenario file and its keys.

    name : the table's key path (``numerics``, ``inflows.breach``).
    array : written ``[[name]]`` (repeatable) rather than ``[name]``.
    meaning : what the table describes.
    config : the dataclass the parser fills from it (holds the defaults).
    keys : its keys, in the order the page lists them.
    required : the file is refused without this table.
    """

    name: str
    array: bool
    meaning: str
    config: type
    keys: tuple[KeyDoc, ...]
    required: bool = False

    @property
    def header(self) -> str:
        return f"[[{self.name}]]" if self.array else f"[{self.name}]"

    def default_text(self, key: KeyDoc) -> str:
        """The default as TOML text (``0.3``, ``"open"``), ``required``, or what absence means."""
        if key.required:
            return "required"
        if key.absent is not None:
            return key.absent
        found = {f.name: f for f in fields(self.config)}.get(key.name)
        if found is None or (found.default is MISSING and found.default_factory is MISSING):
            return "none"
        value = found.default if found.default is not MISSING else found.default_factory()
        return "none" if value is None else toml_text(value)

    def type_text(self, key: KeyDoc) -> str:
        """The key's type, with its allowed values when it is a choice."""
        if key.choices is None:
            return key.type
        return f"{key.type}: " + " | ".join(toml_text(m) for m in key.choices)


def toml_text(value) -> str:
    """A default value as it would be written in the scenario file."""
    if isinstance(value, Enum):
        return toml_text(value.value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, tuple | list):
        return "[" + ", ".join(toml_text(v) for v in value) + "]"
    return repr(value)


VECTOR_KEYS = (
    KeyDoc("file", "path", "A vector file whose features stand for this entry, instead of "
           "inline coordinates: GeoJSON, or GeoPackage, shapefile or FlatGeobuf with the gis "
           "extra; reprojected into the model's CRS (docs/vector-inputs.md).", absent="none"),
    KeyDoc("layer", "string", "With file: the layer of a file that holds several.",
           absent="the file's only layer"),
    KeyDoc("crs", "string", "With file: the CRS of its coordinates, for a file that carries "
           "none or to override its own.", absent="the file's CRS"),
)
"""Keys of an entry drawn from a vector file (``[[walls]]``, ``[[initial_water]]``, ...)."""


SCENARIO = TableDoc("scenario", False, "What the scenario is called and how long it runs.",
                    ScenarioInfo, required=True, keys=(
    KeyDoc("name", "string", "The scenario's name; also the default run folder, out/<name> "
           "beside the scenario file, so no `/ \\ :` or control characters.", required=True),
    KeyDoc("end_time_s", "number", "Simulated time at which the run ends (> 0).", "s",
           required=True),
    KeyDoc("description", "string", "Free text, kept in the run manifest."),
    KeyDoc("start", "date-time", "The calendar instant of t = 0, ISO 8601 with its time zone "
           "(`2024-01-15T06:00:00Z`, `2024-01-15T07:00:00+01:00`; a TOML date-time or a "
           "string). It dates the `time` of every NetCDF file (`seconds since` it, in UTC) "
           "and adds the column `time_utc` to gauges.csv; hydrograph files with a `time` column "
           "of dates count from it. A date-time without a time zone is "
           "refused.", absent="no calendar start: the NetCDF times count from "
           "1970-01-01T00:00:00Z, a placeholder with no meaning, and gauges.csv has no "
           "time_utc column"),
    KeyDoc("crs", "string", "The CRS of the inline coordinates (polygons, lines, extent, the "
           "gauges CSV) when they are not in the DEM file's own CRS (`EPSG:4326`, a WKT or "
           "PROJ string). Vector files keep their own CRS.",
           absent="the DEM file's CRS"),
))

TERRAIN = TableDoc("terrain", False, "The ground: elevation, roughness and what happens at "
                   "the DEM's border.", TerrainConfig, required=True, keys=(
    KeyDoc("dem", "path or array of paths", "Digital elevation model: GeoTIFF, ESRI ASCII grid "
           "(.asc, with .prj), NetCDF (see dem_variable) or a GDAL VRT; a list of tiles or a glob "
           "(`tiles/N36W08*.tif`) is mosaicked. A geographic DEM, or one whose CRS departs from "
           "ground metres by more than 0.5 % (Web Mercator), is reprojected to its UTM zone; a "
           "CRS in feet becomes the same projection in metres.", "m", required=True),
    KeyDoc("crs", "string", "CRS of the DEM (`EPSG:27572`, a WKT or PROJ string), for a file "
           "that carries none, such as a bare .asc.", absent="the DEM file's CRS"),
    KeyDoc("dem_variable", "string", "Variable of a NetCDF DEM that holds the elevation.",
           absent="the file's only raster"),
    KeyDoc("manning", "number or path", "Manning's roughness n: one value for the whole DEM, or "
           "a raster of n on any grid (resampled bilinearly onto the DEM). Values of 1 or more "
           "(Strickler or Chezy coefficients) are refused.", "s m^-1/3"),
    KeyDoc("landcover", "path", "Instead of manning: a raster of land-cover classes, mapped to n "
           "through manning_table (nearest-neighbour resampling, classes are never averaged)."),
    KeyDoc("manning_table", "path", "CSV with columns class, manning_n (extra columns ignored) "
           "for landcover, or \"worldcover\" for the table shipped for ESA WorldCover classes; "
           "required with landcover."),
    KeyDoc("extent", "[xmin, ymin, xmax, ymax]", "Crop of the DEM, in the DEM file's CRS (or "
           "scenario.crs).", absent="the whole DEM"),
    KeyDoc("edges", "string", "`open`: water that crosses the DEM border, or reaches nodata, "
           "leaves and is counted as outflow (waves pass out without reflection); `closed`: the "
           "border and the nodata cells are walls.", choices=Edges),
    KeyDoc("closed_sides", "array of strings", "With edges = \"open\": sides of the DEM "
           f"rectangle ({', '.join(SIDES)}) that stay walls; nodata borders are then walls too."),
))

INITIAL_WATER = TableDoc("initial_water", True, "Water present at t = 0 (a reservoir, a lake): "
                         "a level inside a polygon, or a depth raster.", InitialWater, keys=(
    KeyDoc("level_m", "number", "Free-surface elevation: the polygon is filled wherever the bed "
           "lies below it. Needs polygon.", "m", absent="none (give level_m + polygon or depth)"),
    KeyDoc("polygon", POINTS, "The area to fill to level_m (at least three points, not crossing "
           "itself), in the DEM file's CRS (or scenario.crs).", "m",
           absent="none (give polygon or file with level_m)"),
    KeyDoc("depth", "path", "Instead of level_m + polygon: a raster of initial depth.", "m",
           absent="none"),
    *VECTOR_KEYS,
))

WALLS = TableDoc("walls", True, "Lines water cannot cross (embankments, flood walls, "
                 "buildings).", Wall, keys=(
    KeyDoc("polyline", POINTS, "The wall's vertices, in the DEM file's CRS (or scenario.crs); "
           "a closed polyline (first "
           "point = last) is a solid footprint such as a building.", "m",
           absent="none (give polyline or file)"),
    *VECTOR_KEYS,
    KeyDoc("crest_m", "number or array of numbers", "The wall's crest elevation, in the DEM's "
           "vertical datum: one value, or one per polyline vertex (linear in between; inline "
           "polylines only). Water standing above it passes over the wall as over a "
           "broad-crested weir, reduced when the far side is submerged (Villemonte); the "
           "particles still never cross the wall (docs/structures.md). A crest below the "
           "bed at every vertex is refused.", "m",
           absent="none: the wall is infinitely high"),
    KeyDoc("discharge_coefficient", "number", "C of the weir law q = C sqrt(g) H^1.5 per "
           "metre of crest (dimensionless; with crest_m).",
           absent="(2/3)^1.5 = 0.544, an ideal broad crest"),
    KeyDoc("breach", "table", "A breach that opens in the crest (see [walls.breach]; with "
           "crest_m).", absent="none"),
))

WALL_BREACH = TableDoc("walls.breach", False, "A trapezoidal breach that lowers the crest of "
                       "a crest wall over time, from a notch at the crest to its final size "
                       "(HEC-RAS's breach progression, docs/structures.md).", WallBreach, keys=(
    KeyDoc("centre_m", "number", "Where the breach is centred: the distance along the wall "
           "from its first vertex (at most the wall's length).", "m", required=True),
    KeyDoc("invert_m", "number", "The final breach bottom elevation (below the crest there).",
           "m", required=True),
    KeyDoc("bottom_width_m", "number", "The final bottom width (no wider than the wall).", "m",
           absent="required unless froehlich = true"),
    KeyDoc("formation_s", "number", "The time from the start to the fully formed breach (> 0).",
           "s", absent="required unless froehlich = true"),
    KeyDoc("side_slope", "number", "The breach's side slopes, horizontal : vertical (0: "
           "vertical sides)."),
    KeyDoc("start_s", "number", "When the breach starts to open (>= 0).", "s"),
    KeyDoc("growth", "string", "How the breach grows over formation_s: `linear`, or HEC-RAS's "
           "`sine` wave, fraction (1 - cos(pi t / t_f)) / 2.", choices=BreachGrowth),
    KeyDoc("froehlich", "boolean", "Take the final width (B_avg - side_slope h_b) and the "
           "formation time from Froehlich (2008), overtopping, as `floodsph breach` does."),
    KeyDoc("reservoir_volume_m3", "number", "With froehlich = true: V_w, the volume above the "
           "breach invert at failure.", "m3", absent="none (required with froehlich = true)"),
))

INFLOWS = TableDoc("inflows", True, "A breach section where water enters the model, from a "
                   "hydrograph or a parametric breach.", Inflow, keys=(
    KeyDoc("line", POINTS, "The section's two end points; water enters across it.", "m",
           required=True),
    KeyDoc("hydrograph", "path", "CSV of the total discharge through the section: time as "
           "time_s, time_min or time_h, or time as ISO 8601 dates (counted from scenario.start, "
           "else from the first row); discharge as discharge_m3s or discharge_cfs. Give this "
           "or [inflows.breach].", absent="none"),
    KeyDoc("breach", "table", "A parametric breach turned into the hydrograph "
           "(see [inflows.breach]).", absent="none"),
    KeyDoc("direction", "[dx, dy]", "Direction of the entering flow (any length but zero).",
           absent="normal to line, towards lower ground"),
))

BREACH = TableDoc("inflows.breach", False, "A parametric dam breach (Froehlich 2008 breach "
                  "size and formation time, level-pool routing of the reservoir). Elevations "
                  "in any consistent datum; the same keys as `floodsph breach PARAMS.toml`.",
                  BreachParams, keys=(
    KeyDoc("method", "string", "The breach model; Froehlich (2008) is the only one so far."),
    KeyDoc("mode", "string", "`overtopping` (k0 = 1.3, side slopes 1.0 H:V) or `piping` (k0 = "
           "1.0, 0.7 H:V; routed as weir flow through the same growing trapezoid)."),
    KeyDoc("breach_height_m", "number", "h_b: the dam crest at the breach minus the final "
           "breach invert.", "m", required=True),
    KeyDoc("reservoir_volume_m3", "number", "V_w: the volume above the breach invert at failure; "
           "must agree within 1 % with reservoir_area_m2 or storage_table when they are given.",
           "m3", absent="from reservoir_area_m2 or storage_table (one of the three is required)"),
    KeyDoc("head_m", "number", "h_w: the initial water level minus the breach invert.", "m",
           absent="breach_height_m"),
    KeyDoc("initial_level_m", "number", "Instead of head_m: the initial water level itself.",
           "m", absent="none"),
    KeyDoc("breach_invert_m", "number", "The final breach bottom elevation.", "m"),
    KeyDoc("reservoir_area_m2", "number", "A constant reservoir surface area A, V = A (H - "
           "invert).", "m2", absent="V_w / h_w"),
    KeyDoc("storage_table", "path", "Instead of reservoir_area_m2: a CSV of elevation_m with "
           "volume_m3 or area_m2 (interpolated linearly).", absent="none"),
    KeyDoc("inflow_hydrograph", "path", "Inflow into the reservoir during the breach, a CSV "
           "as inflows.hydrograph (dates count from its first row).", absent="none"),
    KeyDoc("progression", "string", "How the breach grows over the formation time: `linear` or "
           "`sine`."),
    KeyDoc("weir_coefficient", "number", "C_w of the breach weir (side parts 2.45 / 3.1 C_w).",
           "m^0.5 s-1"),
    KeyDoc("average_width_m", "number", "Overrides the average breach width B_avg (for example "
           "a sampled value in an ensemble).", "m", absent="Froehlich (2008)"),
    KeyDoc("formation_time_s", "number", "Overrides the breach formation time t_f.", "s",
           absent="Froehlich (2008)"),
    KeyDoc("start_time_s", "number", "Breach initiation on the hydrograph's clock.", "s"),
    KeyDoc("duration_s", "number", "Length of the hydrograph.", "s",
           absent="until the outflow falls below 1e-4 of the peak after t_f"),
    KeyDoc("dt_s", "number", "Sampling interval of the routed (and written) hydrograph.", "s",
           absent="min(t_f / 200, drainage time / 20)"),
))

SINKS = TableDoc("sinks", True, "Areas where water leaves the model (the sea, a lake far "
                 "downstream); what they absorb is counted as outflow.", Sink, keys=(
    KeyDoc("polygon", POINTS, "The area: DEM cells whose centre lies inside absorb the water "
           "that reaches them.", "m", absent="none (give polygon or file)"),
    *VECTOR_KEYS,
))

LEVEL_BOUNDARIES = TableDoc("level_boundaries", True, "A section where the water level is "
                            "imposed (the sea, a river stage): water enters or leaves across it "
                            "with the level (docs/level-boundary.md).", LevelBoundary, keys=(
    KeyDoc("name", "string", "Labels the boundary in run.json (unique).", required=True),
    KeyDoc("side", "string", "A side of the DEM (`west`, `east`, `south`, `north`), neither in "
           "terrain.closed_sides nor taken by another level boundary. Give this or line.",
           absent="none"),
    KeyDoc("line", POINTS, "Instead of side: the section's two end points, on the DEM.", "m",
           absent="none"),
    KeyDoc("direction", "[dx, dy]", "With line: a direction pointing to the modelled water.",
           absent="normal to line, towards lower ground (onto the DEM at its border)"),
    KeyDoc("level_m", "number", "A constant water level. Give this or file.", "m",
           absent="none"),
    KeyDoc("file", "path", "CSV with columns time_s and level_m: the level, linear in time "
           "between rows, held at the first and last level outside them.", absent="none"),
))

GAUGES = TableDoc("gauges", False, "Time series of depth, level and speed at points "
                  "(written to gauges.csv).", Gauges, keys=(
    KeyDoc("file", "path", "CSV with columns id, x, y (the DEM file's CRS, or scenario.crs), "
           "or a vector file of "
           "points (docs/vector-inputs.md).", required=True),
    KeyDoc("interval_s", "number", "Simulated time between two samples (> 0).", "s"),
    KeyDoc("layer", "string", "With a vector file: the layer of a file that holds several.",
           absent="the file's only layer"),
    KeyDoc("crs", "string", "With a vector file: the CRS of its coordinates.",
           absent="the file's CRS"),
    KeyDoc("id_field", "string", "With a vector file: the attribute that names each gauge.",
           absent="the id attribute, else the feature number from 1"),
))

FLUX_LINES = TableDoc("flux_lines", True, "Lines through which the discharge is measured, "
                      "e.g. a section across the valley below a dam: the mean discharge over "
                      "each interval goes to flux.csv (one column `<name>_m3s`, a row every "
                      "gauges.interval_s, or every output.mass_balance_interval_s without "
                      "gauges) and the volumes passed over the run to run.json "
                      "(docs/outputs.md).", FluxLine, keys=(
    KeyDoc("name", "string", "The line's name, unique among the flux lines (no commas, quotes "
           "or control characters: it heads the column `<name>_m3s` of flux.csv).",
           required=True),
    KeyDoc("polyline", POINTS, "The line's vertices (at least two, non-zero length), in the "
           "DEM file's CRS (or scenario.crs). Water crossing from the left of the direction "
           "of travel (first point towards last) to the right counts positive: a line drawn "
           "from the right bank to the left bank, looking downstream, measures the flow "
           "downstream as positive. Draw it from bank to bank (or beyond the DEM) to catch "
           "all the flow.", "m", required=True),
))

NUMERICS = TableDoc("numerics", False, "The solver's settings. The defaults are the "
                    "recommended values; most scenarios set particle_spacing_m only.",
                    Numerics, keys=(
    KeyDoc("particle_spacing_m", "number", "Spacing of the particle lattice the water is "
           "seeded on (the resolution of the run).", "m", absent="the DEM cell size"),
    KeyDoc("cfl", "number", "Courant number of the time step dt = cfl min h / (|v| + c), in "
           "(0, 1]."),
    KeyDoc("refinement", "string", "Dynamic refinement: split thinning particles and coalesce "
           "small ones (docs/method.md).", choices=Refinement),
    KeyDoc("threads", "integer", "Threads of the numerical kernels; 0 = all cores (the "
           "`--threads` option overrides it)."),
    KeyDoc("kappa", "number", "Smoothing length over particle spacing, h0 / dx. At 1.2 the "
           "square seeding lattice is a stable state of still water."),
    KeyDoc("stabilisation", "string", "Numerical dissipation: a parameter-free Lax-Friedrichs "
           "term, a two-shock Riemann pressure, or the Lax-Friedrichs term on velocities "
           "reconstructed to each pair's midpoint (muscl: sharper bores and fronts, "
           "docs/reconstruction.md). `riemann` and `muscl` need momentum = \"variational\".",
           choices=Stabilisation),
    KeyDoc("density_tol", "number", "Tolerance of the Newton-Raphson solve for depth and "
           "smoothing length, on |R| / rho."),
    KeyDoc("friction_depth_floor_m", "number", "Depth below which Manning friction is evaluated "
           "at this depth (keeps the friction of thin films finite).", "m"),
    KeyDoc("max_slope", "number", "Bed slopes steeper than this are limited in the bed-slope "
           "term (dimensionless, rise over run)."),
    KeyDoc("refine_area_max", "number", "A particle splits when its area m / rho exceeds this "
           "many times particle_spacing_m^2."),
    KeyDoc("refine_area_min", "number", "Particles below this many times particle_spacing_m^2 "
           "may coalesce; must be below refine_area_max / 2."),
    KeyDoc("refine_d_min_m", "number", "Particles shallower than this are not split.", "m"),
    KeyDoc("refine_max_level", "integer", "At most this many generations of splitting."),
    KeyDoc("time_stepping", "string", "`local` (default): each particle at its own "
           "power-of-two multiple of the finest step; `global`: one time step for every "
           "particle.",
           choices=TimeStepping),
    KeyDoc("step_levels", "integer", "With local time stepping, a big step holds at most "
           "2^step_levels finest steps (0 to 6)."),
    KeyDoc("wall_model", "string", "How walls, closed DEM sides and nodata banks hold water: "
           "`mirror`, mirror images of the particles (default); `integral`, the experimental "
           "boundary integral of the kernel support they hide (docs/still-water.md compares "
           "the two; it needs momentum = \"variational\").", choices=WallModel),
    KeyDoc("momentum", "string", "The pressure and bed forces: `balanced` (default), the "
           "free-surface level's renormalised differences, which hold a lake at rest exactly "
           "by walls, nodata banks and shores, with the variational force for water faster "
           "than 0.1 m/s (docs/balanced-momentum.md); `variational`, the variational force on "
           "the summation depth with the bed pointwise. The `riemann` and `muscl` "
           "stabilisations and the `integral` wall model need `variational`.",
           choices=Momentum),
))

OUTPUT = TableDoc("output", False, "Where the run folder is and what goes into it.",
                  OutputConfig, keys=(
    KeyDoc("directory", "path", "The run folder.", absent="out/<name> beside the scenario file"),
    KeyDoc("resolution_m", "number", "Cell size of the output maps.", "m",
           absent="the DEM grid (aligned to it)"),
    KeyDoc("wet_threshold_m", "number", "A cell is wet above this depth (arrival time, duration, "
           "extent).", "m"),
    KeyDoc("formats", "array of strings", "Map file formats to write.", choices=OutputFormat),
    KeyDoc("snapshot_interval_s", "number", "> 0 writes depth, velocity and water-level maps "
           "every this much simulated time to snapshots.nc (and at the start and end); 0 "
           "writes none.", "s"),
    KeyDoc("snapshot_times_s", "array of numbers", "Simulated times at which snapshots are "
           "written as well, strictly increasing, from 0 to scenario.end_time_s; the time "
           "step is shortened to land on each exactly. Alone, the snapshots are at these "
           "times only; with snapshot_interval_s, at both.", "s", absent="none"),
    KeyDoc("mass_balance_interval_s", "number", "Simulated time between rows of "
           "mass_balance.csv (> 0).", "s"),
    KeyDoc("checkpoint_interval_s", "number", "> 0 writes a checkpoint at the first step at or "
           "after each multiple of it, to resume from (`floodsph run --resume`); 0 writes none "
           "on a schedule (a stop signal still writes one).", "s"),
))

TABLES: tuple[TableDoc, ...] = (SCENARIO, TERRAIN, INITIAL_WATER, WALLS, WALL_BREACH, INFLOWS,
                                BREACH, SINKS, LEVEL_BOUNDARIES, GAUGES, FLUX_LINES, NUMERICS,
                                OUTPUT)
"""Every table of the scenario file, in the order the reference lists them."""
