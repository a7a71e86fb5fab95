"""The still-water benchmark's cases as scenario folders: a DEM GeoTIFF and a scenario TOML.

Every case is what a user would run: a DEM, ``[[initial_water]]``, ``[[walls]]`` polylines,
closed edges and floodsph's default numerics, written into its own folder and run by
``benchmarks/still_water.py`` through ``floodsph.run.pipeline.run_scenario``.

* ``rectangle``: 2 m of water in a 300 m x 180 m rectangle of walls (a closed polyline)
  turned by 0, 15, 30 and 45 degrees on a flat 5 m DEM, 5 m spacing;
* ``staircase``: 2 m of water on a flat 300 m x 200 m DEM whose cells north-west of its
  south-west to north-east diagonal are nodata (the nodata border is a wall: closed edges);
* ``bowl``: the parabolic bowl b = a r^2 filled to the level L = 3 m, a chosen so that the
  shore r_s = 200 m lies on a 3 % slope (2 a r_s = 0.03);
* ``building``: 2 m of water in a 400 m x 300 m basin around a 100 m square footprint
  turned by 30 degrees (a closed polyline; the water polygon has the footprint cut out);
* ``dam-break``: Ritter's dam break of ``floodsph.verification.cases`` (10 m of water behind a dam
  half-way along a 2000 m x 100 m channel, dry downstream, 50 s, 10 m spacing) in a channel
  of walls along x and in one turned by 30 degrees;
* ``malpasset``: the Malpasset reservoir at rest (20 m DEM, the reservoir at 100 m from
  ``malpasset/malpasset_setup.reservoir_polygon``, n = 0.033, closed edges, a wall along the
  dam line), read from the benchmark data (third-party, not in this repository).

The synthetic beds are frictionless in effect: a scenario needs Manning's n > 0, and
n = 1e-6 s m^-1/3 gives a friction slope 1e-12 times that of n = 1. ``quick`` makes each
synthetic case a few hundred particles (smaller basins, same spacing and slopes), for tests.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent / "malpasset"))

import malpasset_setup as mp_setup  # noqa: E402

CRS = "EPSG:32632"
ORIGIN = (500_000.0, 4_000_000.0)
"""World coordinates [m] of the lower-left corner of every synthetic DEM."""
FRICTIONLESS_N = 1e-6
"""Manning's n [s m^-1/3] of the synthetic beds (module docstring)."""
LAKE_DEPTH_M = 2.0
BOWL_SLOPE = 0.03
RECTANGLE_ANGLES = (0.0, 15.0, 30.0, 45.0)
DAM_BREAK_ANGLES = (0.0, 30.0)
DAM_WALL_OVERHANG_M = 40.0
"""The Malpasset dam wall runs this far beyond each end of the dam axis, into the nodata of
the valley sides, so that no gap is left between it and the walls of the nodata border."""
MALPASSET_SPACING_M = 20.0
H0_NAME = "malpasset_h0_epsg27572_20m.tif"


@dataclass(frozen=True)
class Limits:
    """The issue's targets of a still-water case (None: no target)."""

    max_speed: float | None = None
    """largest particle speed at any report time [m/s]"""
    p95_speed: float | None = None
    """95th percentile of the particle speeds at any report time [m/s]"""
    level: float | None = None
    """largest |d + b - L| over the particles at any report time [m]"""
    shore: float | None = None
    """largest distance of the shore from its place at any report time [m]"""
    outside_cells: int | None = None
    """map cells wet (max_depth > the wet threshold) outside the initial water"""


@dataclass(frozen=True)
class Shore:
    """A circular shoreline: centre (world) [m] and radius [m]."""

    x: float
    y: float
    radius: float


