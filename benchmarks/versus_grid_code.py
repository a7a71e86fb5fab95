"""floodsph against ANUGA's finite-volume solver on the same scenario and DEM.

For each scenario TOML (default: the sample valley dam break, ``data_samples/valley``), the
script runs floodsph (``floodsph.run.pipeline.run_scenario``) and ANUGA 4 (Roberts et al., ANUGA
user
manual, Geoscience Australia; flow algorithm DE0, a second-order well-balanced finite-volume
scheme on triangles) on the same DEM, with the same Manning n, initial water, inflow
hydrographs and end time, and compares the maximum-depth maps with ``floodsph.output.compare``
(floodsph = model, ANUGA = reference; wet = depth > 0.1 m).

ANUGA set-up, one-to-one with the floodsph inputs (``floodsph.inputs.prepare.prepare_inputs``):

* mesh: ``anuga.rectangular_cross_domain`` on the DEM grid, each DEM cell split into four
  triangles, in the same local frame (origin = lower-left DEM corner);
* bed, Manning n and initial depth: each triangle takes the value of the DEM cell holding its
  centroid (stage = bed + depth, so a reservoir starts flat at its level);
* edges ``"open"``: ``Transmissive_boundary`` (free outflow), except ``closed_sides`` and
  sides walled along their length; ``"closed"``: walls (``Reflective_boundary``);
* ``[[inflows]]``: ``anuga.Inlet_operator`` along the inflow line (moved a quarter cell inside
  the domain when it lies on the border) with Q(t) from the same hydrograph;
* maximum depth: ``Collect_max_quantities_operator`` (every step) together with the initial
  depth, then the mean of the four triangles of each DEM cell: a GeoTIFF on the DEM grid;
* ``[gauges]``: depth, level and speed of the triangle holding each gauge (centroid values)
  every ``interval_s``, in floodsph's ``gauges.csv`` layout.

``[[walls]]`` drawn along the DEM border (covering a whole side, inflow openings aside) make
that side reflective, as in EA Test 4; other walls and ``[[sinks]]`` have no translation here:
such scenarios are refused.

Writes into the results folder: per scenario ``<name>/floodsph/`` (the run folder),
``<name>/anuga_max_depth.tif``, ``<name>/anuga_gauges.csv`` (with ``[gauges]``),
``<name>/anuga_run.json`` (ANUGA's cost and volumes), ``<name>/comparison/`` (``floodsph
compare`` outputs) and ``<name>/max_depth_side_by_side.png`` (floodsph, ANUGA, difference); and
one row per scenario in
``versus_grid_code.csv``: wall times of both codes (same thread count, default 1: on a machine
shared with other jobs, OpenMP threads waiting for a busy core make multi-thread timings
erratic; floodsph's kernels are compiled by a 2-step warm-up run beforehand), their ratio, CSI
and depth RMSE/bias. floodsph's wall time is ``run.json`` ``wall_time_s`` (input preparation,
solver and all output maps); ANUGA's covers the mesh and quantity set-up and ``evolve``.
``--floodsph-run DIR`` (one scenario only) takes floodsph's run from a completed run folder of
that scenario instead of running it (no warm-up then: its wall time is what that run took).
Without ANUGA (``pip install anuga``) the script prints that and exits with status 0.

Usage: ``python benchmarks/versus_grid_code.py [SCENARIO ...] [--end-time S] [--threads N]
[--floodsph-run DIR] [--out DIR]``
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import importlib.util
import json
import math
import os
import shutil
import sys
import time
from pathlib import Path

import numpy as np

from floodsph.output.tables import write_csv

REPO = Path(__file__).resolve().parents[1]
DEFAULT_SCENARIO = REPO / "data_samples" / "valley" / "scenario.toml"
WET_THRESHOLD_M = 0.1
BOUNDARY_TAGS = ("left", "right", "top", "bottom")
YIELD_S = 60.0


def anuga_available() -> bool:
    return importlib.util.find_spec("anuga") is not None


# -- DEM grid <-> triangle centroids (no ANUGA needed) -------------------------------------------
def cell_index(xc, yc, dx: float, dy: float, shape: tuple[int, int]) -> np.ndarray:
    """Flat index ``i * nx + j`` of the grid cell holding each point (row 0 = south); -1 off grid.

    Cell (i, j) covers local x in [j dx, (j+1) dx) and y in [i dy, (i+1) dy).
    """
    ny, nx = shape
    j = np.floor(np.asarray(xc, dtype=np.float64) / dx).astype(np.int64)
    i = np.floor(np.asarray(yc, dtype=np.float64) / dy).astype(np.int64)
    inside = (i >= 0) & (i < ny) & (j >= 0) & (j < nx)
    return np.where(inside, i * nx + j, -1)


def grid_to_centroids(grid: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """The grid value of each point's cell (``cells`` from :func:`cell_index`, all on grid)."""
    if np.any(cells < 0):
        raise ValueError("a point lies outside the grid")
    return np.asarray(grid, dtype=np.float64).ravel()[cells]


