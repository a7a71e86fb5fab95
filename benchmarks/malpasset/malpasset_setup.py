"""The Malpasset benchmark as a floodsph scenario: data folder, polygons, points, TOML.

Benchmark definition (``malpasset/SOURCE.md`` of the benchmark data, which is third-party and
never copied into this repository): instantaneous total failure of the dam at t = 0; the
reservoir at 100 m on the upstream side of the dam axis, except a dry circle of radius 200 m;
the sea at rest at 0 m (every DEM cell with its bed below 0 m starts wet, as in TELEMAC's
geometry file); Manning n = 0.033; closed boundaries; 4000 s.

Local model frame to NTF (Paris) / Lambert zone II etendu (EPSG:27572), exact (SOURCE.md):
``X = y_local + 953595``, ``Y = 1849222 - x_local`` (a rotation by -90 degrees plus a shift,
so the side of a line is preserved).

The sea is modelled in one of two ways (``SEA_MODES``):

* ``"particles"``: ``[[initial_water]]`` at level 0 m over the whole DEM box. The only cells
  of the DEM below 0 m are the sea (one connected area on the coast), so this fills exactly
  the benchmark's sea cells. The flood that reaches the coast runs into still water.
* ``"sink"``: a ``[[sinks]]`` polygon, the outline of the DEM cells below 0 m (cell edges,
  traced with ``rasterio.features.shapes``); water entering it leaves the model and is
  counted as outflow. No sea particles: cheaper, but no backwater from the sea.
"""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
DEM_NAME = "malpasset_dem_epsg27572_20m.tif"
POINTS_NAME = "gauge_locations.csv"
DAM_LOCAL = ((4701.183, 4143.407), (4655.553, 4392.104))
DRY_CIRCLE_LOCAL = (4500.0, 5350.0, 200.0)
CIRCLE_VERTICES = 72
RESERVOIR_LEVEL_M = 100.0
SEA_LEVEL_M = 0.0
MANNING_N = 0.033
END_TIME_S = 4000.0
SEA_MODES = ("particles", "sink")


def to_27572(x_local: float, y_local: float) -> tuple[float, float]:
    """Local Malpasset frame [m] to NTF (Paris) / Lambert zone II etendu (EPSG:27572) [m]."""
    return y_local + 953595.0, 1849222.0 - x_local


def data_folder() -> Path | None:
    """``$FLOODSPH_BENCHMARKS/malpasset`` or ``<repo>/../shared/benchmarks/malpasset``.

    None when the DEM is not there (the caller exits or skips with a message).
    """
    root = os.environ.get("FLOODSPH_BENCHMARKS")
    base = Path(root) if root else REPO.parent / "shared" / "benchmarks"
    folder = base / "malpasset"
    return folder if (folder / DEM_NAME).is_file() else None


