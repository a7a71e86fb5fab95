"""The EA test 4 validation page: floodsph at 10 m with ANUGA alongside on the same DEM.

Writes ``docs/validation/ea-test4.md`` and its figures from two result folders, made here when
not given:

* floodsph: ``run_ea_test4.py --dem-cell 10 --threads N`` (default numerics: split+coalesce,
  one global step), its results folder (``run/``, ``ea_test4.toml``);
* ANUGA: ``versus_grid_code.py <that ea_test4.toml> --floodsph-run <that run/>`` (a cross
  mesh of four triangles per 10 m DEM cell, the inflow an ``Inlet_operator``, the west edge a
  wall, the others transmissive; see that script), its results folder.

The page gives, per output point P1-P6 and for both codes, the arrival time (first 10 s gauge
sample deeper than 0.01 m), the peak depth and its time; the volume balance (injected against
the hydrograph integral, in the domain, out through the open edges, the mass-budget error);
the maximum-depth comparison of ``floodsph.output.compare`` (floodsph = model, ANUGA = reference,
wet
= depth > 0.1 m); the wall times on the same thread count. Figures: ``ea-test4_depths.png``
(depth against time at P1-P6, both codes), ``ea-test4_volume.png`` (floodsph's volume
balance) and ``ea-test4_max_depth.png`` (both maps and their difference).

Usage: ``python benchmarks/ea_test4/ea_test4_page.py [--floodsph-run DIR] [--anuga-run DIR]
[--end-time 18000] [--threads 1] [--work DIR] [--out docs/validation]``. Without the benchmark
data, or without ANUGA when its run is still to be made, the script says so and exits with
status 0.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

import provenance  # noqa: E402
import run_ea_test4 as ea4  # noqa: E402
import run_record  # noqa: E402
import versus_grid_code as grid_code  # noqa: E402

from floodsph.output.tables import markdown  # noqa: E402

REPO = ea4.REPO
DEM_CELL = 10
SCENARIO_NAME = "ea_test4"


def completed(run_json: Path) -> bool:
    return run_json.is_file() and json.loads(run_json.read_text()).get("status") == "completed"


def floodsph_results(work: Path, end_time: float, threads: int) -> Path:
    """Run floodsph on EA test 4 at 10 m into ``work/floodsph``, after a 2-step warm-up that
    compiles (or loads) the numba kernels outside the timed run."""
    out = work / "floodsph"
    cmd = [sys.executable, str(HERE / "run_ea_test4.py"), "--dem-cell", str(DEM_CELL),
           "--end-time", repr(end_time), "--threads", str(threads), "--overwrite"]
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads))
    warm = work / "floodsph_warmup"
    subprocess.run([*cmd, "--max-steps", "2", "--out", str(warm)], env=env, check=True,
                   stdout=subprocess.DEVNULL)
    shutil.rmtree(warm)
    run_record.run_recorded([*cmd, "--out", str(out)], out, REPO, env)
    return out


def anuga_results(work: Path, fs_dir: Path, threads: int) -> Path:
    out = work / "versus_anuga"
    cmd = [sys.executable, str(HERE.parent / "versus_grid_code.py"),
           str(fs_dir / "ea_test4.toml"), "--floodsph-run", str(fs_dir / "run"), "--threads",
           str(threads), "--out", str(out), "--quiet"]
    run_record.run_recorded(cmd, out, REPO, dict(os.environ, OMP_NUM_THREADS=str(threads)))
    return out


def anuga_point_table(gauges_csv: Path, points) -> list[dict]:
    series = ea4.gauge_series(gauges_csv)
    rows = []
    for pid, *_ in points:
        arrival, peak, t_peak = ea4.arrival_and_peak(*series[pid], ea4.WET_THRESHOLD_M)
        rows.append({"point": pid, "arrival_s": arrival, "peak_depth_m": peak,
                     "time_of_peak_s": t_peak})
    return rows


def plot_depths(path: Path, fs_gauges: Path, an_gauges: Path, points) -> Path:
    from matplotlib.figure import Figure

    fs, an = ea4.gauge_series(fs_gauges), ea4.gauge_series(an_gauges)
    fig = Figure(figsize=(9.0, 4.8), dpi=100)
    ax = fig.subplots()
    for k, (pid, x, y) in enumerate(points):
        ax.plot(fs[pid][0] / 3600.0, fs[pid][1], f"C{k}-", lw=1.2,
                label=f"{pid} ({x:g}, {y:g}) floodsph")
        ax.plot(an[pid][0] / 3600.0, an[pid][1], f"C{k}--", lw=1.0, label=f"{pid} ANUGA")
    ax.set(xlabel="time [h]", ylabel="depth [m]",
           title="EA test 4, 10 m: depth at the output points (solid floodsph, dashed ANUGA)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path)
    return path


def fmt(v: float, spec: str) -> str:
    return "never" if v != v else format(v, spec)


def points_table(fs_rows, an_rows) -> str:
    return markdown([{
        "point": f["point"], "x, y m": f"{f['x_m']:g}, {f['y_m']:g}",
        "arrival s floodsph": fmt(f["arrival_s"], ".0f"),
        "arrival s ANUGA": fmt(a["arrival_s"], ".0f"),
        "peak depth m floodsph": f"{f['peak_depth_m']:.3f}",
        "peak depth m ANUGA": f"{a['peak_depth_m']:.3f}",
        "time of peak s floodsph": fmt(f["time_of_peak_s"], ".0f"),
        "time of peak s ANUGA": fmt(a["time_of_peak_s"], ".0f")}
        for f, a in zip(fs_rows, an_rows, strict=True)])


def volume_table(balance: dict, anuga: dict, expected: float) -> str:
    return markdown([
        {"code": "floodsph", "hydrograph integral m3": f"{expected:.0f}",
         "injected m3": f"{balance['volume_in_m3']:.0f} "
                        f"({balance['injected_rel_error']:+.1e})",
         "in the domain at the end m3": f"{balance['volume_domain_m3']:.0f}",
         "out through the open edges m3": f"{balance['volume_out_m3']:.0f}",
         "mass-budget error": f"{balance['mass_error_rel']:.1e}"},
        {"code": "ANUGA", "hydrograph integral m3": f"{expected:.0f}",
         "injected m3": "not recorded (Inlet_operator)",
         "in the domain at the end m3": f"{anuga['volume_final_m3']:.0f}",
         "out through the open edges m3": "not recorded",
         "mass-budget error": "not recorded"}])


def page(command, machine, records, row, fs_rows, an_rows, balance, anuga, expected) -> str:
    end = row["sim_time_s"]
    ratio = row["wall_ratio_floodsph_to_anuga"]
    maps = markdown([{
        "cells": row["dem_cells"], "hits": row["hits"], "false alarms": row["false_alarms"],
        "misses": row["misses"], "CSI": f"{row['csi']:.3f}",
        "hit rate": f"{row['hit_rate']:.3f}",
        "false-alarm ratio": f"{row['false_alarm_ratio']:.3f}",
        "depth RMSE m": f"{row['depth_rmse_m']:.3f}", "depth bias m": f"{row['depth_bias_m']:+.3f}",
        "cells wet in both": row["cells_wet_both"]}])
    cost = markdown([
        {"code": "floodsph", "threads": row["threads"], "steps": row["floodsph_steps"],
         "size": f"{row['particles_initial']} -> {row['particles_final']} particles",
         "wall s": f"{row['floodsph_wall_s']:.0f}"},
        {"code": f"ANUGA {anuga['version']} (DE0)", "threads": anuga["threads"],
         "steps": row["anuga_steps"], "size": f"{row['triangles']} triangles",
         "wall s": f"{row['anuga_wall_s']:.0f}"}])
    return "\n".join([
        "# EA test 4: flood propagation over a floodplain, floodsph and ANUGA", "",
        f"Made by `{command}` on {time.strftime('%Y-%m-%d')} at commit "
        f"`{provenance.commit(REPO)}`; {machine}", "",
        f"* floodsph run: {run_record.note(records[0])}.",
        f"* ANUGA run: {run_record.note(records[1])}.", "",
        "The benchmark data (Néelz & Pender 2013, Environment Agency report SC120002; "
        "third-party, not in this repository, see its `SOURCE.md`) is read from "
        "`$FLOODSPH_BENCHMARKS/ea_test4` or `../shared/benchmarks/ea_test4`. The reference "
        "results of other codes are not used: this page compares floodsph with ANUGA.", "",
        "## Set-up", "",
        "* A flat, initially dry floodplain 1000 m x 2000 m, Manning n = 0.05, fed through a "
        "20 m opening in the middle of the west edge by the trapezoidal hydrograph (0 -> "
        "20 m3/s from 300 s to 3600 s, 20 m3/s to 14 400 s, -> 0 at 18 000 s); the west edge a "
        "wall outside the opening, the other edges open.",
        f"* Both codes on the 10 m DEM (the report recommends 5 m), t = 0 to {end:g} s "
        f"{'(the full test)' if end >= ea4.END_TIME_S else '(shorter than the 18 000 s test)'}.",
        "* floodsph: `benchmarks/ea_test4/run_ea_test4.py --dem-cell 10`, particles at 10 m, "
        "split+coalesce refinement (the default) and one global time step (the workflow's "
        "default).",
        "* ANUGA: `benchmarks/versus_grid_code.py` on the scenario that script writes: four "
        "triangles per DEM cell, the inflow an `Inlet_operator` on the opening, "
        "`Reflective_boundary` on the west edge, `Transmissive_boundary` on the others; a "
        "gauge is the centroid value of the triangle holding the point.", "",
        "## Output points", "",
        f"Arrival = first 10 s gauge sample deeper than {ea4.WET_THRESHOLD_M} m; peak depth and "
        "its time from the same 10 s series.", "",
        points_table(fs_rows, an_rows), "",
        "![depth against time at the output points, both codes](ea-test4_depths.png)", "",
        "## Volume balance", "",
        volume_table(balance, anuga, expected), "",
        "![floodsph volume balance against the hydrograph integral](ea-test4_volume.png)", "",
        "## Maximum depth maps", "",
        "floodsph = model, ANUGA = reference, wet = maximum depth > 0.1 m (`floodsph "
        "compare`).", "",
        maps, "",
        "![maximum depth, floodsph and ANUGA, and their difference](ea-test4_max_depth.png)",
        "",
        "## Cost", "",
        cost, "",
        f"floodsph took {ratio:.2f} times ANUGA's wall time on the same thread count "
        f"({'slower' if ratio > 1 else 'faster'}). floodsph: `run.json` `wall_time_s` (inputs, "
        "solver, output maps; the numba kernels compiled beforehand by a 2-step warm-up run "
        "when the page script made the run); ANUGA: mesh and quantity set-up and `evolve`.",
        "",
    ])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--floodsph-run", type=Path, default=None,
                        help="an existing run_ea_test4.py results folder (default: run)")
    parser.add_argument("--anuga-run", type=Path, default=None,
                        help="an existing versus_grid_code.py results folder (default: run)")
    parser.add_argument("--end-time", type=float, default=ea4.END_TIME_S,
                        help="simulated time of new runs [s] (default 18000)")
    parser.add_argument("--threads", type=int, default=1, help="threads of both runs")
    parser.add_argument("--work", type=Path, default=REPO / "benchmarks" / "results" /
                        "ea_test4_anuga", help="folder for new runs")
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "validation")
    args = parser.parse_args(argv)
    argv = sys.argv[1:] if argv is None else argv
    folder = ea4.data_folder()
    if folder is None:
        print("EA test 4 data not found (FLOODSPH_BENCHMARKS): the page is not made.",
              file=sys.stderr)
        return 0
    if args.anuga_run is None and not grid_code.anuga_available():
        print("ANUGA is not installed (pip install anuga) and no --anuga-run was given: the "
              "page is not made.", file=sys.stderr)
        return 0
    from floodsph.io.hydrograph import read_hydrograph
    from floodsph.run.manifest import read_manifest

    work = args.work.resolve()
    t0, load0 = time.perf_counter(), os.getloadavg()[0]
    fs_dir = args.floodsph_run.resolve() if args.floodsph_run else None
    if fs_dir is None or not completed(fs_dir / "run" / "run.json"):
        fs_dir = floodsph_results(work, args.end_time, args.threads)
    vs_dir = args.anuga_run.resolve() if args.anuga_run else None
    if vs_dir is None or not (vs_dir / "versus_grid_code.csv").is_file():
        vs_dir = anuga_results(work, fs_dir, args.threads)
    with open(vs_dir / "versus_grid_code.csv", newline="") as f:
        row = {k: (float(v) if k != "scenario" else v)
               for k, v in next(r for r in csv.DictReader(f) if r["scenario"] == SCENARIO_NAME)
               .items()}
    case = vs_dir / SCENARIO_NAME
    anuga = json.loads((case / "anuga_run.json").read_text())
    points = ea4.read_points(folder)
    run = fs_dir / "run"
    fs_rows = ea4.point_table(run, points, ea4.WET_THRESHOLD_M)
    an_rows = anuga_point_table(case / "anuga_gauges.csv", points)
    hydrograph = read_hydrograph(fs_dir / "ea4_hydrograph.csv")
    manifest = read_manifest(run)
    balance = ea4.volume_balance(manifest, hydrograph)
    args.out.mkdir(parents=True, exist_ok=True)
    plot_depths(args.out / "ea-test4_depths.png", run / "gauges.csv", case / "anuga_gauges.csv",
                points)
    ea4.plot_volume(args.out / "ea-test4_volume.png", run, hydrograph)
    shutil.copyfile(case / "max_depth_side_by_side.png", args.out / "ea-test4_max_depth.png")
    for key in ("threads", "dem_cells", "triangles", "hits", "false_alarms", "misses",
                "cells_wet_both", "particles_initial", "particles_final", "floodsph_steps",
                "anuga_steps"):
        row[key] = int(row[key])
    machine = provenance.machine_note((load0, os.getloadavg()[0]), time.perf_counter() - t0,
                                      "The wall times of the runs are in the cost table.")
    command = " ".join(["python benchmarks/ea_test4/ea_test4_page.py", *argv])
    text = page(command, machine, (run_record.read(fs_dir), run_record.read(vs_dir)), row,
                fs_rows, an_rows, balance, anuga, balance["hydrograph_volume_m3"])
    path = args.out / "ea-test4.md"
    path.write_text(text)
    print(f"CSI {row['csi']:.3f}, RMSE {row['depth_rmse_m']:.3f} m; page: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
