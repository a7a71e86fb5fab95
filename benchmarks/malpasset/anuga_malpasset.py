"""Malpasset with ANUGA on the benchmark's triangle mesh, the bed taken from the 20 m DEM.

The reference run of the Malpasset pages: ANUGA 4 (Roberts et al., ANUGA user manual,
Geoscience Australia; flow algorithm DE0, a second-order well-balanced finite-volume scheme on
triangles) on the TELEMAC geometry of the benchmark (``mesh_small_nodes.csv`` /
``mesh_small_triangles.csv``: 13 541 nodes, 26 000 triangles, local frame converted to
EPSG:27572 with ``malpasset_setup.to_27572``), set up one-to-one with floodsph's inputs:

* bed: the 20 m DEM cell holding each triangle centroid (``floodsph.inputs.prepare.prepare_inputs``
  fills the few nodata cells under the mesh edge from the nearest valid cell), so both codes
  see the same 20 m bed, not TELEMAC's node elevations;
* initial water: floodsph's initial depth grid of the benchmark state (reservoir at 100 m in
  the keyhole polygon of ``malpasset_setup.reservoir_polygon``, every cell below 0 m at 0 m),
  stage = bed + depth of the centroid's cell, at rest;
* Manning n = 0.033; every mesh edge on the outline a wall (``Reflective_boundary``);
  instantaneous failure at t = 0, 4000 s.

Outputs (``--out``, an ANUGA run folder read like a floodsph run folder by
``malpasset_results.point_table``): ``max_depth.tif`` and ``max_level.tif`` on the DEM grid
(per DEM cell, the value of the triangle holding the cell centre; NaN outside the mesh; the
maxima are ``Collect_max_quantities_operator`` values, updated every step, together with the
initial state), ``gauges.csv`` (``time_s,id,depth_m,level_m,speed_ms`` every
``--gauge-interval`` s, centroid values of the triangle holding each of the 29 points) and
``run.json`` (triangles, steps, wall time of the set-up and ``evolve``, threads, volumes).

Needs ANUGA (``pip install anuga``); without it, or without the benchmark data, the script
prints that and exits with status 0.

Usage: ``OMP_NUM_THREADS=1 python benchmarks/malpasset/anuga_malpasset.py --out DIR
[--threads 1] [--end-time 4000] [--gauge-interval 5]``
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

import malpasset_setup as setup  # noqa: E402
import versus_grid_code as grid_code  # noqa: E402

NODES_NAME = "mesh_small_nodes.csv"
TRIANGLES_NAME = "mesh_small_triangles.csv"
GAUGE_HEADER = ("time_s", "id", "depth_m", "level_m", "speed_ms")
PROGRESS_EVERY = 100
"""A progress line every this many gauge samples."""
DRY_M = 1e-3
"""A cell whose maximum depth never exceeds this [m] gets no maximum level (NaN)."""


def read_mesh(folder: Path) -> tuple[np.ndarray, np.ndarray]:
    """The benchmark's small mesh: node coordinates in EPSG:27572 [m], (n, 2), and triangles
    as 0-based node indices, (m, 3)."""
    with open(folder / NODES_NAME, newline="") as f:
        rows = list(csv.DictReader(f))
    local = np.array([(float(r["x_local_m"]), float(r["y_local_m"])) for r in rows])
    nodes = np.column_stack(setup.to_27572(local[:, 0], local[:, 1]))
    triangles = np.loadtxt(folder / TRIANGLES_NAME, delimiter=",", skiprows=1, dtype=np.int64)
    return nodes, triangles


def counter_clockwise(nodes: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """The triangles with their vertices in anticlockwise order (ANUGA requires it).

    The local-to-EPSG:27572 map is a rotation, so the TELEMAC orientation is kept; the check
    makes the order explicit rather than assumed.
    """
    a, b, c = (nodes[triangles[:, k]] for k in range(3))
    signed = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    out = triangles.copy()
    flip = signed < 0
    out[flip, 1], out[flip, 2] = triangles[flip, 2], triangles[flip, 1]
    return out


def benchmark_inputs(folder: Path):
    """floodsph's inputs of the benchmark state (reservoir and sea as initial water)."""
    from floodsph.inputs.prepare import prepare_inputs
    from floodsph.scenario.reader import load_scenario

    with tempfile.TemporaryDirectory() as tmp:
        path = setup.write_scenario(folder, Path(tmp), "particles", setup.END_TIME_S, 20.0)
        return prepare_inputs(load_scenario(path))


def triangle_of_points(nodes_local: np.ndarray, triangles: np.ndarray, x, y) -> np.ndarray:
    """Index of the triangle holding each point (local coordinates), -1 outside the mesh."""
    from matplotlib.tri import Triangulation

    tri = Triangulation(nodes_local[:, 0], nodes_local[:, 1], triangles)
    return np.asarray(tri.get_trifinder()(np.asarray(x, float), np.asarray(y, float)))


def on_grid(values: np.ndarray, cell_triangle: np.ndarray, shape) -> np.ndarray:
    """Per-triangle values on the DEM grid (row 0 = south) by the triangle holding each cell
    centre; NaN outside the mesh."""
    flat = np.where(cell_triangle >= 0, values[np.maximum(cell_triangle, 0)], np.nan)
    return flat.reshape(shape)


