"""The scenario: the frozen dataclasses a scenario TOML file is read into.

``floodsph.scenario.reader.load_scenario`` fills them from the file (validated, paths
absolute, the contract's defaults filled in: ``docs/scenario-reference.md``), and
``floodsph.scenario.writer`` writes them back. Nothing else in floodsph reads the TOML;
everything reads the :class:`Scenario`.

Coordinates stay in the DEM's CRS here; they are shifted to the terrain's local origin only
when the model is built (``floodsph.run.pipeline``).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from datetime import datetime
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING

from floodsph.io.roughness import N_DEFAULT
from floodsph.scenario.numerics import Numerics

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
    """``[scenario]``: the name (also the default output folder), the simulated time [s] and
    the calendar instant of its start (time zone aware, None when the scenario gives none;
    hydrograph dates count from it). ``crs`` is the CRS of the inline coordinates (polygons,
    lines, extents) when they are not in the DEM file's own CRS
    (``floodsph.io.coordinates``)."""

    name: str
    end_time_s: float
    description: str = ""
    start: datetime | None = None
    crs: str | None = None


@dataclass(frozen=True)
class TerrainConfig:
    """``[terrain]``: the DEM and the bed roughness (a uniform n, an n raster or land cover).

    ``dem`` is one file, or a tuple of tile files mosaicked into one grid
    (``floodsph.io.mosaic``).

    ``manning`` is None when the roughness comes from ``landcover`` (+ ``manning_table``: a
    CSV path, or ``"worldcover"`` for the shipped ESA WorldCover table).
    """

    dem: Path | tuple[Path, ...]
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
        (``floodsph.model.flood_model.FloodModel`` walls nodata unless every edge is open)."""
        return self.edges is Edges.CLOSED or bool(self.closed_sides)


@dataclass(frozen=True)
class InitialWater:
    """``[[initial_water]]``: a free-surface level inside a polygon, or a depth raster.

    The polygons may come from a vector ``file`` (+ ``layer``, ``crs``) instead of
    ``polygon`` (``floodsph.io.vector``); ``feature`` names the feature of such a file a
    body was read from (``floodsph.inputs.vectors``).
    """

    level_m: float | None = None
    polygon: tuple[Point, ...] | None = None
    depth: Path | None = None
    file: Path | None = None
    layer: str | None = None
    crs: str | None = None
    feature: str | None = None


class BreachGrowth(Enum):
    """How a wall breach grows over its formation time (``floodsph.breach.formulas.progression``):
    linearly, or along HEC-RAS's sine wave, slow at the start and the end."""

    LINEAR = "linear"
    SINE = "sine"


@dataclass(frozen=True)
class WallBreach:
    """``[walls.breach]``: a trapezoidal breach that opens in a crest wall
    (``floodsph.boundaries.crest``, ``docs/structures.md``).

    ``centre_m`` is the distance along the wall from its first vertex [m] (in the model's
    metres); ``invert_m`` the final breach bottom elevation [m]; ``bottom_width_m`` its final
    bottom width [m]; ``side_slope`` H:V; the breach starts at ``start_s`` and is fully formed
    ``formation_s`` later. With ``froehlich`` the final width and the formation time come from
    Froehlich (2008) for ``reservoir_volume_m3`` (``floodsph.breach.formulas``).
    """

    centre_m: float
    invert_m: float
    bottom_width_m: float | None = None
    formation_s: float | None = None
    side_slope: float = 1.0
    start_s: float = 0.0
    growth: BreachGrowth = BreachGrowth.LINEAR
    froehlich: bool = False
    reservoir_volume_m3: float | None = None


@dataclass(frozen=True)
class Wall:
    """``[[walls]]``: a polyline water cannot cross (closed: a solid footprint), or the lines
    and polygon outlines of a vector ``file`` (+ ``layer``, ``crs``; see InitialWater).

    With ``crest_m`` (one elevation [m], or one per vertex, linear in between) water above
    the crest passes over the wall as over a broad-crested weir of ``discharge_coefficient``
    (None: the ideal (2/3)^(3/2)), and ``breach`` may open a breach in it
    (``floodsph.boundaries.weir``). Without it the wall is infinitely high.
    """

    polyline: tuple[Point, ...] | None = None
    file: Path | None = None
    layer: str | None = None
    crs: str | None = None
    feature: str | None = None
    crest_m: float | tuple[float, ...] | None = None
    discharge_coefficient: float | None = None
    breach: WallBreach | None = None

    @property
    def closed(self) -> bool:
        return self.polyline is not None and self.polyline[0] == self.polyline[-1]


@dataclass(frozen=True)
class Inflow:
    """``[[inflows]]``: a breach section with a discharge hydrograph Q(t) [m3/s].

    ``hydrograph`` is the CSV of Q(t) (read by ``floodsph.inputs.prepare``, as every file the
    scenario names); ``breach`` the validated ``[inflows.breach]`` table of a parametric breach
    (``floodsph.breach.params.BreachParams``, file paths absolute), routed into Q(t) there.

    ``direction`` (optional) is the flow direction [dx, dy]; by default water enters normal
    to ``line`` towards lower ground.
    """

    line: tuple[Point, Point]
    hydrograph: Path | None = None
    breach: BreachParams | None = None
    direction: Point | None = None


