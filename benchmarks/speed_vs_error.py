"""Speed against error of floodsph: analytic cases, real terrain, and raw solver throughput.

* **Analytic cases** (``floodsph.verification.cases``): Ritter and Stoker dam breaks and Thacker's
  basin at three spacings each, in each refinement mode (default: all three, ``none``,
  ``split`` and ``split+coalesce``) and each time stepping (``--time-stepping``, default
  global; ``global local`` runs both); the error is the L1 relative depth error against the
  exact solution.
* **Real cases**: Malpasset (``benchmarks/malpasset/scenario.toml``, 1000 s, the sea as
  particles) and EA Test 4 (``benchmarks/ea_test4``, 18000 s) at three particle spacings in
  each mode, through the real run chain (run folders, maps). Their observed values are held
  back, so the error is against the finest ``split+coalesce`` run of the case (the
  reference): CSI of the max-depth maps (wet = 0.1 m) and depth RMSE where both are wet.
  The data is read from ``$FLOODSPH_BENCHMARKS`` (or ``<repo>/../shared/benchmarks``); a case
  whose data is absent is skipped with a message.
* **Throughput** of two ~100,000-particle blocks (the default kappa, 1.2: 20 interacting
  neighbours per particle on the lattice, as at 1.3): still water in a closed box (the
  neighbour lists are kept from step to step) and a dam break on a sloping bed (fast flow:
  the lists are rebuilt every step or two).

Writes into the results folder ``speed_vs_error.csv`` (analytic and throughput rows),
``real_cases.csv``, ``speed_vs_error.png`` (error against wall time, one panel per case: the
Pareto view) and ``speed_vs_error.md`` (the report, with the command that made it). Timings
are wall-clock on this machine: compare rows of one run, not runs on different days.

    python benchmarks/speed_vs_error.py [--out results/speed_vs_error] [--quick]
        [--cases ritter stoker thacker malpasset ea_test4] [--modes none split split+coalesce]
        [--max-steps N] [--real-spacings DX [DX ...]] [--time-stepping global local]
        [--no-throughput]
    python benchmarks/speed_vs_error.py --throughput-only [--repeats 5] [--skin 0.3]

Throughput: every kernel is compiled on a small block first, the big block is built and
advanced a few steps untimed, then ``repeats`` blocks of ``steps`` steps are timed and the
fastest is kept (the machine is shared). Only ``model.step`` is inside the timing;
interactions (directed pairs with r < 2 max(h_i, h_j)) are counted between steps.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent / "malpasset"))
sys.path.insert(0, str(Path(__file__).resolve().parent / "ea_test4"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import malpasset_setup as mp_setup  # noqa: E402
import run_ea_test4 as ea4  # noqa: E402
import scenario_runs as runs  # noqa: E402

from floodsph.constants import RHO_WATER  # noqa: E402
from floodsph.model.builder import set_up_model  # noqa: E402
from floodsph.model.flood_model import FloodModel  # noqa: E402
from floodsph.model.particles import ParticleSet  # noqa: E402
from floodsph.model.terrain import Terrain  # noqa: E402
from floodsph.output.tables import markdown, write_csv  # noqa: E402
from floodsph.scenario.numerics import Numerics, Refinement, TimeStepping  # noqa: E402
from floodsph.verification import cases  # noqa: E402

REPO = Path(__file__).resolve().parents[1]

BLOCK_SIDE = 316
"""Particles per side of the throughput blocks (316^2 = 99,856)."""


def block_model(kind: str, n_side: int, dx: float = 5.0, **numerics) -> FloodModel:
    """An n_side^2 lattice of water at spacing dx, h = kappa dx (the default kappa), closed edges.

    kind "still": 2 m of still water filling a flat box. kind "dam-break": 4 m of water in
    the upstream half of a box twice as long, released onto a dry bed sloping 1e-3 downstream.
    """
    side = n_side * dx
    if kind == "still":
        terrain = Terrain.from_function(lambda x, y: 0 * x, (0, side), (0, side), 10.0)
        depth = 2.0
    else:
        terrain = Terrain.from_function(lambda x, y: -1e-3 * x, (0, 2 * side), (0, side), 10.0)
        depth = 4.0
    X, Y = np.meshgrid((np.arange(n_side) + 0.5) * dx, (np.arange(n_side) + 0.5) * dx)
    p = ParticleSet(X.size)
    p.append(x=X.ravel(), y=Y.ravel(), m=np.full(X.size, RHO_WATER * depth * dx * dx),
             rho=np.full(X.size, RHO_WATER * depth), h=np.full(X.size, Numerics.kappa * dx))
    return set_up_model(terrain, p, Numerics(particle_spacing_m=dx, **numerics))


def throughput(kind: str, n_side: int = BLOCK_SIDE, steps: int = 10, repeats: int = 3,
               **numerics) -> tuple[cases.CaseResult, float]:
    """Fastest of ``repeats`` timed blocks of ``steps`` steps; returns (row, list builds/step)."""
    small = block_model(kind, 20, **numerics)
    for _ in range(3):
        small.step()  # compile every kernel outside the timing
    model = block_model(kind, n_side, **numerics)
    for _ in range(2):
        model.step()
    best = None
    for _ in range(repeats):
        wall, pst, pairs, builds = 0.0, 0, 0, 0
        for _ in range(steps):
            p, nl = model.particles, model.work.nl
            pst += p.n
            pairs += nl.interactions(p.x, p.y, p.h)
            t0 = time.perf_counter()
            model.step()
            wall += time.perf_counter() - t0
            builds += model.work.nl is not nl
        if best is None or pst / wall > best[1] / best[0]:
            best = (wall, pst, pairs, builds)
    wall, pst, pairs, builds = best
    row = cases.CaseResult(f"throughput-{kind}", 5.0, model.particles.n, steps, wall, pst,
                           pairs, math.nan, math.nan, 0.0,
                           particles_max=model.state.counters["particles_max"])
    return row, builds / steps


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("results/speed_vs_error"))
    ap.add_argument("--quick", action="store_true", help="one coarse spacing per case")
    ap.add_argument("--cases", nargs="+", choices=[*ANALYTIC, *REAL], default=[*ANALYTIC, *REAL])
    ap.add_argument("--modes", nargs="+", choices=MODES, default=list(MODES))
    ap.add_argument("--time-stepping", nargs="+", choices=STEPPINGS, default=["global"],
                    help="numerics.time_stepping of the analytic and real cases")
    ap.add_argument("--max-steps", type=int, default=None, help="real cases: stop after N steps")
    ap.add_argument("--real-spacings", nargs="+", type=float, default=None,
                    help="particle spacings [m] of the real cases (default: each case's three)")
    ap.add_argument("--throughput-only", action="store_true", help="only the throughput blocks")
    ap.add_argument("--no-throughput", action="store_true", help="skip the throughput blocks")
    ap.add_argument("--repeats", type=int, default=3, help="timed blocks per throughput case")
    ap.add_argument("--skin", type=float, default=None, help="neighbour_skin of the blocks")
    args = ap.parse_args(argv)
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    rows, real = [], []
    if not args.throughput_only:
        names = [c for c in args.cases if c in ANALYTIC]
        if names:  # compile every kernel once, outside the timings
            cases.ritter(20.0, refinement=Refinement.SPLIT_COALESCE)
        for name in names:
            for dx in (QUICK if args.quick else SPACINGS)[name]:
                for mode in args.modes:
                    for stepping in args.time_stepping:
                        rows.append(cases.CASES[name](dx, refinement=Refinement(mode),
                                                      time_stepping=TimeStepping(stepping)))
                        print_row(rows[-1])
        for name in (c for c in args.cases if c in REAL):
            real += real_case(name, out / name, args.modes, args.quick, args.max_steps,
                              args.real_spacings, args.time_stepping)
    speed = []
    if not args.no_throughput:
        numerics = {} if args.skin is None else {"neighbour_skin": args.skin}
        side = 100 if args.quick else BLOCK_SIDE
        for kind in ("still", "dam-break"):
            row, builds = throughput(kind, side, repeats=args.repeats, **numerics)
            rows.append(row)
            speed.append((row, builds))
            print_row(row)
        print_throughput(speed)
    if rows:
        write_csv(out / "speed_vs_error.csv",
                  [{k: getattr(r, k) for k in CSV_COLUMNS} for r in rows], CSV_COLUMNS)
    if real:
        write_csv(out / "real_cases.csv", real, REAL_COLUMNS)
    analytic = [r for r in rows if r.case in ANALYTIC]
    picture = plot(out / "speed_vs_error.png", analytic, real)
    (out / "speed_vs_error.md").write_text(report(analytic, real, speed, picture, argv))
    print(f"report: {out / 'speed_vs_error.md'}")


def real_scenario(case: str, out: Path) -> Path | None:
    """The scenario file of a real case, written into ``out`` from the benchmark data (the
    absolute DEM path in it), or None when the data is absent."""
    module = mp_setup if case == "malpasset" else ea4
    folder = module.data_folder()
    if folder is None:
        print(f"{case}: skipped, benchmark data not found (set FLOODSPH_BENCHMARKS)")
        return None
    out.mkdir(parents=True, exist_ok=True)
    end_time = REAL[case]["end_time"]
    if case == "malpasset":
        return mp_setup.write_scenario(folder, out, "particles", end_time, 20.0)
    return ea4.write_inputs(folder, out, end_time, 5, 5.0)


def real_case(case: str, out: Path, modes, quick: bool, max_steps: int | None,
              spacings=None, steppings=("global",)) -> list[dict]:
    """Runs of a real case at its spacings (``spacings``, default the case's own) in each
    mode and time stepping, with their agreement with the finest ``split+coalesce`` run (or
    the finest run of the first mode without it) of the first time stepping."""
    path = real_scenario(case, out)
    if path is None:
        return []
    spacings = spacings or REAL[case]["spacings"]
    spacings = spacings[:1] if quick else spacings
    rows = []
    for dx in spacings:
        for mode in modes:
            for stepping in steppings:
                folder = out / f"{mode}_{dx:g}m_{stepping}"
                scenario = runs.variant(path, folder, mode, dx, time_stepping=stepping)
                rows.append(runs.run(scenario, folder, max_steps, case=case) | {"run": folder})
    ref_mode = "split+coalesce" if "split+coalesce" in modes else modes[0]
    ref = min((r for r in rows if r["mode"] == ref_mode and r["time_stepping"] == steppings[0]),
              key=lambda r: r["spacing_m"])
    name, ref_run = f"{ref_mode} {ref['spacing_m']:g} m {steppings[0]}", ref["run"]
    for r in rows:
        r.update(reference=name, **runs.agreement(r.pop("run"), ref_run))
    return rows


SPACINGS = {"ritter": (10.0, 5.0, 2.5), "stoker": (10.0, 5.0, 2.5),
            "thacker": (200.0, 100.0, 50.0)}
QUICK = {"ritter": (10.0,), "stoker": (10.0,), "thacker": (200.0,)}
ANALYTIC = tuple(SPACINGS)
REAL = {"malpasset": {"spacings": (80.0, 60.0, 40.0), "end_time": 1000.0},
        "ea_test4": {"spacings": (20.0, 10.0, 5.0), "end_time": ea4.END_TIME_S}}
MODES = ("none", "split", "split+coalesce")
STEPPINGS = ("global", "local")
CSV_COLUMNS = ["case", "refinement", "time_stepping", "spacing", "particles", "particles_max",
               "steps", "wall_s", "l1", "front_error_m", "mass_error_rel", "particle_steps_per_s",
               "interactions_per_s"]
REAL_COLUMNS = ["case", "mode", "time_stepping", "spacing_m", "wall_s", "sim_time_s", "steps",
                "particles_initial", "particles_max", "particle_steps", "splits", "merges",
                "mass_error_rel", "reference", "csi", "rmse_m", "bias_m"]


def print_row(r: cases.CaseResult) -> None:
    print(f"{r.case:10s} {r.refinement:14s} {r.time_stepping:6s} dx={r.spacing:7.1f} "
          f"n={r.particles:7d} "
          f"steps={r.steps:5d} wall={r.wall_s:8.2f}s L1={r.l1:.4f} "
          f"front_err={r.front_error_m:8.1f}m mass_err={r.mass_error_rel:.1e} "
          f"particle-steps/s={r.particle_steps_per_s:,.0f} "
          f"interactions/s={r.interactions_per_s:,.0f} "
          f"neighbours/particle={r.interactions / max(r.particle_steps, 1):.1f}", flush=True)


def print_throughput(speed) -> None:
    print(f"\n{'case':22s} {'particles':>9s} {'steps':>5s} {'wall s':>7s} "
          f"{'particle-steps/s':>16s} {'interactions/s':>14s} {'neighbours':>10s} "
          f"{'list builds/step':>16s}")
    for r, builds in speed:
        print(f"{r.case:22s} {r.particles:9d} {r.steps:5d} {r.wall_s:7.2f} "
              f"{r.particle_steps_per_s:16,.0f} {r.interactions_per_s:14,.0f} "
              f"{r.interactions / r.particle_steps:10.1f} {builds:16.2f}")


def report(analytic, real, speed, picture, argv) -> str:
    """The markdown report: the command, the three tables and the picture."""
    import numba

    command = " ".join(["python benchmarks/speed_vs_error.py", *(argv or sys.argv[1:])])
    lines = ["# floodsph: speed against error", "",
             f"Made by `{command}` on {time.strftime('%Y-%m-%d')}, {os.cpu_count()} cores, "
             f"{numba.get_num_threads()} numba thread(s). Wall times are of this machine and "
             "this run: compare rows, not runs.", ""]
    if analytic:
        lines += ["## Analytic cases (error against the exact solution)", "",
                  markdown([{"case": r.case, "refinement": r.refinement,
                             "time stepping": r.time_stepping, "spacing m": r.spacing,
                             "peak particles": r.particles_max, "steps": r.steps,
                             "wall s": r.wall_s, "L1": r.l1, "front error m": r.front_error_m,
                             "mass error": r.mass_error_rel} for r in analytic]), ""]
    if real:
        lines += ["## Real terrain (agreement with a reference run)", "",
                  "Observed values are held back; `csi` and `rmse_m` compare each run's "
                  "max-depth map with the case's reference run, its finest split+coalesce "
                  "run (wet = 0.1 m; RMSE over cells wet in both). The reference scores "
                  "itself perfectly, and a run at its spacing in another mode measures the "
                  "difference between the modes, not a convergence error.", "",
                  markdown([{k: r[k] for k in ("case", "mode", "time_stepping", "spacing_m",
                                               "reference", "wall_s",
                                               "particles_max", "particle_steps",
                                               "mass_error_rel", "csi", "rmse_m")}
                            for r in real]), ""]
    if speed:
        lines += ["## Throughput (blocks of still water and of a dam break)", "",
                  markdown([{"block": r.case, "particles": r.particles, "neighbours":
                             r.interactions / r.particle_steps,
                             "particle-steps/s": r.particle_steps_per_s,
                             "interactions/s": r.interactions_per_s,
                             "list builds/step": builds} for r, builds in speed]), ""]
    if picture is not None:
        lines += [f"![error against wall time]({picture.name})", ""]
    return "\n".join(lines)


def plot(path: Path, analytic, real) -> Path | None:
    """Error against wall time, one log-log panel per case, one line per mode and time
    stepping."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("plot skipped: matplotlib not installed")
        return None
    series = []
    for name in ANALYTIC:
        for mode in MODES:
            for stepping in STEPPINGS:
                sel = [(r.wall_s, r.l1, r.spacing) for r in analytic if r.case == name
                       and r.refinement == mode and r.time_stepping == stepping]
                series.append((name, "L1 relative depth error", mode, stepping, sel))
    for name in REAL:
        for mode in MODES:
            for stepping in STEPPINGS:
                sel = [(r["wall_s"], r["rmse_m"], r["spacing_m"]) for r in real
                       if r["case"] == name and r["mode"] == mode
                       and r["time_stepping"] == stepping and r["rmse_m"] > 0]
                series.append((name, "max-depth RMSE vs reference [m]", mode, stepping, sel))
    panels = [n for n in (*ANALYTIC, *REAL) if any(s[0] == n and s[4] for s in series)]
    if not panels:
        return None
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 3.8), squeeze=False)
    for ax, name in zip(axes[0], panels, strict=True):
        for case, label, mode, stepping, sel in series:
            if case != name or not sel:
                continue
            wall, err, dx = zip(*sel, strict=True)
            ax.loglog(wall, err, ("o" if mode == "none" else "s")
                      + ("-" if stepping == "global" else ":"),
                      label=mode if stepping == "global" else f"{mode}, local")
            for w, e, d in sel:
                ax.annotate(f"{d:g} m", (w, e), fontsize=7)
            ax.set_ylabel(label)
        ax.set_title(name)
        ax.set_xlabel("wall time [s]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


if __name__ == "__main__":
    main()