@dataclass(frozen=True)
class Channel:
    """A straight channel of walls: origin (world, upstream right-hand corner) [m], the angle
    of its axis to x [degrees], length and width [m]; Ritter's dam at ``x_dam`` along it,
    ``d0`` [m] of water upstream, measured at ``t_end`` [s]."""

    x0: float
    y0: float
    angle: float
    length: float
    width: float
    x_dam: float
    d0: float
    t_end: float

    def axes(self) -> tuple[np.ndarray, np.ndarray]:
        """Unit vectors along and across the channel."""
        t = math.radians(self.angle)
        return np.array([math.cos(t), math.sin(t)]), np.array([-math.sin(t), math.cos(t)])

    def to_world(self, s, n) -> tuple[np.ndarray, np.ndarray]:
        """Channel coordinates (s along from the upstream end, n across from the right
        wall) [m] to world coordinates [m]."""
        along, across = self.axes()
        s, n = np.asarray(s, dtype=float), np.asarray(n, dtype=float)
        return (self.x0 + s * along[0] + n * across[0], self.y0 + s * along[1] + n * across[1])

    def to_channel(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """World coordinates [m] to channel coordinates (s, n) [m]."""
        along, across = self.axes()
        dx, dy = np.asarray(x) - self.x0, np.asarray(y) - self.y0
        return dx * along[0] + dy * along[1], dx * across[0] + dy * across[1]

    def ring(self, s_end: float | None = None) -> list:
        """The channel (up to ``s_end`` along it, default its length) as a closed ring."""
        s = [0.0, self.length if s_end is None else s_end]
        x, y = self.to_world([s[0], s[1], s[1], s[0], s[0]], [0.0, 0.0, self.width,
                                                               self.width, 0.0])
        return [[round(float(a), 6), round(float(b), 6)] for a, b in zip(x, y, strict=True)]


@dataclass(frozen=True)
class Case:
    """One run of the benchmark: its scenario file and what it is measured against."""

    kind: str
    """the case's name in ``--cases``"""
    label: str
    """its row in the tables"""
    scenario: Path
    level_m: float | None = None
    """the still-water level [m]; None for the dam break"""
    limits: Limits = Limits()
    shore: Shore | None = None
    channel: Channel | None = None
    reservoir: np.ndarray | None = None
    """Malpasset: the reservoir's DEM cells (north-up, True = initially wet)"""


def write_dem(path: Path, z: np.ndarray, cell: float, x0: float = ORIGIN[0],
              y0: float = ORIGIN[1], nodata: float = -9999.0) -> Path:
    """A north-up float32 GeoTIFF of ``z`` (row 0 = north, NaN = nodata) with its
    lower-left corner at (x0, y0) [m]."""
    import rasterio
    from rasterio.transform import Affine

    z = np.where(np.isfinite(z), z, nodata).astype(np.float32)
    transform = Affine(cell, 0.0, x0, 0.0, -cell, y0 + z.shape[0] * cell)
    with rasterio.open(path, "w", driver="GTiff", width=z.shape[1], height=z.shape[0],
                       count=1, dtype="float32", crs=CRS, transform=transform,
                       nodata=nodata) as dst:
        dst.write(z, 1)
    return path


def cell_centres(shape: tuple[int, int], cell: float) -> tuple[np.ndarray, np.ndarray]:
    """World x and y [m] of the cell centres of a north-up synthetic DEM."""
    ny, nx = shape
    x = ORIGIN[0] + (np.arange(nx) + 0.5) * cell
    y = ORIGIN[1] + (ny - np.arange(ny) - 0.5) * cell
    return np.meshgrid(x, y)


def box(width: float, height: float) -> list:
    """The synthetic DEM's outline as a closed ring [m]."""
    x0, y0 = ORIGIN
    return [[x0, y0], [x0 + width, y0], [x0 + width, y0 + height], [x0, y0 + height],
            [x0, y0]]


def turned_rectangle(cx: float, cy: float, half_x: float, half_y: float,
                     angle: float) -> list:
    """The rectangle of half-sides (half_x, half_y) [m] centred at (cx, cy), turned by
    ``angle`` degrees anticlockwise, as a closed ring [m]."""
    t = math.radians(angle)
    ring = []
    for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1)):
        px, py = sx * half_x, sy * half_y
        ring.append([round(cx + px * math.cos(t) - py * math.sin(t), 6),
                     round(cy + px * math.sin(t) + py * math.cos(t), 6)])
    return ring


def keyhole(outer: list, hole: list) -> list:
    """One ring: ``outer`` with ``hole`` cut out through a zero-width slit from the first
    vertex of each (the even-odd inside test of ``[[initial_water]]`` counts the slit twice,
    so the hole stays dry)."""
    return [*outer[:-1], outer[0], *hole[:-1], hole[0], outer[0]]


