"""The Malpasset validation page: floodsph against ANUGA on the same 20 m DEM.

Writes ``docs/validation/malpasset.md`` and its figures from two run folders, made here when
not given:

* floodsph: ``run_malpasset.py --sea sink --time-stepping local --threads N`` (the folder
  ``<out>/sink`` of that script: ``run/`` and ``points.csv``);
* ANUGA: ``anuga_malpasset.py`` (the benchmark's 26 000-triangle mesh, the bed from the same
  DEM; see that script), with the same thread count.

The two seas differ: floodsph's is a sink (water entering the cells below 0 m leaves the
model), ANUGA's the benchmark's still sea at 0 m in a closed domain. The map comparison
therefore leaves out the sea cells (bed < 0 m): both maximum-depth maps are copied with those
cells set to NaN, then compared with ``floodsph.output.compare.compare`` (floodsph = model, ANUGA =
reference, wet = maximum depth > 0.1 m): CSI, hit rate, false-alarm ratio, depth RMSE and
bias over the cells wet in both. Point values (``malpasset_results.point_table`` on each
folder): the maximum water level at the survey points P1-P17 and gauges S6-S14 (in the cell,
and the highest wet cell within 40 m), arrival times (depth > 0.05 m, 5 s gauge interval) at
S6-S14 and the transformers A, B, C.

Figures: ``malpasset_max_depth.png`` (both maps and their difference), ``malpasset_points.png``
(levels and arrival times, floodsph against ANUGA) and ``malpasset_gauges.png`` (depth against
time at S6-S14, A, B, C).

Usage: ``python benchmarks/malpasset/malpasset_page.py [--floodsph-run DIR] [--anuga-run DIR]
[--work DIR] [--threads 1] [--out docs/validation]``. Without the benchmark data, or without
ANUGA when its run is still to be made, the script says so and exits with status 0.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

import malpasset_results as results  # noqa: E402
import malpasset_setup as setup  # noqa: E402
import provenance  # noqa: E402
import run_record  # noqa: E402
import versus_grid_code as grid_code  # noqa: E402

from floodsph.output.tables import markdown  # noqa: E402

REPO = setup.REPO
WET_THRESHOLD_M = 0.1
LEVEL_POINTS = tuple(f"P{k}" for k in range(1, 18)) + tuple(f"S{k}" for k in range(6, 15))
ARRIVAL_POINTS = tuple(f"S{k}" for k in range(6, 15)) + ("A", "B", "C")


# -- the runs --------------------------------------------------------------------------------
def completed(run_json: Path) -> bool:
    return run_json.is_file() and json.loads(run_json.read_text()).get("status") == "completed"


def floodsph_run(work: Path, threads: int) -> Path:
    """Run floodsph on Malpasset (sea as a sink, local steps) into ``work/floodsph``, after a
    2-step warm-up that compiles (or loads) the numba kernels outside the timed run."""
    out = work / "floodsph"
    cmd = [sys.executable, str(HERE / "run_malpasset.py"), "--sea", "sink", "--time-stepping",
           "local", "--threads", str(threads), "--overwrite"]
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads))
    warm = work / "floodsph_warmup"
    subprocess.run([*cmd, "--max-steps", "2", "--out", str(warm)], env=env, check=True,
                   stdout=subprocess.DEVNULL)
    shutil.rmtree(warm)
    run_record.run_recorded([*cmd, "--out", str(out)], out / "sink", REPO, env)
    return out / "sink"


def anuga_run(work: Path, threads: int) -> Path:
    """Run ANUGA on Malpasset into ``work/anuga``."""
    out = work / "anuga"
    cmd = [sys.executable, str(HERE / "anuga_malpasset.py"), "--out", str(out),
           "--threads", str(threads)]
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    run_record.run_recorded(cmd, out, REPO, env)
    return out


# -- maps ------------------------------------------------------------------------------------
def read_map(path: Path):
    """A single-band raster as float64 (nodata -> NaN), its transform and rasterio profile."""
    import rasterio

    with rasterio.open(path) as src:
        data = src.read(1).astype(np.float64)
        if src.nodata is not None and not math.isnan(src.nodata):
            data[data == src.nodata] = np.nan
        return data, src.transform, src.profile


def land_copy(src: Path, sea: np.ndarray, dst: Path) -> Path:
    """``src`` with the sea cells set to NaN, as float32 GeoTIFF ``dst``."""
    import rasterio

    data, _, profile = read_map(src)
    data[sea] = np.nan
    profile.update(dtype="float32", nodata=float("nan"), count=1)
    with rasterio.open(dst, "w", **profile) as out:
        out.write(data.astype(np.float32), 1)
    return dst


def compare_maps(fs_run: Path, an_run: Path, dem: Path, work: Path):
    """floodsph against ANUGA, land cells only: the Comparison and the sea-cell count."""
    from floodsph.output.compare import compare, write_outputs

    bed, _, _ = read_map(dem)
    sea = np.nan_to_num(bed, nan=1.0) < setup.SEA_LEVEL_M
    folder = work / "comparison"
    folder.mkdir(parents=True, exist_ok=True)
    model = land_copy(fs_run / "max_depth.tif", sea, folder / "floodsph_land_max_depth.tif")
    ref = land_copy(an_run / "max_depth.tif", sea, folder / "anuga_land_max_depth.tif")
    result = compare(model, ref, threshold=WET_THRESHOLD_M)
    write_outputs(result, folder)
    return result, int(sea.sum())


# -- figures ---------------------------------------------------------------------------------
def plot_maps(path: Path, fs_run: Path, an_run: Path, dem: Path, points, result) -> Path:
    """floodsph and ANUGA maximum depth and their difference over a hillshade."""
    from matplotlib import colors
    from matplotlib.figure import Figure

    fs, t, _ = read_map(fs_run / "max_depth.tif")
    an, _, _ = read_map(an_run / "max_depth.tif")
    bed, _, _ = read_map(dem)
    wet = (np.nan_to_num(fs) > WET_THRESHOLD_M) | (np.nan_to_num(an) > WET_THRESHOLD_M)
    rows, cols = np.nonzero(wet | (np.nan_to_num(bed, nan=1.0) < 0))
    r0, r1 = max(rows.min() - 10, 0), min(rows.max() + 11, bed.shape[0])
    c0, c1 = max(cols.min() - 10, 0), min(cols.max() + 11, bed.shape[1])
    extent = ((t.c + c0 * t.a) / 1e3, (t.c + c1 * t.a) / 1e3,
              (t.f + r1 * t.e) / 1e3, (t.f + r0 * t.e) / 1e3)
    crop = np.s_[r0:r1, c0:c1]
    shade = colors.LightSource(azdeg=315, altdeg=45).hillshade(
        np.nan_to_num(bed, nan=float(np.nanmin(bed))), vert_exag=2.0, dx=t.a, dy=-t.e)[crop]
    top = float(np.nanpercentile(np.where(wet, np.fmax(fs, an), np.nan), 99))
    diff = result.difference[crop]
    lim = float(np.nanpercentile(np.abs(diff), 99))
    s = result.summary
    panels = ((np.where(np.nan_to_num(fs) > WET_THRESHOLD_M, fs, np.nan)[crop],
               "floodsph maximum depth [m]", "viridis", 0.0, top),
              (np.where(np.nan_to_num(an) > WET_THRESHOLD_M, an, np.nan)[crop],
               "ANUGA maximum depth [m]", "viridis", 0.0, top),
              (diff, f"floodsph - ANUGA [m], land cells\nCSI {s['csi']:.3f}, RMSE "
                     f"{s['depth']['rmse']:.2f} m, bias {s['depth']['bias']:+.2f} m",
               "RdBu_r", -lim, lim))
    aspect = (r1 - r0) / (c1 - c0)
    fig = Figure(figsize=(14.0, 4.2 * aspect + 1.2), dpi=100)
    axes = fig.subplots(1, 3, sharex=True, sharey=True)
    for ax, (data, title, cmap, lo, hi) in zip(axes, panels, strict=True):
        ax.imshow(np.ma.masked_where(np.isnan(bed[crop]), shade), cmap="gray", extent=extent,
                  interpolation="nearest")
        im = ax.imshow(data, cmap=cmap, vmin=lo, vmax=hi, extent=extent, alpha=0.9,
                       interpolation="nearest")
        fig.colorbar(im, ax=ax, shrink=0.6)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("Easting, EPSG:27572 [km]")
        for p in points:
            ax.plot(p["x"] / 1e3, p["y"] / 1e3, "r+" if p["id"].startswith("P") else "kx", ms=4)
    axes[0].set_ylabel("Northing, EPSG:27572 [km]")
    fig.tight_layout()
    fig.savefig(path)
    return path


def plot_points(path: Path, level_rows: list[dict], arrival_rows: list[dict]) -> Path:
    """Maximum level (within 40 m) and arrival time, floodsph against ANUGA, per point."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10.0, 4.6), dpi=100)
    ax1, ax2 = fig.subplots(1, 2)
    for ax, rows, key, unit in ((ax1, level_rows, "level_r40", "m"),
                                (ax2, arrival_rows, "arrival", "s")):
        a = np.array([r[f"anuga_{key}"] for r in rows], dtype=float)
        f = np.array([r[f"floodsph_{key}"] for r in rows], dtype=float)
        ok = np.isfinite(a) & np.isfinite(f)
        ax.set_xlabel(f"ANUGA [{unit}]")
        ax.set_ylabel(f"floodsph [{unit}]")
        ax.grid(True, alpha=0.3)
        if not ok.any():
            continue
        lo, hi = float(np.min([a[ok], f[ok]])), float(np.max([a[ok], f[ok]]))
        pad = 0.05 * (hi - lo)
        ax.plot([lo - pad, hi + pad], [lo - pad, hi + pad], "k-", lw=0.8, label="equal")
        ax.plot(a[ok], f[ok], "o", ms=4)
        for r, x, y, good in zip(rows, a, f, ok, strict=True):
            if good:
                ax.annotate(r["id"], (x, y), fontsize=6, xytext=(3, 2), textcoords="offset points")
    ax1.set_title("maximum water level (highest wet cell within 40 m)", fontsize=9)
    ax2.set_title(f"arrival time (depth > {results.ARRIVAL_DEPTH_M} m)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    return path


def read_gauges(path: Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """``gauges.csv`` as {id: (time [s], depth [m])}."""
    import csv

    series: dict[str, list] = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            series.setdefault(row["id"], []).append((float(row["time_s"]), float(row["depth_m"])))
    return {k: (np.array([t for t, _ in v]), np.array([d for _, d in v]))
            for k, v in series.items()}


def plot_gauges(path: Path, fs_run: Path, an_run: Path) -> Path:
    """Depth against time at S6-S14 and A, B, C, both codes."""
    from matplotlib.figure import Figure

    fs, an = read_gauges(fs_run / "gauges.csv"), read_gauges(an_run / "gauges.csv")
    fig = Figure(figsize=(12.0, 7.5), dpi=100)
    axes = fig.subplots(3, 4, sharex=True).ravel()
    for ax, pid in zip(axes, ARRIVAL_POINTS, strict=True):
        ax.plot(*an[pid], "k-", lw=1.0, label="ANUGA")
        ax.plot(*fs[pid], "C0-", lw=1.0, label="floodsph")
        ax.set_title(pid, fontsize=9)
        ax.grid(True, alpha=0.3)
    for ax in axes[::4]:
        ax.set_ylabel("depth [m]")
    for ax in axes[-4:]:
        ax.set_xlabel("time [s]")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    return path


# -- tables ----------------------------------------------------------------------------------
def point_rows(fs_run: Path, an_run: Path, dem: Path, points) -> tuple[list, list]:
    """Level rows (P1-P17, S6-S14) and arrival rows (S6-S14, A, B, C) of both codes."""
    fs = {r["id"]: r for r in results.point_table(fs_run, dem, points, "sink")}
    an = {r["id"]: r for r in results.point_table(an_run, dem, points, "anuga")}
    levels = [{"id": k, "bed": fs[k]["bed_m"],
               "floodsph_level": fs[k]["max_level_m"], "anuga_level": an[k]["max_level_m"],
               "floodsph_level_r40": fs[k]["max_level_r40_m"],
               "anuga_level_r40": an[k]["max_level_r40_m"],
               "diff_r40": fs[k]["max_level_r40_m"] - an[k]["max_level_r40_m"]}
              for k in LEVEL_POINTS]
    arrivals = [{"id": k, "floodsph_arrival": fs[k]["arrival_time_s"],
                 "anuga_arrival": an[k]["arrival_time_s"],
                 "diff": fs[k]["arrival_time_s"] - an[k]["arrival_time_s"]}
                for k in ARRIVAL_POINTS]
    return levels, arrivals


def fmt(v, spec: str) -> str:
    return "never" if isinstance(v, float) and math.isnan(v) else format(v, spec)


def diff_stats(values) -> dict:
    """Mean, mean absolute and largest absolute value of the finite differences."""
    v = np.array([x for x in values if math.isfinite(x)])
    if v.size == 0:
        return {"n": 0, "mean": math.nan, "mae": math.nan, "max": math.nan}
    k = int(np.argmax(np.abs(v)))
    return {"n": len(v), "mean": float(v.mean()), "mae": float(np.abs(v).mean()),
            "max": float(v[k])}


def cost_rows(fs_run: Path, an_run: Path) -> list[dict]:
    fs = json.loads((fs_run / "run.json").read_text())
    an = json.loads((an_run / "run.json").read_text())
    an_change = (an["volume_final_m3"] - an["volume_initial_m3"]) / an["volume_initial_m3"]
    return [
        {"code": f"floodsph {fs['floodsph_version']}", "threads": fs["threads"],
         "wall s": f"{fs['wall_time_s']:.0f}", "steps": fs["steps"],
         "size": f"{fs['particles_initial']} -> {fs['particles_final']} particles "
                 f"(max {fs['particles_max']})",
         "initial water Mm3": f"{fs['volume_initial_m3'] / 1e6:.2f} (no sea)",
         "mass": f"{fs['volume_out_m3'] / 1e6:.2f} Mm3 into the sea sink; budget error "
                 f"{fs['mass_error_rel']:.1e}"},
        {"code": f"ANUGA {an['version']} ({an['flow_algorithm']})", "threads": an["threads"],
         "wall s": f"{an['wall_time_s']:.0f}", "steps": an["steps"],
         "size": f"{an['triangles']} triangles (median area "
                 f"{an['triangle_area_median_m2']:.0f} m2)",
         "initial water Mm3": f"{an['volume_initial_m3'] / 1e6:.2f} (with the sea; "
                              f"{an['volume_initial_land_m3'] / 1e6:.2f} on land)",
         "mass": f"volume change {an_change:.1e} (closed domain)"},
    ]


def cost_rows_raw(fs_run: Path, an_run: Path) -> dict:
    """Wall times, steps and threads of both runs from their ``run.json``."""
    fs = json.loads((fs_run / "run.json").read_text())
    an = json.loads((an_run / "run.json").read_text())
    return {"sim_time_s": fs["sim_time_s"], "threads": fs["threads"],
            "anuga_threads": an["threads"], "floodsph_wall_s": fs["wall_time_s"],
            "anuga_wall_s": an["wall_time_s"], "floodsph_steps": fs["steps"],
            "anuga_steps": an["steps"], "particles_initial": fs["particles_initial"],
            "particles_final": fs["particles_final"], "triangles": an["triangles"]}


def write_summary(path: Path, result, costs: dict) -> Path:
    """The map scores and costs of the page as one JSON row (read by against_anuga_page)."""
    s = result.summary
    row = {"scenario": "malpasset", **costs, "csi": s["csi"], "hit_rate": s["hit_rate"],
           "false_alarm_ratio": s["false_alarm_ratio"], "depth_rmse_m": s["depth"]["rmse"],
           "depth_bias_m": s["depth"]["bias"], "cells_wet_both": s["depth"]["n"],
           "wet_threshold_m": WET_THRESHOLD_M,
           "note": "land cells only (the sea is a sink in floodsph, still water in ANUGA)"}
    path.write_text(json.dumps(row, indent=2) + "\n")
    return path


def page(command: str, machine: str, result, sea_cells: int, levels, arrivals, costs,
         records, fs_run: Path, an_run: Path) -> str:
    s = result.summary
    d = s["depth"]
    lvl = diff_stats([r["diff_r40"] for r in levels])
    arr = diff_stats([r["diff"] for r in arrivals])
    level_table = markdown([{
        "point": r["id"], "bed m": f"{r['bed']:.2f}",
        "floodsph cell m": fmt(r["floodsph_level"], ".2f"),
        "ANUGA cell m": fmt(r["anuga_level"], ".2f"),
        "floodsph within 40 m": fmt(r["floodsph_level_r40"], ".2f"),
        "ANUGA within 40 m": fmt(r["anuga_level_r40"], ".2f"),
        "floodsph - ANUGA m": fmt(r["diff_r40"], "+.2f")} for r in levels])
    arrival_table = markdown([{
        "point": r["id"], "floodsph s": fmt(r["floodsph_arrival"], ".0f"),
        "ANUGA s": fmt(r["anuga_arrival"], ".0f"),
        "floodsph - ANUGA s": fmt(r["diff"], "+.0f")} for r in arrivals])
    map_table = markdown([{
        "cells compared": s["cells_compared"] - sea_cells, "hits": s["hits"],
        "false alarms": s["false_alarms"], "misses": s["misses"], "CSI": f"{s['csi']:.3f}",
        "hit rate": f"{s['hit_rate']:.3f}", "false-alarm ratio": f"{s['false_alarm_ratio']:.3f}",
        "depth RMSE m": f"{d['rmse']:.2f}", "depth bias m": f"{d['bias']:+.2f}",
        "depth MAE m": f"{d['mae']:.2f}", "cells wet in both": d["n"]}])
    ratio = float(costs[0]["wall s"]) / float(costs[1]["wall s"])
    return "\n".join([
        "# Malpasset dam failure: floodsph against ANUGA", "",
        f"Made by `{command}` on {time.strftime('%Y-%m-%d')} at commit "
        f"`{provenance.commit(REPO)}`; {machine}", "",
        f"* floodsph run: {run_record.note(records[0])}.",
        f"* ANUGA run: {run_record.note(records[1])}.", "",
        "The benchmark data (third-party, not in this repository; its `SOURCE.md` gives origin "
        "and licence) is read from `$FLOODSPH_BENCHMARKS/malpasset` or "
        "`../shared/benchmarks/malpasset`. The observed levels are not used here: this page "
        "compares two codes, not a code with the survey.", "",
        "## Set-up", "",
        "* Both codes: the 20 m DEM in EPSG:27572, Manning n = 0.033, walls all round, "
        "instantaneous total failure at t = 0, the reservoir at 100 m inside the polygon of "
        "`benchmarks/malpasset/scenario.toml` (upstream of the dam axis, minus the dry circle), "
        "4000 s, both on the same number of threads.",
        "* floodsph: `benchmarks/malpasset/run_malpasset.py --sea sink --time-stepping local`, "
        "particles at 20 m, the sea a sink (water entering the cells below 0 m leaves the "
        "model), default numerics otherwise.",
        "* ANUGA: `benchmarks/malpasset/anuga_malpasset.py`, the benchmark's own triangle mesh "
        "(TELEMAC `geo_malpasset-small`), each triangle's bed the DEM cell holding its "
        "centroid, the initial depth floodsph's initial depth of that cell with the sea at "
        "0 m (the benchmark's state; the domain is closed, so the sea stays).",
        f"* So the seas differ. The {sea_cells} sea cells (bed < 0 m) are left out of the map "
        "comparison; near the coast floodsph has no backwater from the sea, ANUGA has.",
        "* Maps: ANUGA's maxima are per triangle, put on the DEM grid by the triangle holding "
        "each cell centre. Points: a floodsph gauge is the SPH depth at the point, an ANUGA "
        "gauge the centroid value of the triangle holding it; both sampled every 5 s.", "",
        "## Cost", "",
        markdown(costs), "",
        f"floodsph took {ratio:.2f} times ANUGA's wall time on the same thread count "
        f"({'slower' if ratio > 1 else 'faster'}). floodsph's wall time is `run.json` "
        "`wall_time_s` (input preparation, solver, output maps; the numba kernels compiled "
        "beforehand by a 2-step warm-up run when the page script made the run); ANUGA's "
        "covers floodsph's input preparation it reuses, the mesh, quantities and `evolve`.",
        "",
        "## Maximum depth maps", "",
        f"floodsph = model, ANUGA = reference, wet = maximum depth > {WET_THRESHOLD_M} m "
        "(`floodsph compare`), land cells only.", "",
        map_table, "",
        "![maximum depth, floodsph and ANUGA, and their difference](malpasset_max_depth.png)",
        "",
        "## Maximum water level at the survey points", "",
        "`cell` = the map value in the cell holding the point; `within 40 m` = the highest "
        f"maximum level among the cells within 40 m deeper than {results.ARRIVAL_DEPTH_M} m "
        "(several points lie on steep valley sides, see the benchmark's `SOURCE.md`).", "",
        level_table, "",
        f"Within 40 m, floodsph - ANUGA over {lvl['n']} points: mean {lvl['mean']:+.2f} m, "
        f"mean absolute {lvl['mae']:.2f} m, largest {lvl['max']:+.2f} m.", "",
        "## Arrival times", "",
        f"First gauge sample deeper than {results.ARRIVAL_DEPTH_M} m (5 s resolution).", "",
        arrival_table, "",
        f"floodsph - ANUGA over {arr['n']} points: mean {arr['mean']:+.0f} s, mean absolute "
        f"{arr['mae']:.0f} s, largest {arr['max']:+.0f} s.", "",
        "![levels and arrival times, floodsph against ANUGA](malpasset_points.png)", "",
        "![depth against time at the gauges and transformers](malpasset_gauges.png)", "",
    ])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--floodsph-run", type=Path, default=None,
                        help="an existing run_malpasset.py <out>/sink folder (default: run)")
    parser.add_argument("--anuga-run", type=Path, default=None,
                        help="an existing anuga_malpasset.py folder (default: run)")
    parser.add_argument("--work", type=Path,
                        default=REPO / "benchmarks" / "results" / "malpasset_anuga",
                        help="folder for new runs and the comparison outputs")
    parser.add_argument("--threads", type=int, default=1, help="threads of both runs")
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "validation")
    args = parser.parse_args(argv)
    argv = sys.argv[1:] if argv is None else argv
    folder = setup.data_folder()
    if folder is None:
        print("Malpasset data not found (FLOODSPH_BENCHMARKS): the page is not made.",
              file=sys.stderr)
        return 0
    if args.anuga_run is None and not grid_code.anuga_available():
        print("ANUGA is not installed (pip install anuga) and no --anuga-run was given: the "
              "page is not made.", file=sys.stderr)
        return 0
    work = args.work.resolve()
    t0, load0 = time.perf_counter(), os.getloadavg()[0]
    fs_dir = args.floodsph_run.resolve() if args.floodsph_run else None
    if fs_dir is None or not completed(fs_dir / "run" / "run.json"):
        fs_dir = floodsph_run(work, args.threads)
    an_dir = args.anuga_run.resolve() if args.anuga_run else None
    if an_dir is None or not completed(an_dir / "run.json"):
        an_dir = anuga_run(work, args.threads)
    fs_run = fs_dir / "run"
    dem = folder / setup.DEM_NAME
    points = setup.read_points(folder)
    result, sea_cells = compare_maps(fs_run, an_dir, dem, work)
    levels, arrivals = point_rows(fs_run, an_dir, dem, points)
    args.out.mkdir(parents=True, exist_ok=True)
    plot_maps(args.out / "malpasset_max_depth.png", fs_run, an_dir, dem, points, result)
    plot_points(args.out / "malpasset_points.png", levels, arrivals)
    plot_gauges(args.out / "malpasset_gauges.png", fs_run, an_dir)
    machine = provenance.machine_note((load0, os.getloadavg()[0]), time.perf_counter() - t0,
                                      "Wall times are indicative only; those of the runs are "
                                      "in the cost table.")
    command = " ".join(["python benchmarks/malpasset/malpasset_page.py", *argv])
    text = page(command, machine, result, sea_cells, levels, arrivals,
                cost_rows(fs_run, an_dir), (run_record.read(fs_dir), run_record.read(an_dir)),
                fs_dir, an_dir)
    path = args.out / "malpasset.md"
    path.write_text(text)
    write_summary(work / "summary.json", result, cost_rows_raw(fs_run, an_dir))
    print(f"CSI {result.summary['csi']:.3f}, RMSE {result.summary['depth']['rmse']:.3f} m; "
          f"page: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
