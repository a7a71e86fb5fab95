"""Malpasset dam failure (France, 2 Dec 1959) with floodsph on the 20 m EPSG:27572 DEM.

Reads the benchmark data from ``$FLOODSPH_BENCHMARKS/malpasset`` or
``<repo>/../shared/benchmarks/malpasset`` (never copied into the repository), writes a
scenario TOML (absolute paths to the data) and a gauges CSV into the results folder, and runs
it. Benchmark definition (SOURCE.md there): instantaneous total failure; reservoir at 100 m on
the upstream side of the dam axis, except a dry circle of radius 200 m; Manning n = 0.033;
closed boundaries; 4000 s. Local model frame to EPSG:27572:
``X = y_local + 953595``, ``Y = 1849222 - x_local`` (a rotation by -90 degrees, so the side
of a line is preserved).

Usage: ``python workflows/malpasset/run_malpasset.py --end-time 5 --out /tmp/mp``
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
DEM_NAME = "malpasset_dem_epsg27572_20m.tif"
DAM_LOCAL = ((4701.183, 4143.407), (4655.553, 4392.104))
DRY_CIRCLE_LOCAL = (4500.0, 5350.0, 200.0)
CIRCLE_VERTICES = 72
RESERVOIR_LEVEL_M = 100.0
MANNING_N = 0.033


def to_27572(x_local: float, y_local: float) -> tuple[float, float]:
    """Local Malpasset frame [m] to NTF (Paris) / Lambert zone II etendu (EPSG:27572) [m]."""
    return y_local + 953595.0, 1849222.0 - x_local


def data_folder() -> Path:
    """The malpasset benchmark folder, or exit with a message saying where it was looked for."""
    root = os.environ.get("FLOODSPH_BENCHMARKS")
    base = Path(root) if root else REPO.parent / "shared" / "benchmarks"
    folder = base / "malpasset"
    if not (folder / DEM_NAME).is_file():
        sys.exit(f"Malpasset data not found: {folder / DEM_NAME} is missing. Set "
                 "FLOODSPH_BENCHMARKS to the folder holding malpasset/.")
    return folder


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


def reservoir_polygon(bounds) -> list:
    """The DEM box upstream of the dam axis with the dry circle cut out as a keyhole.

    The hole is the upstream part of the circle (a regular polygon of CIRCLE_VERTICES
    vertices on the circle, clipped by the dam axis), joined to the first outer vertex by a
    zero-width slit traversed both ways: floodsph's even-odd point-in-polygon test counts the
    two slit edges twice, so they cancel and the hole stays dry.
    """
    left, bottom, right, top = bounds
    box = [(left, bottom), (right, bottom), (right, top), (left, top)]
    a, b = (to_27572(*p) for p in DAM_LOCAL)
    outer = clip_left(box, a, b)
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


def write_gauges(folder: Path, path: Path) -> Path:
    """gauge_locations.csv -> ``id,x,y`` in EPSG:27572 (converted from the local frame)."""
    with open(folder / "gauge_locations.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["id", "x", "y"])
        for row in rows:
            x, y = to_27572(float(row["x_local_m"]), float(row["y_local_m"]))
            w.writerow([row["id"], f"{x:.1f}", f"{y:.1f}"])
    return path


def write_scenario(folder: Path, out: Path, end_time: float, spacing: float) -> Path:
    """The scenario TOML in ``out`` (absolute data paths); returns its path."""
    import rasterio

    from floodsph.toml_writer import dumps

    dem = folder / DEM_NAME
    with rasterio.open(dem) as src:
        bounds = tuple(src.bounds)
    gauges = write_gauges(folder, out / "gauges_epsg27572.csv")
    scenario = {
        "scenario": {
            "name": "malpasset",
            "end_time_s": end_time,
            "description": "Malpasset dam failure 1959: instantaneous total failure, "
                           "reservoir at 100 m; sea dry, closed domain (no sinks yet)",
        },
        "terrain": {"dem": str(dem), "manning": MANNING_N, "edges": "closed"},
        "initial_water": [{"level_m": RESERVOIR_LEVEL_M,
                           "polygon": reservoir_polygon(bounds)}],
        "gauges": {"file": str(gauges), "interval_s": 10.0},
        "numerics": {"particle_spacing_m": spacing},
    }
    path = out / "malpasset.toml"
    path.write_text(dumps(scenario), encoding="utf-8")
    return path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time", type=float, default=4000.0, help="simulated time [s]")
    parser.add_argument("--spacing", type=float, default=20.0,
                        help="particle_spacing_m [m] (default 20, the DEM cell)")
    parser.add_argument("--out", type=Path, default=REPO / "workflows" / "malpasset" / "results",
                        help="results folder (scenario, gauges, run folder 'run/')")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run")
    args = parser.parse_args(argv)

    folder = data_folder()
    from floodsph.run import run_scenario
    from floodsph.scenario import load_scenario

    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    path = write_scenario(folder, out, args.end_time, args.spacing)
    manifest = run_scenario(load_scenario(path), out_dir=out / "run", overwrite=args.overwrite)
    print(f"{manifest['status']}: t = {manifest['sim_time_s']:g} s, {manifest['steps']} steps, "
          f"{manifest['particles_initial']} particles, mass error "
          f"{manifest['mass_error_rel']:.2e}; maps in {out / 'run'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