def scenario_text(name: str, end_time: float, dem: str, manning: float, water: list,
                  walls: list, spacing: float) -> str:
    """A scenario TOML (docs/scenario-reference.md): closed edges, default numerics, GeoTIFF
    maps."""
    from tomli_w import dumps

    data = {
        "scenario": {"name": name, "end_time_s": float(end_time),
                     "description": "still-water benchmark (benchmarks/still_water.py)"},
        "terrain": {"dem": dem, "manning": manning, "edges": "closed"},
        "initial_water": water,
        "walls": [{"polyline": w} for w in walls],
        "numerics": {"particle_spacing_m": float(spacing)},
        "output": {"formats": ["geotiff"]},
    }
    if not walls:
        del data["walls"]
    return dumps(data)


def _write(folder: Path, name: str, end_time: float, z: np.ndarray, cell: float, water: list,
           walls: list, spacing: float) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    write_dem(folder / "dem.tif", z, cell)
    path = folder / "scenario.toml"
    path.write_text(scenario_text(name, end_time, "dem.tif", FRICTIONLESS_N, water, walls,
                                  spacing), encoding="utf-8")
    return path


def rectangle(folder: Path, angle: float, end_time: float, quick: bool) -> Case:
    """2 m of water inside a rectangle of walls turned by ``angle`` degrees."""
    side, half = (140.0, (50.0, 30.0)) if quick else (400.0, (150.0, 90.0))
    cell = 5.0
    n = int(side / cell)
    wall = turned_rectangle(ORIGIN[0] + side / 2, ORIGIN[1] + side / 2, *half, angle)
    path = _write(folder, f"rectangle-{angle:g}", end_time, np.zeros((n, n)), cell,
                  [{"level_m": LAKE_DEPTH_M, "polygon": wall}], [wall], cell)
    return Case("rectangle", f"rectangle {angle:g} deg", path, LAKE_DEPTH_M,
                Limits(max_speed=0.01))


def staircase(folder: Path, end_time: float, quick: bool) -> Case:
    """2 m of water bounded by a nodata staircase: the cells north-west of the DEM's
    south-west to north-east diagonal are nodata."""
    width, height = (100.0, 60.0) if quick else (300.0, 200.0)
    cell = 5.0
    X, Y = cell_centres((int(height / cell), int(width / cell)), cell)
    z = np.where((Y - ORIGIN[1]) * width > (X - ORIGIN[0]) * height, np.nan, 0.0)
    path = _write(folder, "staircase", end_time, z, cell,
                  [{"level_m": LAKE_DEPTH_M, "polygon": box(width, height)}], [], cell)
    return Case("staircase", "nodata staircase", path, LAKE_DEPTH_M, Limits(max_speed=0.01))


def bowl(folder: Path, end_time: float, quick: bool) -> Case:
    """The parabolic bowl b = a r^2 filled to L, the shore r_s on a 3 % slope."""
    level = 1.5 if quick else 3.0
    r_s = 2.0 * level / BOWL_SLOPE  # L = a r_s^2 and 2 a r_s = slope
    a = level / r_s**2
    cell = 5.0
    side = 2.0 * r_s + 60.0
    n = int(round(side / cell))
    side = n * cell
    cx, cy = ORIGIN[0] + side / 2, ORIGIN[1] + side / 2
    X, Y = cell_centres((n, n), cell)
    z = a * ((X - cx) ** 2 + (Y - cy) ** 2)
    path = _write(folder, "bowl", end_time, z, cell,
                  [{"level_m": level, "polygon": box(side, side)}], [], cell)
    return Case("bowl", "parabolic bowl", path, level,
                Limits(max_speed=0.03, p95_speed=0.01, shore=cell), shore=Shore(cx, cy, r_s))


def building(folder: Path, end_time: float, quick: bool) -> Case:
    """2 m of water around a square footprint (a closed wall) turned by 30 degrees."""
    width, height, half = (150.0, 120.0, 20.0) if quick else (400.0, 300.0, 50.0)
    cell = 5.0
    footprint = turned_rectangle(ORIGIN[0] + width / 2, ORIGIN[1] + height / 2, half, half,
                                 30.0)
    water = keyhole(box(width, height), footprint)
    path = _write(folder, "building", end_time, np.zeros((int(height / cell),
                                                          int(width / cell))), cell,
                  [{"level_m": LAKE_DEPTH_M, "polygon": water}], [footprint], cell)
    return Case("building", "building 30 deg", path, LAKE_DEPTH_M, Limits(max_speed=0.01))