def clip_left(poly: list, a, b) -> list:
    """Sutherland-Hodgman: the part of polygon ``poly`` left of the line a -> b.

    Left means cross(b - a, p - a) > 0, the upstream (reservoir) side of the dam axis as
    ordered in the benchmark (TELEMAC corsui.f signed distance > 0).
    """
    def side(p):
        return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])

    out = []
    for k, p in enumerate(poly):
        q = poly[(k + 1) % len(poly)]
        sp, sq = side(p), side(q)
        if sp >= 0:
            out.append(p)
        if (sp >= 0) != (sq >= 0):
            t = sp / (sp - sq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    return out


def dem_bounds(folder: Path) -> tuple[float, float, float, float]:
    """(left, bottom, right, top) of the DEM [m, EPSG:27572]."""
    import rasterio

    with rasterio.open(folder / DEM_NAME) as src:
        return tuple(src.bounds)


def box(bounds) -> list:
    """The rectangle ``bounds`` as a closed ring of [x, y] pairs."""
    left, bottom, right, top = bounds
    return [[left, bottom], [right, bottom], [right, top], [left, top], [left, bottom]]


def reservoir_polygon(bounds) -> list:
    """The DEM box upstream of the dam axis with the dry circle cut out as a keyhole.

    The hole is the upstream part of the circle (a regular polygon of CIRCLE_VERTICES
    vertices on the circle, clipped by the dam axis), joined to the first outer vertex by a
    zero-width slit traversed both ways: floodsph's even-odd point-in-polygon test counts the
    two slit edges twice, so they cancel and the hole stays dry.
    """
    a, b = (to_27572(*p) for p in DAM_LOCAL)
    outer = clip_left([tuple(p) for p in box(bounds)[:-1]], a, b)
    cx, cy = to_27572(DRY_CIRCLE_LOCAL[0], DRY_CIRCLE_LOCAL[1])
    r = DRY_CIRCLE_LOCAL[2]
    circle = [(cx + r * math.cos(2 * math.pi * k / CIRCLE_VERTICES),
               cy - r * math.sin(2 * math.pi * k / CIRCLE_VERTICES))
              for k in range(CIRCLE_VERTICES)]
    # The circle straddles the extended dam axis: only its upstream part is a hole (the rest
    # is outside the reservoir anyway, and would be filled by the even-odd rule otherwise).
    hole = clip_left(circle, a, b)
    ring = [outer[0], *hole, hole[0], outer[0], *outer[1:], outer[0]]
    return [[round(x, 3), round(y, 3)] for x, y in ring]


def sea_outline(folder: Path) -> list:
    """The outline (cell edges) of the DEM cells whose bed is below SEA_LEVEL_M.

    Raises ValueError unless those cells form one connected area without holes (true for the
    benchmark DEM; a sink polygon cannot have holes).
    """
    import numpy as np
    import rasterio
    from rasterio import features

    with rasterio.open(folder / DEM_NAME) as src:
        bed = src.read(1, masked=True)
        transform = src.transform
    sea = (bed < SEA_LEVEL_M).filled(False).astype(np.uint8)
    shapes = [geom for geom, _ in features.shapes(sea, mask=sea.astype(bool),
                                                   transform=transform)]
    if len(shapes) != 1 or len(shapes[0]["coordinates"]) != 1:
        raise ValueError(f"{folder / DEM_NAME}: the cells below {SEA_LEVEL_M} m are not one "
                         "area without holes; cannot draw one sink polygon")
    return [[float(x), float(y)] for x, y in shapes[0]["coordinates"][0]]


def read_points(folder: Path) -> list[dict]:
    """P1-P17, S6-S14 and A-C from gauge_locations.csv: id, type, x, y (EPSG:27572) [m].

    The EPSG:27572 columns of the file are used; ValueError if they disagree with the local
    columns converted by :func:`to_27572` by more than 0.15 m (they are rounded to 0.1 m).
    """
    path = folder / POINTS_NAME
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    out = []
    for row in rows:
        x, y = float(row["x_epsg27572_m"]), float(row["y_epsg27572_m"])
        xc, yc = to_27572(float(row["x_local_m"]), float(row["y_local_m"]))
        if math.hypot(x - xc, y - yc) > 0.15:
            raise ValueError(f"{path}: point {row['id']}: EPSG:27572 ({x}, {y}) disagrees with "
                             f"the local frame converted ({xc:.1f}, {yc:.1f})")
        out.append({"id": row["id"], "type": row["type"], "x": x, "y": y})
    return out


def write_gauges(points: list[dict], path: Path) -> Path:
    """The points as a floodsph gauge file ``id,x,y``."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["id", "x", "y"])
        for p in points:
            w.writerow([p["id"], f"{p['x']:.1f}", f"{p['y']:.1f}"])
    return path


def scenario_dict(dem: str, bounds, sea: str, end_time: float, spacing: float,
                  gauges: str | None = None, gauge_interval: float = 5.0,
                  sea_outline_ring: list | None = None, numerics: dict | None = None) -> dict:
    """The Malpasset scenario (docs/scenario-reference.md) as plain data for ``tomli_w.dumps``.

    ``sea`` is one of SEA_MODES; ``"sink"`` needs ``sea_outline_ring`` (:func:`sea_outline`).
    ``numerics``: further keys of the ``[numerics]`` table, such as ``refinement`` (default:
    floodsph's).
    """
    if sea not in SEA_MODES:
        raise ValueError(f"sea must be one of {SEA_MODES}, got {sea!r}")
    water = [{"level_m": RESERVOIR_LEVEL_M, "polygon": reservoir_polygon(bounds)}]
    if sea == "particles":
        water.append({"level_m": SEA_LEVEL_M, "polygon": box(bounds)})
    out = {
        "scenario": {
            "name": f"malpasset-sea-{sea}",
            "end_time_s": float(end_time),
            "description": "Malpasset dam failure 1959: instantaneous total failure, reservoir "
                           f"at 100 m, closed domain; the sea as {sea}",
        },
        "terrain": {"dem": dem, "manning": MANNING_N, "edges": "closed"},
        "initial_water": water,
    }
    if sea == "sink":
        if sea_outline_ring is None:
            raise ValueError("sea = 'sink' needs the sea outline polygon")
        out["sinks"] = [{"polygon": sea_outline_ring}]
    if gauges is not None:
        out["gauges"] = {"file": gauges, "interval_s": float(gauge_interval)}
    out["numerics"] = {"particle_spacing_m": float(spacing), **(numerics or {})}
    return out


def write_scenario(folder: Path, out: Path, sea: str, end_time: float, spacing: float,
                   gauge_interval: float = 5.0, numerics: dict | None = None) -> Path:
    """``out/malpasset.toml`` (absolute paths to the data) and ``out/gauges_epsg27572.csv``."""
    from tomli_w import dumps

    out.mkdir(parents=True, exist_ok=True)
    gauges = write_gauges(read_points(folder), out / "gauges_epsg27572.csv")
    ring = sea_outline(folder) if sea == "sink" else None
    data = scenario_dict(str(folder / DEM_NAME), dem_bounds(folder), sea, end_time, spacing,
                         gauges=str(gauges), gauge_interval=gauge_interval,
                         sea_outline_ring=ring, numerics=numerics)
    path = out / "malpasset.toml"
    path.write_text(dumps(data), encoding="utf-8")
    return path


STATIC_HEADER = """\
# Malpasset dam failure (2 Dec 1959): the benchmark scenario in EPSG:27572 with the sea as
# particles, for the standard layout where the benchmark data sits in
# <repo>/../shared/benchmarks (not in this repository). Written by
# `python benchmarks/malpasset/run_malpasset.py --write-static`; run_malpasset.py adds the
# gauges and offers the sea as a sink (--sea sink). See README.md.

"""


def write_static_scenario(folder: Path, path: Path) -> Path:
    """The repository's ``scenario.toml``: no gauges, DEM path relative to ``path``."""
    from tomli_w import dumps

    dem = os.path.relpath(folder / DEM_NAME, path.parent)
    data = scenario_dict(dem, dem_bounds(folder), "particles", END_TIME_S, 20.0)
    path.write_text(STATIC_HEADER + dumps(data), encoding="utf-8")
    return path