@dataclass(frozen=True)
class LevelBoundary:
    """``[[level_boundaries]]``: a section where the water level follows a given series
    (``floodsph.boundaries.level``, ``docs/level-boundary.md``).

    ``name`` labels it in run.json; ``side`` is a side of the DEM rectangle, or ``line`` two
    points on the DEM (model CRS) with the optional ``direction`` [dx, dy] pointing to the
    modelled water (by default towards lower ground, as for an inflow); the level is the
    constant ``level_m`` [m] or the ``time_s,level_m`` CSV ``file``
    (``floodsph.io.level_series``).
    """

    name: str
    side: str | None = None
    line: tuple[Point, Point] | None = None
    direction: Point | None = None
    level_m: float | None = None
    file: Path | None = None


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
class FluxLine:
    """``[[flux_lines]]``: a named polyline through which the discharge is measured
    (``flux.csv``, ``floodsph.simulation.flux``). Water crossing it from the left of its
    direction of travel (first point to last) to the right counts positive."""

    name: str
    polyline: tuple[Point, ...]


@dataclass(frozen=True)
class OutputConfig:
    """``[output]``: where and what to write. ``directory = None`` means ``out/<name>``.

    ``checkpoint_interval_s`` [s of simulated time] > 0 writes a checkpoint at the first step
    at or after each multiple of it (``floodsph.simulation.checkpoint``); 0 writes none on a
    schedule
    (a stop signal still writes one).

    ``snapshot_times_s`` [s]: increasing times within the run at which snapshots are written
    as well (the time step lands on them), alone or with ``snapshot_interval_s``.
    """

    directory: Path | None = None
    resolution_m: float | None = None
    wet_threshold_m: float = 0.01
    formats: tuple[OutputFormat, ...] = (OutputFormat.GEOTIFF, OutputFormat.NETCDF)
    snapshot_interval_s: float = 0.0
    snapshot_times_s: tuple[float, ...] = ()
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
    level_boundaries: tuple[LevelBoundary, ...] = ()
    gauges: Gauges | None = None
    flux_lines: tuple[FluxLine, ...] = ()
    numerics: Numerics = Numerics()
    output: OutputConfig = OutputConfig()

    @property
    def name(self) -> str:
        return self.scenario.name

    @property
    def end_time_s(self) -> float:
        return self.scenario.end_time_s

    @property
    def start(self) -> datetime | None:
        """The calendar instant of t = 0 (``[scenario] start``, time zone aware), or None."""
        return self.scenario.start

    @property
    def flux_interval_s(self) -> float:
        """Simulated time between rows of ``flux.csv`` [s]: the gauges' interval, else the
        mass balance's."""
        if self.gauges is not None:
            return self.gauges.interval_s
        return self.output.mass_balance_interval_s

    @property
    def output_directory(self) -> Path:
        """The run folder: ``output.directory`` or ``<scenario folder>/out/<name>``."""
        if self.output.directory is not None:
            return self.output.directory
        return self.path.parent / "out" / self.name

    def input_files(self) -> tuple[Path, ...]:
        """The scenario file and every file it reads (a run never writes over them)."""
        t = self.terrain
        tiles = t.dem if isinstance(t.dem, tuple) else (t.dem,)
        files = [self.path, *tiles, t.landcover,
                 t.manning_table if isinstance(t.manning_table, Path) else None,
                 t.manning if isinstance(t.manning, Path) else None,
                 *(w.depth for w in self.initial_water),
                 *(entry.file for entry in self.initial_water),
                 *(entry.file for entry in self.walls),
                 *(entry.file for entry in self.sinks),
                 *(i.hydrograph for i in self.inflows),
                 *(b.file for b in self.level_boundaries),
                 None if self.gauges is None else self.gauges.file]
        return tuple(f for f in files if f is not None)

    def to_dict(self) -> dict:
        """The resolved scenario as plain JSON/TOML-able data (paths absolute, defaults filled).

        ``None`` values are left out, so the result reloads into an equal :class:`Scenario`.
        """
        out = {f.name: _plain(getattr(self, f.name)) for f in fields(self) if f.name != "path"}
        out["output"]["directory"] = str(self.output_directory)
        if not out["output"].get("snapshot_times_s"):
            out["output"].pop("snapshot_times_s", None)  # absent: as before the key existed
        return {k: v for k, v in out.items() if v is not None and v != []}

    def __repr__(self) -> str:
        return (
            f"Scenario({self.name!r}, end_time_s={self.end_time_s:g}, "
            f"dem={dem_label(self.terrain.dem)!r}, "
            f"initial_water={len(self.initial_water)}, walls={len(self.walls)}, "
            f"inflows={len(self.inflows)}, sinks={len(self.sinks)})"
        )


def dem_label(dem) -> str:
    """A DEM's file name, or ``a.tif + 3 tiles`` for a mosaic, for messages."""
    if isinstance(dem, tuple):
        return f"{dem[0].name} + {len(dem) - 1} tiles"
    return dem.name


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
    if isinstance(value, datetime):
        return value.isoformat()
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


TOP_KEYS = (
    "scenario",
    "terrain",
    "initial_water",
    "walls",
    "inflows",
    "sinks",
    "level_boundaries",
    "gauges",
    "flux_lines",
    "numerics",
    "output",
)
"""The tables of a scenario file, in the order of the contract."""

SIDES = ("west", "east", "south", "north")
"""The DEM border's sides, as ``terrain.closed_sides`` names them."""