def run(folder: Path, out: Path, threads: int, end_time: float, gauge_interval: float) -> dict:
    """Set up and run ANUGA, write the run folder; returns the ``run.json`` content."""
    anuga = grid_code.import_anuga()
    from anuga.operators.collect_max_quantities_operator import (
        Collect_max_quantities_operator,
    )

    start = time.perf_counter()
    inputs = benchmark_inputs(folder)
    terrain = inputs.terrain
    nodes, triangles = read_mesh(folder)
    nodes_local = np.column_stack(terrain.to_local(nodes[:, 0], nodes[:, 1]))
    triangles = counter_clockwise(nodes_local, triangles)
    anuga.set_omp_num_threads(threads, verbose=False)
    domain = anuga.Domain(nodes_local, triangles)
    domain.set_name("anuga_malpasset")
    domain.set_datadir(str(out))
    domain.set_store(False)
    centroids = domain.centroid_coordinates
    cells = grid_code.cell_index(centroids[:, 0], centroids[:, 1], terrain.dx, terrain.dy,
                                 terrain.shape)
    bed = grid_code.grid_to_centroids(terrain.elevation, cells)
    depth0 = grid_code.grid_to_centroids(inputs.depth, cells)
    domain.set_quantity("elevation", bed, location="centroids")
    domain.set_quantity("friction", setup.MANNING_N, location="centroids")
    domain.set_quantity("stage", bed + depth0, location="centroids")
    domain.set_boundary({tag: anuga.Reflective_boundary(domain)
                         for tag in domain.get_boundary_tags()})
    maxima = Collect_max_quantities_operator(domain)
    points = setup.read_points(folder)
    px, py = terrain.to_local([p["x"] for p in points], [p["y"] for p in points])
    gauge_tri = triangle_of_points(nodes_local, triangles, px, py)
    if np.any(gauge_tri < 0):
        missing = [p["id"] for p, k in zip(points, gauge_tri, strict=True) if k < 0]
        raise SystemExit(f"points outside the ANUGA mesh: {missing}")
    volume0 = float(domain.get_water_volume())
    setup_s = time.perf_counter() - start
    stage_q, bed_q = domain.quantities["stage"], domain.quantities["elevation"]
    xmom, ymom = domain.quantities["xmomentum"], domain.quantities["ymomentum"]
    rows, steps = [], 0
    for t in domain.evolve(yieldstep=gauge_interval, finaltime=end_time):
        steps += domain.number_of_steps
        if round(t / gauge_interval) % PROGRESS_EVERY == 0:
            print(f"t = {t:g} s, {steps} steps, {time.perf_counter() - start:.0f} s wall",
                  flush=True)
        stage = stage_q.centroid_values[gauge_tri]
        depth = stage - bed_q.centroid_values[gauge_tri]
        flux = np.hypot(xmom.centroid_values[gauge_tri], ymom.centroid_values[gauge_tri])
        for p, d, s, q in zip(points, depth, stage, flux, strict=True):
            wet = d > DRY_M
            rows.append((float(t), p["id"], max(float(d), 0.0),
                         float(s) if wet else math.nan, float(q / d) if wet else math.nan))
    wall_s = time.perf_counter() - start
    xc, yc = terrain.cell_centres()
    gx, gy = np.meshgrid(xc, yc)
    cell_tri = triangle_of_points(nodes_local, triangles, gx.ravel(), gy.ravel())
    max_depth = np.maximum(maxima.max_depth, depth0)
    max_level = np.where(max_depth > DRY_M, np.maximum(maxima.max_stage, bed + depth0), np.nan)
    out.mkdir(parents=True, exist_ok=True)
    grid_code.write_grid_geotiff(out / "max_depth.tif", on_grid(max_depth, cell_tri,
                                 terrain.shape), terrain, "ANUGA maximum depth")
    grid_code.write_grid_geotiff(out / "max_level.tif", on_grid(max_level, cell_tri,
                                 terrain.shape), terrain, "ANUGA maximum water level")
    with open(out / "gauges.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(GAUGE_HEADER)
        for t, pid, d, s, v in rows:
            w.writerow([f"{t:.3f}", pid, f"{d:.3f}", f"{s:.3f}", f"{v:.3f}"])
    areas = domain.areas
    info = {"code": "ANUGA", "version": anuga.__version__, "status": "completed",
            "flow_algorithm": domain.get_flow_algorithm(), "mesh": NODES_NAME,
            "triangles": int(len(triangles)), "triangle_area_median_m2": float(np.median(areas)),
            "sim_time_s": float(domain.get_time()), "steps": int(steps), "threads": threads,
            "setup_s": setup_s, "wall_time_s": wall_s,
            "volume_initial_m3": volume0,
            "volume_initial_land_m3": float(np.sum(areas * depth0 * (bed >= setup.SEA_LEVEL_M))),
            "volume_final_m3": float(domain.get_water_volume())}
    (out / "run.json").write_text(json.dumps(info, indent=2) + "\n")
    return info


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True, help="ANUGA run folder to write")
    parser.add_argument("--threads", type=int, default=1, help="OpenMP threads (default 1)")
    parser.add_argument("--end-time", type=float, default=setup.END_TIME_S,
                        help="simulated time [s] (default 4000)")
    parser.add_argument("--gauge-interval", type=float, default=5.0,
                        help="gauge sampling interval [s] (default 5)")
    args = parser.parse_args(argv)
    if not grid_code.anuga_available():
        print("ANUGA is not installed (pip install anuga): nothing to run.", file=sys.stderr)
        return 0
    folder = setup.data_folder()
    if folder is None:
        print("Malpasset data not found: set FLOODSPH_BENCHMARKS to the folder holding "
              f"malpasset/{setup.DEM_NAME}.", file=sys.stderr)
        return 0
    info = run(folder, args.out.resolve(), args.threads, args.end_time, args.gauge_interval)
    print(f"ANUGA {info['version']}: {info['triangles']} triangles, t = {info['sim_time_s']:g} s "
          f"in {info['steps']} steps, {info['wall_time_s']:.1f} s wall "
          f"({info['setup_s']:.1f} s set-up); volume {info['volume_initial_m3']:.4g} -> "
          f"{info['volume_final_m3']:.4g} m3; {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
