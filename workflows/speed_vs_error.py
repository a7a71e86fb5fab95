"""Speed against error of floodsph on the analytic cases, and raw solver throughput.

Runs Ritter and Stoker dam breaks and Thacker's basin at three spacings each through the real
solver (``floodsph.verification``), plus the throughput of two ~100,000-particle blocks
(kappa 1.3, about 21 interacting neighbours per particle): still water in a closed box (the
neighbour lists are kept from step to step) and a dam break on a sloping bed (fast flow: the
lists are rebuilt every step or two). Writes ``speed_vs_error.csv`` and ``speed_vs_error.png``
(error against wall time) into the results folder and prints the table. Timings are
wall-clock on this machine: compare rows of one run, not runs on different days.

    python workflows/speed_vs_error.py [--out results/speed_vs_error] [--quick]
    python workflows/speed_vs_error.py --throughput-only [--repeats 5] [--skin 0.3]

Throughput: every kernel is compiled on a small block first, the big block is built and
advanced a few steps untimed, then ``repeats`` blocks of ``steps`` steps are timed and the
fastest is kept (the machine is shared). Only ``model.step`` is inside the timing;
interactions (directed pairs with r < 2 max(h_i, h_j)) are counted between steps.
"""

from __future__ import annotations

import argparse
import csv
import math
import time
from pathlib import Path

import numpy as np

from floodsph import verification as cases
from floodsph.constants import RHO_WATER
from floodsph.model import FloodModel, Numerics
from floodsph.particles import ParticleSet
from floodsph.terrain import Terrain

SPACINGS = {"ritter": (10.0, 5.0, 2.5), "stoker": (10.0, 5.0, 2.5),
            "thacker": (200.0, 100.0, 50.0)}
QUICK = {"ritter": (10.0,), "stoker": (10.0,), "thacker": (200.0,)}
BLOCK_SIDE = 316
"""Particles per side of the throughput blocks (316^2 = 99,856)."""


def block_model(kind: str, n_side: int, dx: float = 5.0, **numerics) -> FloodModel:
    """An n_side^2 lattice of water at spacing dx, h = 1.3 dx, closed edges.

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
             rho=np.full(X.size, RHO_WATER * depth), h=np.full(X.size, 1.3 * dx))
    return FloodModel(terrain, p, Numerics(spacing=dx, kappa=1.3, **numerics))


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
            p, nl = model.particles, model.nl
            pst += p.n
            pairs += nl.interactions(p.x, p.y, p.h)
            t0 = time.perf_counter()
            model.step()
            wall += time.perf_counter() - t0
            builds += model.nl is not nl
        if best is None or pst / wall > best[1] / best[0]:
            best = (wall, pst, pairs, builds)
    wall, pst, pairs, builds = best
    row = cases.CaseResult(f"throughput-{kind}", 5.0, model.particles.n, steps, wall, pst,
                           pairs, math.nan, math.nan, 0.0)
    return row, builds / steps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("results/speed_vs_error"))
    ap.add_argument("--quick", action="store_true", help="one coarse spacing per case")
    ap.add_argument("--throughput-only", action="store_true", help="skip the analytic cases")
    ap.add_argument("--repeats", type=int, default=3, help="timed blocks per throughput case")
    ap.add_argument("--skin", type=float, default=None, help="neighbour_skin of the blocks")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    if not args.throughput_only:
        cases.ritter(20.0)  # compile every kernel once, outside the timings
        for name, spacings in (QUICK if args.quick else SPACINGS).items():
            for dx in spacings:
                rows.append(cases.CASES[name](dx))
                print_row(rows[-1])
    numerics = {} if args.skin is None else {"neighbour_skin": args.skin}
    side = 100 if args.quick else BLOCK_SIDE
    speed = []
    for kind in ("still", "dam-break"):
        row, builds = throughput(kind, side, repeats=args.repeats, **numerics)
        rows.append(row)
        speed.append((row, builds))
        print_row(row)
    print_throughput(speed)
    write_csv(args.out / "speed_vs_error.csv", rows)
    if not args.throughput_only:
        plot(args.out / "speed_vs_error.png", rows)


def print_row(r: cases.CaseResult) -> None:
    print(f"{r.case:10s} dx={r.spacing:7.1f} n={r.particles:7d} steps={r.steps:5d} "
          f"wall={r.wall_s:8.2f}s L1={r.l1:.4f} front_err={r.front_error_m:8.1f}m "
          f"mass_err={r.mass_error_rel:.1e} particle-steps/s={r.particle_steps_per_s:,.0f} "
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


def write_csv(path: Path, rows) -> None:
    fields = ["case", "spacing", "particles", "steps", "wall_s", "l1", "front_error_m",
              "mass_error_rel", "particle_steps_per_s", "interactions_per_s"]
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(fields)
        for r in rows:
            w.writerow([getattr(r, k) for k in fields])


def plot(path: Path, rows) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("plot skipped: matplotlib not installed")
        return
    fig, ax = plt.subplots(figsize=(7, 5))
    for name in ("ritter", "stoker", "thacker"):
        sel = [r for r in rows if r.case == name]
        if sel:
            ax.loglog([r.wall_s for r in sel], [r.l1 for r in sel], "o-", label=name)
            for r in sel:
                ax.annotate(f"{r.spacing:g} m", (r.wall_s, r.l1), fontsize=8)
    ax.set_xlabel("wall time [s] (2 cores)")
    ax.set_ylabel("L1 relative depth error")
    ax.set_title("floodsph: error against wall time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.savefig(path, dpi=100, bbox_inches="tight")


if __name__ == "__main__":
    main()
