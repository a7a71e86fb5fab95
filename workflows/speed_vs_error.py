"""Speed against error of floodsph on the analytic cases, and raw solver throughput.

Runs Ritter and Stoker dam breaks and Thacker's basin at three spacings each through the real
solver (``floodsph.verification``), plus a 100,000-particle still-water block for throughput.
Writes ``speed_vs_error.csv`` and ``speed_vs_error.png`` (error against wall time) into the
results folder and prints the table. Timings are wall-clock on this machine: compare rows of
one run, not runs on different days.

    python workflows/speed_vs_error.py [--out results/speed_vs_error] [--quick]
"""

from __future__ import annotations

import argparse
import csv
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


def throughput(n_side: int = 316, steps: int = 30) -> cases.CaseResult:
    """Particle-steps per second on an n_side^2 block of still water, flat bed, closed box."""
    dx = 5.0
    terrain = Terrain.from_function(lambda x, y: 0 * x, (0, n_side * dx), (0, n_side * dx), 10.0)
    X, Y = np.meshgrid((np.arange(n_side) + 0.5) * dx, (np.arange(n_side) + 0.5) * dx)
    p = ParticleSet(X.size)
    p.append(x=X.ravel(), y=Y.ravel(), m=np.full(X.size, RHO_WATER * 2.0 * dx * dx),
             rho=np.full(X.size, RHO_WATER * 2.0), h=np.full(X.size, 1.3 * dx))
    model = FloodModel(terrain, p, Numerics(spacing=dx, kappa=1.3))
    model.step()  # compile outside the timing
    pairs = 0
    t0 = time.perf_counter()
    for _ in range(steps):
        pairs += model.nl.count()
        model.step()
    wall = time.perf_counter() - t0
    return cases.CaseResult("throughput", dx, p.n, steps, wall, p.n * steps, pairs,
                            float("nan"), float("nan"), 0.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("results/speed_vs_error"))
    ap.add_argument("--quick", action="store_true", help="one coarse spacing per case")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    cases.ritter(20.0)  # compile every kernel once, outside the timings
    rows = []
    for name, spacings in (QUICK if args.quick else SPACINGS).items():
        for dx in spacings:
            rows.append(cases.CASES[name](dx))
            print_row(rows[-1])
    rows.append(throughput(100 if args.quick else 316))
    print_row(rows[-1])
    write_csv(args.out / "speed_vs_error.csv", rows)
    plot(args.out / "speed_vs_error.png", rows)


def print_row(r: cases.CaseResult) -> None:
    print(f"{r.case:10s} dx={r.spacing:7.1f} n={r.particles:7d} steps={r.steps:5d} "
          f"wall={r.wall_s:8.2f}s L1={r.l1:.4f} front_err={r.front_error_m:8.1f}m "
          f"mass_err={r.mass_error_rel:.1e} particle-steps/s={r.particle_steps_per_s:,.0f} "
          f"interactions/s={r.interactions_per_s:,.0f} "
          f"neighbours/particle={r.interactions / max(r.particle_steps, 1):.1f}", flush=True)


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