def centroids_to_grid(values: np.ndarray, cells: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Mean of the values of the points in each cell (row 0 = south); NaN for an empty cell.

    For equal-area triangles (a cross mesh on the grid) the mean is the area-weighted mean.
    Points off the grid (``cells == -1``) are ignored.
    """
    on = cells >= 0
    n = shape[0] * shape[1]
    total = np.bincount(cells[on], weights=np.asarray(values, dtype=np.float64)[on], minlength=n)
    count = np.bincount(cells[on], minlength=n)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / count, np.nan).reshape(shape)


def inlet_line(line_local: np.ndarray, dx: float, dy: float, width: float,
               height: float) -> list[list[float]]:
    """The inflow line in local coordinates, kept at least a quarter cell inside the domain.

    ANUGA's ``Inlet_operator`` adds water to the triangles the line crosses; a line on the
    domain border would touch only triangle edges.
    """
    x = np.clip(line_local[:, 0], 0.25 * dx, width - 0.25 * dx)
    y = np.clip(line_local[:, 1], 0.25 * dy, height - 0.25 * dy)
    return [[float(a), float(b)] for a, b in zip(x, y, strict=True)]


def write_grid_geotiff(path: Path, grid: np.ndarray, terrain, description: str) -> Path:
    """A south-up grid (row 0 = south) as a north-up float32 GeoTIFF on the DEM's grid and CRS."""
    import rasterio
    from rasterio.crs import CRS

    ny, nx = grid.shape
    profile = {"driver": "GTiff", "width": nx, "height": ny, "count": 1, "dtype": "float32",
               "nodata": float("nan"), "crs": CRS.from_wkt(terrain.crs_wkt),
               "transform": terrain.north_up_transform(), "compress": "deflate"}
    with rasterio.open(path, "w", **profile) as dst:
        dst.write(np.asarray(grid[::-1], dtype=np.float32), 1)
        dst.set_band_description(1, description)
        dst.update_tags(1, units="m")
    return path


# -- the two runs ----------------------------------------------------------------------------
@dataclasses.dataclass
class AnugaRun:
    """ANUGA's maximum depth on the DEM grid (row 0 = south, NaN = never wet) and its cost."""

    max_depth: np.ndarray
    wall_s: float
    setup_s: float
    steps: int
    triangles: int
    volume_initial_m3: float
    volume_final_m3: float
    gauges: list = dataclasses.field(default_factory=list)
    """Rows (time [s], id, depth [m], level [m], speed [m/s]); NaN level and speed when dry."""


def walled_sides(walls, openings, width: float, height: float, tol: float) -> set[str]:
    """DEM sides ("left", "right", "bottom", "top") closed by walls drawn along them.

    ``walls`` are polylines and ``openings`` inflow lines, as (k, 2) arrays in local
    coordinates. Every wall segment must lie on one side (within ``tol``); the walls and
    openings on a side must cover all of it, which then becomes a reflective ANUGA boundary
    (the inflow enters through ``Inlet_operator``, which is not a boundary). Raises
    ValueError for a wall off the border or a side only partly walled.
    """
    sides = {"left": (0, 0.0, 1, height), "right": (0, width, 1, height),
             "bottom": (1, 0.0, 0, width), "top": (1, height, 0, width)}

    def side_of(p, q):
        for name, (axis, at, _, _) in sides.items():
            if abs(p[axis] - at) <= tol and abs(q[axis] - at) <= tol:
                return name
        return None

    spans: dict[str, list] = {}
    for wall in walls:
        for p, q in zip(wall[:-1], wall[1:], strict=True):
            name = side_of(p, q)
            if name is None:
                raise ValueError(f"wall segment {p.tolist()} - {q.tolist()} (local m) is not "
                                 "on the DEM border")
            along = sides[name][2]
            spans.setdefault(name, []).append(sorted((p[along], q[along])))
    for line in openings:
        name = side_of(line[0], line[1])
        if name in spans:
            spans[name].append(sorted((line[0][sides[name][2]], line[1][sides[name][2]])))
    for name, intervals in spans.items():
        reach = 0.0
        for lo, hi in sorted(intervals):
            if lo > reach + tol:
                break
            reach = max(reach, hi)
        if reach < sides[name][3] - tol:
            raise ValueError(f"the walls cover only part of the {name} side of the DEM")
    return set(spans)


def translate_walls(scenario, terrain) -> set[str]:
    """The walled DEM sides of ``scenario``; exit with a message for what ANUGA cannot take."""
    if scenario.sinks:
        raise SystemExit(f"{scenario.path}: [[sinks]] has no ANUGA translation in this "
                         "workflow; remove it or compare another scenario")

    def local(points):
        return np.column_stack(terrain.to_local(*np.asarray(points, dtype=np.float64).T))

    anuga_side = {"west": "left", "east": "right", "south": "bottom", "north": "top"}
    closed = {anuga_side[side] for side in scenario.terrain.closed_sides}
    try:
        return closed | walled_sides([local(w.polyline) for w in scenario.walls],
                                     [local(f.line) for f in scenario.inflows], terrain.width,
                                     terrain.height, 1e-6 * max(terrain.width, terrain.height))
    except ValueError as err:
        raise SystemExit(f"{scenario.path}: [[walls]]: {err}; only walls along the DEM border "
                         "have an ANUGA translation in this workflow") from None


def import_anuga():
    """Import ANUGA with its OpenMP threads waiting passively.

    ANUGA's wheel bundles its own libgomp, which reads ``OMP_WAIT_POLICY`` when it loads. By
    default idle threads spin, which stalls them badly on a machine shared with other jobs
    (measured: 2 threads 100x slower than 1 on a loaded 2-core machine); passive waiting costs
    little when the cores are free. numba's OpenMP layer uses the system libgomp and keeps its
    own default. A policy the user set is left as it is.
    """
    if "OMP_WAIT_POLICY" in os.environ:  # the user's choice
        import anuga

        return anuga
    os.environ["OMP_WAIT_POLICY"] = "PASSIVE"
    try:
        import anuga
    finally:
        del os.environ["OMP_WAIT_POLICY"]
    return anuga


def run_anuga(scenario, inputs, walled: set[str], threads: int, work: Path) -> AnugaRun:
    """Run the scenario with ANUGA (see the module docstring for the set-up)."""
    anuga = import_anuga()
    from anuga.operators.collect_max_quantities_operator import (
        Collect_max_quantities_operator,
    )

    terrain = inputs.terrain
    shape, dx, dy = terrain.shape, terrain.dx, terrain.dy
    start = time.perf_counter()
    anuga.set_omp_num_threads(threads, verbose=False)
    domain = anuga.rectangular_cross_domain(shape[1], shape[0], terrain.width, terrain.height)
    domain.set_name("anuga")
    domain.set_datadir(str(work))
    domain.set_store(False)
    cells = cell_index(domain.centroid_coordinates[:, 0], domain.centroid_coordinates[:, 1],
                       dx, dy, shape)
    bed = grid_to_centroids(terrain.elevation, cells)
    depth0 = grid_to_centroids(inputs.depth, cells)
    domain.set_quantity("elevation", bed, location="centroids")
    domain.set_quantity("friction", grid_to_centroids(terrain.manning, cells),
                        location="centroids")
    domain.set_quantity("stage", bed + depth0, location="centroids")
    open_edge, wall = anuga.Transmissive_boundary(domain), anuga.Reflective_boundary(domain)
    closed = scenario.terrain.edges.value == "closed"
    domain.set_boundary({tag: wall if closed or tag in walled else open_edge
                         for tag in BOUNDARY_TAGS})
    for inflow, hydrograph in zip(scenario.inflows, inputs.hydrographs, strict=True):
        local = np.column_stack(terrain.to_local(*np.asarray(inflow.line, dtype=np.float64).T))
        line = inlet_line(local, dx, dy, terrain.width, terrain.height)
        anuga.Inlet_operator(domain, line, Q=lambda t, hg=hydrograph: float(hg.discharge(t)))
    maxima = Collect_max_quantities_operator(domain)
    volume0 = float(domain.get_water_volume())
    points = inputs.gauges
    yield_s = YIELD_S if points is None else scenario.gauges.interval_s
    gauge_tri = [] if points is None else [
        domain.get_triangle_containing_point([float(x), float(y)])
        for x, y in zip(points.x, points.y, strict=True)]
    setup = time.perf_counter() - start
    steps, rows = 0, []
    end = scenario.end_time_s
    for t in domain.evolve(yieldstep=min(yield_s, end), finaltime=end):
        steps += domain.number_of_steps
        if gauge_tri:
            rows += gauge_rows(domain, float(t), points.ids, gauge_tri)
    wall = time.perf_counter() - start
    peak = np.maximum(maxima.max_depth, depth0)
    grid = centroids_to_grid(peak, cells, shape)
    grid[~(grid > 0.0)] = np.nan
    return AnugaRun(grid, wall, setup, steps, len(cells), volume0,
                    float(domain.get_water_volume()), rows)


def gauge_rows(domain, t: float, ids, triangles, dry: float = 1e-3) -> list[tuple]:
    """(t, id, depth, level, speed) of the centroids of ``triangles``; dry below ``dry`` m."""
    q = domain.quantities
    out = []
    for gid, k in zip(ids, triangles, strict=True):
        stage = float(q["stage"].centroid_values[k])
        depth = max(stage - float(q["elevation"].centroid_values[k]), 0.0)
        flux = math.hypot(q["xmomentum"].centroid_values[k], q["ymomentum"].centroid_values[k])
        wet = depth > dry
        out.append((t, gid, depth, stage if wet else math.nan, flux / depth if wet else math.nan))
    return out


def write_anuga_outputs(folder: Path, run: AnugaRun, threads: int) -> None:
    """``anuga_gauges.csv`` (floodsph's ``gauges.csv`` columns) and ``anuga_run.json``."""
    import anuga

    if run.gauges:
        with open(folder / "anuga_gauges.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(("time_s", "id", "depth_m", "level_m", "speed_ms"))
            for t, gid, d, level, v in run.gauges:
                w.writerow([f"{t:.3f}", gid, f"{d:.4f}", f"{level:.4f}", f"{v:.4f}"])
    info = {k: v for k, v in dataclasses.asdict(run).items() if k not in ("max_depth", "gauges")}
    info.update(version=anuga.__version__, threads=threads)
    (folder / "anuga_run.json").write_text(json.dumps(info, indent=2) + "\n")


def run_floodsph(scenario, out: Path, threads: int, progress: bool) -> dict:
    """A 2-step warm-up (compiles or loads the numba kernels), then the timed run."""
    from floodsph.run.pipeline import run_scenario

    warm = out.parent / (out.name + "_warmup")
    run_scenario(scenario, out_dir=warm, max_steps=2, progress=False, overwrite=True,
                 threads=threads)
    shutil.rmtree(warm)
    return run_scenario(scenario, out_dir=out, progress=progress, overwrite=True,
                        threads=threads)


# -- comparison, picture, table ---------------------------------------------------------------
def summary_row(name: str, manifest: dict, anuga: AnugaRun, result, cells: int) -> dict:
    """One CSV row: sizes, wall times and their ratio, wet/dry scores, depth errors."""
    s = result.summary
    return {
        "scenario": name, "sim_time_s": manifest["sim_time_s"], "dem_cells": cells,
        "triangles": anuga.triangles, "particles_initial": manifest["particles_initial"],
        "particles_final": manifest["particles_final"], "threads": manifest["threads"],
        "floodsph_steps": manifest["steps"], "anuga_steps": anuga.steps,
        "floodsph_wall_s": manifest["wall_time_s"], "anuga_wall_s": anuga.wall_s,
        "anuga_setup_s": anuga.setup_s,
        "wall_ratio_floodsph_to_anuga": manifest["wall_time_s"] / anuga.wall_s,
        "floodsph_volume_initial_m3": manifest["volume_initial_m3"],
        "anuga_volume_initial_m3": anuga.volume_initial_m3,
        "floodsph_volume_final_m3": manifest["volume_domain_m3"],
        "anuga_volume_final_m3": anuga.volume_final_m3,
        "wet_threshold_m": WET_THRESHOLD_M, "hits": s["hits"],
        "false_alarms": s["false_alarms"], "misses": s["misses"], "csi": s["csi"],
        "hit_rate": s["hit_rate"], "false_alarm_ratio": s["false_alarm_ratio"],
        "depth_rmse_m": s["depth"]["rmse"], "depth_bias_m": s["depth"]["bias"],
        "cells_wet_both": s["depth"]["n"],
    }


def plot_side_by_side(path: Path, result, reference_on_model: np.ndarray) -> Path | None:
    """floodsph max depth, ANUGA max depth (on floodsph's grid) and their difference."""
    try:
        import matplotlib
    except ImportError:
        return None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    m = result.model
    ny, nx = m.data.shape
    t = m.transform
    extent = (t.c / 1e3, (t.c + nx * t.a) / 1e3, (t.f + ny * t.e) / 1e3, t.f / 1e3)
    fs = np.where(m.data > 0, m.data, np.nan)
    an = np.where(reference_on_model > 0, reference_on_model, np.nan)
    top = float(np.nanmax([np.nanmax(fs), np.nanmax(an)])) if np.isfinite(fs).any() else 1.0
    diff = result.difference
    lim = float(np.nanmax(np.abs(diff))) if np.isfinite(diff).any() else 1.0
    panel = 5.0
    fig, axes = plt.subplots(1, 3, figsize=(3 * panel + 1.5, panel * ny / nx + 1.3),
                             sharex=True, sharey=True)
    s = result.summary
    panels = ((fs, "floodsph max depth [m]", "Blues", 0.0, top),
              (an, "ANUGA max depth [m]", "Blues", 0.0, top),
              (diff, f"floodsph - ANUGA [m]: CSI {s['csi']:.3f}, RMSE "
                     f"{s['depth']['rmse']:.3f} m", "RdBu_r", -lim, lim))
    for ax, (data, title, cmap, lo, hi) in zip(axes, panels, strict=True):
        im = ax.imshow(data, cmap=cmap, vmin=lo, vmax=hi, extent=extent,
                       interpolation="nearest")
        fig.colorbar(im, ax=ax, shrink=0.8)
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("Easting [km]")
    axes[0].set_ylabel("Northing [km]")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def reused_floodsph_run(run_dir: Path, scenario) -> dict:
    """The manifest of a completed floodsph run of ``scenario`` (same name and end time)."""
    from floodsph.run.manifest import read_manifest

    manifest = read_manifest(run_dir)
    if manifest is None or manifest.get("status") != "completed":
        raise SystemExit(f"{run_dir}: not a completed floodsph run folder")
    ran = manifest["scenario"]["scenario"]
    if ran["name"] != scenario.name or ran["end_time_s"] != scenario.end_time_s:
        raise SystemExit(f"{run_dir}: a run of {ran['name']!r} to {ran['end_time_s']} s, not "
                         f"of {scenario.name!r} to {scenario.end_time_s} s")
    return manifest


def compare_scenario(path: Path, out: Path, end_time: float | None, threads: int,
                     progress: bool, floodsph_run: Path | None = None) -> dict:
    """Both runs (floodsph's taken from ``floodsph_run`` when given), the comparison outputs
    and the summary row of one scenario."""
    from floodsph.inputs.prepare import prepare_inputs
    from floodsph.output.compare import align, compare, read_raster, write_outputs
    from floodsph.scenario.reader import load_scenario

    scenario = load_scenario(path)
    if end_time is not None:
        scenario = dataclasses.replace(
            scenario, scenario=dataclasses.replace(scenario.scenario, end_time_s=end_time))
    inputs = prepare_inputs(scenario)
    walled = translate_walls(scenario, inputs.terrain)
    if not inputs.terrain.valid.all():
        print(f"{path}: the DEM has nodata cells; ANUGA treats them as ground at the "
              "nearest valid elevation", file=sys.stderr)
    folder = out / scenario.name
    folder.mkdir(parents=True, exist_ok=True)
    if floodsph_run is None:
        floodsph_run = folder / "floodsph"
        manifest = run_floodsph(scenario, floodsph_run, threads, progress)
    else:
        manifest = reused_floodsph_run(floodsph_run, scenario)
    anuga = run_anuga(scenario, inputs, walled, threads, folder)
    write_anuga_outputs(folder, anuga, threads)
    anuga_tif = write_grid_geotiff(folder / "anuga_max_depth.tif", anuga.max_depth,
                                   inputs.terrain, "ANUGA maximum depth")
    result = compare(floodsph_run / "max_depth.tif", anuga_tif, threshold=WET_THRESHOLD_M)
    write_outputs(result, folder / "comparison")
    on_model, _ = align(result.model, read_raster(anuga_tif))
    plot_side_by_side(folder / "max_depth_side_by_side.png", result, on_model)
    return summary_row(scenario.name, manifest, anuga, result, inputs.terrain.elevation.size)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", type=Path, default=[DEFAULT_SCENARIO],
                        help="scenario TOML files (default: the sample valley)")
    parser.add_argument("--end-time", type=float, default=None,
                        help="simulated time [s] for both codes (default: the scenario's)")
    parser.add_argument("--threads", type=int, default=1,
                        help="threads for both codes (default 1; 0 = all cores)")
    parser.add_argument("--out", type=Path, default=REPO / "benchmarks" / "results" /
                        "versus_grid_code", help="results folder")
    parser.add_argument("--floodsph-run", type=Path, default=None,
                        help="a completed floodsph run folder of the (single) scenario to "
                             "use instead of running floodsph")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    if args.floodsph_run is not None and len(args.scenarios) != 1:
        parser.error("--floodsph-run needs exactly one scenario")
    if not anuga_available():
        print("ANUGA is not installed (pip install anuga): the comparison is skipped.",
              file=sys.stderr)
        return 0
    threads = args.threads or os.cpu_count() or 1
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for path in args.scenarios:
        rows.append(compare_scenario(path.resolve(), out, args.end_time, threads,
                                     not args.quiet, args.floodsph_run and
                                     args.floodsph_run.resolve()))
        r = rows[-1]
        print(f"{r['scenario']}: t = {r['sim_time_s']:g} s; floodsph {r['floodsph_wall_s']:.1f} s "
              f"wall ({r['floodsph_steps']} steps), ANUGA {r['anuga_wall_s']:.1f} s "
              f"({r['anuga_steps']} steps), ratio {r['wall_ratio_floodsph_to_anuga']:.2f}; "
              f"CSI {r['csi']:.3f}, depth RMSE {r['depth_rmse_m']:.3f} m, bias "
              f"{r['depth_bias_m']:+.3f} m ({r['cells_wet_both']} cells wet in both)")
    write_csv(out / "versus_grid_code.csv", rows)
    print(f"wrote {out / 'versus_grid_code.csv'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
