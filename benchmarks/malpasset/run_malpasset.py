"""Malpasset dam failure (France, 2 Dec 1959) with floodsph on the 20 m EPSG:27572 DEM.

Reads the benchmark data from ``$FLOODSPH_BENCHMARKS/malpasset`` or
``<repo>/../shared/benchmarks/malpasset`` (never copied into the repository), writes the
scenario (``malpasset_setup``), runs it and reports (``malpasset_results``): the simulated
maximum water level at the survey points P1-P17 and gauges S6-S14, arrival times (depth >
0.05 m) at S6-S14 and the transformers A, B, C, maximum-level maps, the particle count over
time and the cost of the run. The sea is either particles (the benchmark's still sea at 0 m)
or a sink (``--sea``); ``--sea both`` runs both, each in its own process so that each peak
memory figure is its own.

Results folder (default ``benchmarks/malpasset/results``):

* ``<sea>/``: ``malpasset.toml``, ``gauges_epsg27572.csv``, the run folder ``run/``,
  ``points.csv``, ``particles.csv`` (time, particles, wall time, outflow), ``cost.json``,
  ``max_level.png``;
* ``malpasset_points.csv`` and ``malpasset_costs.csv`` (all sea modes run so far, one row per
  point / per mode) and ``particles.png`` (particle count and wall time against time).

Usage: ``python benchmarks/malpasset/run_malpasset.py [--sea particles|sink|both]
[--end-time S] [--spacing M] [--refinement MODE] [--time-stepping global|local]
[--stabilisation lax-friedrichs|riemann|muscl] [--momentum variational|balanced] [--out DIR]
[--overwrite] [--max-steps N]``
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import malpasset_results as results  # noqa: E402
import malpasset_setup as setup  # noqa: E402

from floodsph.output.tables import write_csv  # noqa: E402

DEFAULT_OUT = setup.REPO / "benchmarks" / "malpasset" / "results"
PARTICLE_COUNT_INTERVAL_S = 10.0


def run_variant(folder: Path, out: Path, sea: str, end_time: float = setup.END_TIME_S,
                spacing: float = 20.0, gauge_interval: float = 5.0, overwrite: bool = False,
                max_steps: int | None = None, progress: bool = True,
                threads: int | None = None, numerics: dict | None = None) -> dict:
    """Write, run and report one sea mode in ``out/<sea>/``; returns its cost row.
    ``numerics``: keys of the scenario's ``[numerics]`` to set (default: floodsph's)."""
    from floodsph.run.pipeline import run_scenario
    from floodsph.scenario.reader import load_scenario
    from floodsph.simulation.schedules import TimeInterval

    where = out / sea
    path = setup.write_scenario(folder, where, sea, end_time, spacing, gauge_interval,
                                numerics)
    counter = results.ParticleCounter()
    run_dir = where / "run"
    run_scenario(load_scenario(path), out_dir=run_dir, overwrite=overwrite, progress=progress,
                 max_steps=max_steps, threads=threads,
                 callbacks=[(counter, TimeInterval(PARTICLE_COUNT_INTERVAL_S, align=False))])
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    counter.write_csv(where / "particles.csv")
    points = setup.read_points(folder)
    dem = folder / setup.DEM_NAME
    rows = results.point_table(run_dir, dem, points, sea)
    write_csv(where / "points.csv", rows, results.POINT_COLUMNS, ".3f")
    cost = results.cost_row(run_dir, sea, peak_mb)
    (where / "cost.json").write_text(json.dumps(cost, indent=2) + "\n")
    results.plot_max_level(run_dir, dem, points, where / "max_level.png",
                           f"Malpasset, sea as {sea}: maximum water level, "
                           f"t = 0-{cost['sim_time_s']:g} s")
    return cost


def summarise(out: Path) -> tuple[list[dict], list[dict]]:
    """Gather the sea modes run in ``out``: malpasset_points.csv, _costs.csv, particles.png.

    A mode counts when its run folder holds a completed run (or one stopped by
    ``--max-steps``) and its report (cost.json).
    """
    import csv

    from floodsph.run.manifest import read_manifest

    points, costs, curves = [], [], {}
    for sea in setup.SEA_MODES:
        cost_file = out / sea / "cost.json"
        manifest = read_manifest(out / sea / "run") or {}
        if manifest.get("status") not in ("completed", "stopped") or not cost_file.is_file():
            continue
        costs.append(json.loads(cost_file.read_text()))
        with open(out / sea / "points.csv", newline="") as f:
            points += list(csv.DictReader(f))
        curves[sea] = out / sea / "particles.csv"
    if costs:
        write_csv(out / "malpasset_points.csv", points, results.POINT_COLUMNS, ".3f")
        write_csv(out / "malpasset_costs.csv", costs, results.COST_COLUMNS, ".3f")
        results.plot_particles(curves, out / "particles.png")
    return points, costs


def _print(points: list[dict], costs: list[dict]) -> None:
    for c in costs:
        print(f"sea as {c['sea']}: {c['status']}, t = {c['sim_time_s']:g} s in {c['steps']} "
              f"steps, particles {c['particles_initial']} -> {c['particles_final']} (max "
              f"{c['particles_max']}), wall {c['wall_time_s']:.1f} s, peak memory "
              f"{c['peak_rss_mb']:.0f} MB, outflow {c['volume_out_m3']:.4g} m3, mass error "
              f"{c['mass_error_rel']:.1e}")
    print(f"{'sea':<10}{'id':<5}{'bed':>8}{'max lvl':>9}{'r40 lvl':>9}{'arrival':>9}")
    for p in points:
        print(f"{p['sea']:<10}{p['id']:<5}" + "".join(
            f"{float(p[k]):>9.2f}" for k in ("bed_m", "max_level_m", "max_level_r40_m"))
            + f"{float(p['arrival_time_s']):>9.0f}")


def _numerics(args) -> dict:
    """The ``[numerics]`` keys the command line sets."""
    keys = ("refinement", "time_stepping", "stabilisation", "momentum")
    return {k: getattr(args, k) for k in keys if getattr(args, k) is not None}


def _child(args, sea: str) -> int:
    """Run one sea mode in a new process (its own peak memory); its exit status."""
    cmd = [sys.executable, str(Path(__file__).resolve()), "--sea", sea, "--no-summary",
           "--end-time", repr(args.end_time), "--spacing", repr(args.spacing),
           "--gauge-interval", repr(args.gauge_interval), "--out", str(args.out)]
    cmd += ["--overwrite"] if args.overwrite else []
    cmd += ["--max-steps", str(args.max_steps)] if args.max_steps else []
    cmd += ["--threads", str(args.threads)] if args.threads is not None else []
    for key, value in _numerics(args).items():
        cmd += ["--" + key.replace("_", "-"), value]
    return subprocess.run(cmd, check=False).returncode


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sea", choices=(*setup.SEA_MODES, "both"), default="particles",
                        help="the sea as still-water particles (the benchmark), a sink, or both")
    parser.add_argument("--end-time", type=float, default=setup.END_TIME_S,
                        help="simulated time [s] (default 4000)")
    parser.add_argument("--spacing", type=float, default=20.0,
                        help="particle_spacing_m [m] (default 20, the DEM cell)")
    parser.add_argument("--gauge-interval", type=float, default=5.0,
                        help="gauge sampling interval [s]: the resolution of arrival times")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help="results folder")
    parser.add_argument("--overwrite", action="store_true", help="replace earlier runs")
    parser.add_argument("--max-steps", type=int, default=None, help="stop after N steps")
    parser.add_argument("--threads", type=int, default=None,
                        help="numba threads (default: all cores)")
    parser.add_argument("--refinement", choices=("split+coalesce", "split", "none"),
                        default=None, help="numerics.refinement (default: floodsph's)")
    parser.add_argument("--time-stepping", choices=("global", "local"), default=None,
                        help="numerics.time_stepping (default: floodsph's, local)")
    parser.add_argument("--stabilisation", choices=("lax-friedrichs", "riemann", "muscl"),
                        default=None, help="numerics.stabilisation (default: floodsph's)")
    parser.add_argument("--momentum", choices=("variational", "balanced"), default=None,
                        help="numerics.momentum (default: floodsph's)")
    parser.add_argument("--no-summary", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--write-static", action="store_true",
                        help="(re)write benchmarks/malpasset/scenario.toml and exit")
    args = parser.parse_args(argv)

    folder = setup.data_folder()
    if folder is None:
        sys.exit("Malpasset data not found: set FLOODSPH_BENCHMARKS to the folder holding "
                 f"malpasset/{setup.DEM_NAME} (default <repo>/../shared/benchmarks).")
    if args.write_static:
        static = setup.write_static_scenario(folder, Path(__file__).parent / "scenario.toml")
        print(f"wrote {static}")
        return 0
    args.out = args.out.resolve()
    status = 0
    if args.sea == "both":
        for sea in setup.SEA_MODES:
            code = _child(args, sea)
            if code:
                print(f"sea as {sea}: failed (exit status {code})", file=sys.stderr)
                status = 1
    else:
        from floodsph.errors import InputError

        try:
            run_variant(folder, args.out, args.sea, args.end_time, args.spacing,
                        args.gauge_interval, args.overwrite, args.max_steps,
                        threads=args.threads, numerics=_numerics(args))
        except InputError as exc:
            print(f"Error: {exc}", file=sys.stderr)
            return 2
    if not args.no_summary:
        points, costs = summarise(args.out)
        _print(points, costs)
        print(f"results in {args.out}")
    return status


if __name__ == "__main__":
    sys.exit(main())