def dam_break(folder: Path, angle: float, end_time: float, quick: bool) -> Case:
    """Ritter's dam break in a channel of walls whose axis is turned by ``angle`` degrees,
    measured at ``end_time`` [s] (``floodsph.verification.cases.ritter``: 50 s).

    The channel's upstream right-hand corner lies 50 m in from the DEM's south-west corner
    (at 30 degrees, 50 m in from the west and ``width sin 30`` higher, so the turned
    channel fits); the 10 m DEM cells and the particle lattice share the DEM's origin, so
    the walls of the channel along x lie on lattice cell edges.
    """
    length, t_end = (600.0 if quick else 2000.0), end_time
    width, d0, spacing, margin = 100.0, 10.0, 10.0, 50.0
    t = math.radians(angle)
    x0 = ORIGIN[0] + margin + width * math.sin(t)
    y0 = ORIGIN[1] + margin
    channel = Channel(x0, y0, angle, length, width, length / 2, d0, t_end)
    nx = int(math.ceil((length * math.cos(t) + width * math.sin(t) + 2 * margin) / spacing))
    ny = int(math.ceil((length * math.sin(t) + width * math.cos(t) + 2 * margin) / spacing))
    path = _write(folder, f"dam-break-{angle:g}", t_end, np.zeros((ny, nx)), spacing,
                  [{"level_m": d0, "polygon": channel.ring(channel.x_dam)}],
                  [channel.ring()], spacing)
    return Case("dam-break", f"dam break {angle:g} deg", path, channel=channel)


def reservoir_cells(data: Path) -> np.ndarray:
    """The Malpasset reservoir's cells of the 20 m DEM (north-up): where the benchmark's
    initial depth raster holds water whose surface is at 100 m."""
    import rasterio

    with rasterio.open(data / mp_setup.DEM_NAME) as dem, rasterio.open(data / H0_NAME) as h0:
        if dem.transform != h0.transform or dem.shape != h0.shape:
            raise ValueError(f"{data / H0_NAME} is not on the grid of {mp_setup.DEM_NAME}")
        z = dem.read(1, masked=True)
        d = h0.read(1, masked=True)
    surface = (d > 0) & (np.abs(d + z - mp_setup.RESERVOIR_LEVEL_M) < 1e-3)
    return np.asarray(surface.filled(False))


def dam_wall(overhang: float = DAM_WALL_OVERHANG_M) -> list:
    """The Malpasset dam axis in EPSG:27572, ``overhang`` [m] longer at each end."""
    (ax, ay), (bx, by) = (mp_setup.to_27572(*p) for p in mp_setup.DAM_LOCAL)
    length = math.hypot(bx - ax, by - ay)
    ux, uy = (bx - ax) / length, (by - ay) / length
    return [[round(ax - overhang * ux, 3), round(ay - overhang * uy, 3)],
            [round(bx + overhang * ux, 3), round(by + overhang * uy, 3)]]


def malpasset(folder: Path, end_time: float, data: Path) -> Case:
    """The Malpasset reservoir at rest behind a wall along the dam line."""
    from tomli_w import dumps

    folder.mkdir(parents=True, exist_ok=True)
    bounds = mp_setup.dem_bounds(data)
    scenario = {
        "scenario": {"name": "malpasset-at-rest", "end_time_s": float(end_time),
                     "description": "the Malpasset reservoir at rest behind a wall along the "
                                    "dam line (benchmarks/still_water.py)"},
        "terrain": {"dem": str(data / mp_setup.DEM_NAME), "manning": mp_setup.MANNING_N,
                    "edges": "closed"},
        "initial_water": [{"level_m": mp_setup.RESERVOIR_LEVEL_M,
                           "polygon": mp_setup.reservoir_polygon(bounds)}],
        "walls": [{"polyline": dam_wall()}],
        "numerics": {"particle_spacing_m": MALPASSET_SPACING_M},
        "output": {"formats": ["geotiff"]},
    }
    path = folder / "scenario.toml"
    path.write_text(dumps(scenario), encoding="utf-8")
    return Case("malpasset", "Malpasset at rest", path, mp_setup.RESERVOIR_LEVEL_M,
                Limits(max_speed=0.05, p95_speed=0.01, level=0.05, outside_cells=0),
                reservoir=reservoir_cells(data))
