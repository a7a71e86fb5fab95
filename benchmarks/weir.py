"""Steady flow over a crest wall across a channel: discharge per metre against the weir law,
free and submerged (``floodsph.boundaries.weir``, ``docs/structures.md``).

A flat, frictionless channel 5 m wide: a reservoir (x in 0-10 m) fed at its west end with a
constant discharge Q, a crest wall across the channel at x = 10 m with its crest at 1 m, and
beyond it

* ``free``: a dry channel 10 m long, open at its east end;
* ``submerged``: a basin 10 m long closed by a second crest wall at x = 20 m, crest
  ``crest2`` below 1 m, then 10 m of dry channel open at the east end. In steady flow the
  second wall passes Q freely, which holds the basin at crest2 + H(Q): the tailwater of the
  first wall.

The water starts at the levels steady flow should have, and the run goes on for ``--time``
seconds; over its second half the script records the mean level 3-7 m upstream of the first
wall (and of the second), the net volume passed over the first wall per second (what passed
west to east less what passed back), and compares:
q_model = passed volume / (time x width) against q_law = C sqrt(g) H_u^1.5 (1 - (H_d /
H_u)^1.5)^0.385 with the levels measured, and the head H_u against the head the law gives for
the inflow q = Q / width. It writes a markdown table with ``--out``.

Usage: ``python benchmarks/weir.py [--spacing 0.25] [--time 30] [--out docs/weir-benchmark.md]``
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from floodsph.boundaries import Inflow, Weir
from floodsph.boundaries.crest import Crest
from floodsph.boundaries.weir import IDEAL_COEFFICIENT, unit_discharge
from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.inputs.initial_water import particles_at
from floodsph.io.hydrograph import Hydrograph
from floodsph.model.builder import set_up_model
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Momentum, Numerics, TimeStepping

WIDTH = 5.0
BASIN = 10.0
CREST = 1.0
CASES = (("free", 0.25, None), ("free", 0.5, None), ("free", 1.0, None),
         ("submerged", 0.5, 0.95), ("submerged", 0.5, 0.98))


def free_head(q: float) -> float:
    """H [m] that passes q [m2/s] over an ideal broad crest in free flow."""
    return (q / (IDEAL_COEFFICIENT * math.sqrt(GRAVITY))) ** (2.0 / 3.0)


def submerged_head(q: float, head_down: float) -> float:
    """H_u [m] that passes q [m2/s] with the tailwater H_d [m] above the crest."""
    return brentq(lambda h: float(unit_discharge(h, head_down)) - q, head_down + 1e-9,
                  head_down + 10.0)


def lattice(x0, x1, dx):
    x, y = np.meshgrid(np.arange(x0 + dx / 2, x1, dx), np.arange(dx / 2, WIDTH, dx))
    return x.ravel(), y.ravel()


def channel(q_in: float, crest2: float | None, dx: float,
            momentum: Momentum = Momentum.BALANCED):
    """The model of a case and its weirs (module docstring)."""
    q = q_in / WIDTH
    length = 3 * BASIN if crest2 is not None else 2 * BASIN
    terrain = Terrain.from_function(lambda x, y: 0.0 * x, (0.0, length), (0.0, WIDTH), 0.5)
    num = Numerics(particle_spacing_m=dx, time_stepping=TimeStepping.GLOBAL, momentum=momentum)
    walls = [np.array([[BASIN, 0.0], [BASIN, WIDTH]])]
    weirs = [Weir(Crest(walls[0], CREST), dx, num.kappa, name="walls[0]")]
    x, y = lattice(0.0, BASIN, dx)
    if crest2 is None:
        level = np.full(x.shape, CREST + free_head(q))
    else:
        tail = crest2 + free_head(q)
        level = np.full(x.shape, CREST + submerged_head(q, tail - CREST))
        x2, y2 = lattice(BASIN, 2 * BASIN, dx)
        x, y = np.concatenate([x, x2]), np.concatenate([y, y2])
        level = np.concatenate([level, np.full(x2.shape, tail)])
        walls.append(np.array([[2 * BASIN, 0.0], [2 * BASIN, WIDTH]]))
        weirs.append(Weir(Crest(walls[1], crest2), dx, num.kappa, name="walls[1]"))
    particles = particles_at(x, y, level, dx, num.kappa)
    inflow = Inflow([[0.0, 0.0], [0.0, WIDTH]], Hydrograph([0.0, 1e5], [q_in, q_in]), dx,
                    num.kappa, terrain, direction=[1.0, 0.0])
    model = set_up_model(terrain, particles, num, walls=walls, closed_sides=("south", "north"),
                         boundaries=[inflow, *weirs])
    return model, weirs


def band_level(model, x0: float, x1: float) -> float:
    """Area-weighted mean depth [m] (the level: the bed is at 0) of the water in x0 < x < x1."""
    p = model.particles
    band = (p.x > x0) & (p.x < x1)
    if not band.any():
        return -math.inf
    return float(np.average(p.rho[band], weights=p.m[band] / p.rho[band]) / RHO_WATER)


def run_case(kind: str, q_in: float, crest2: float | None, dx: float, t_end: float,
             momentum: Momentum = Momentum.BALANCED) -> dict:
    started = time.perf_counter()
    model, weirs = channel(q_in, crest2, dx, momentum)
    half = 0.5 * t_end
    while model.t < half - 1e-9:
        model.step(half - model.t)
    v0, t0 = weirs[0].volume_net, model.t
    up, down, heads = [], [], []
    while model.t < t_end - 1e-9:
        model.step(t_end - model.t)
        up.append(band_level(model, 3.0, 7.0))
        down.append(band_level(model, BASIN + 3.0, BASIN + 7.0) if crest2 is not None
                    else -math.inf)
        heads.append(float(np.mean(weirs[0].head)))
    q_model = (weirs[0].volume_net - v0) / (model.t - t0) / WIDTH
    h_u = float(np.mean(up)) - CREST
    h_d = float(np.mean(down)) - CREST if crest2 is not None else 0.0
    q_law = float(unit_discharge(h_u, h_d))
    q = q_in / WIDTH
    h_expected = free_head(q) if crest2 is None else submerged_head(q, (crest2 + free_head(q))
                                                                       - CREST)
    return {"case": kind, "Q_in": q_in, "crest2": crest2, "q_in": q, "H_u": h_u, "H_d": h_d,
            "H_expected": h_expected, "q_model": q_model, "q_law": q_law,
            "error_q": q_model / q_law - 1.0, "error_H": h_u / h_expected - 1.0,
            "submergence": h_d / h_u, "particles": model.particles.n, "steps": model.steps,
            "wall_s": time.perf_counter() - started}


def table(rows: list[dict], dx: float, t_end: float, momentum: str = "balanced") -> str:
    lines = [
        "# Weir benchmark: steady flow over a crest wall",
        "",
        f"Written by `python benchmarks/weir.py --momentum {momentum}` (see its docstring for "
        "the set-up): a flat, "
        "frictionless channel 5 m wide, a crest wall at 1 m across it, fed with Q; the "
        f"particle spacing {dx:g} m, {t_end:g} s simulated, measured over the second half. "
        "H_u and H_d are the mean levels 3-7 m upstream and downstream of the wall above its "
        "crest; q_model the net volume passed over the wall per second and metre; q_law the weir "
        "law (C = 0.544, Villemonte) at H_u, H_d; H_expected the head the law gives for the "
        "inflow q = Q / 5 m (docs/structures.md). The net volume counts what passed "
        "back over the wall against what passed forward; wall: seconds of the run on one "
        "thread (NUMBA_NUM_THREADS=1).",
        "",
        "| case | Q [m3/s] | q [m2/s] | H_d / H_u | H_u [m] | H_expected [m] | H error | "
        "q_model [m2/s] | q_law [m2/s] | q error | particles | wall [s] |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        lines.append(
            f"| {r['case']} | {r['Q_in']:g} | {r['q_in']:.3f} | {r['submergence']:.2f} | "
            f"{r['H_u']:.4f} | {r['H_expected']:.4f} | {100 * r['error_H']:+.1f} % | "
            f"{r['q_model']:.4f} | {r['q_law']:.4f} | {100 * r['error_q']:+.1f} % | "
            f"{r['particles']} | {r['wall_s']:.0f} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spacing", type=float, default=0.25)
    parser.add_argument("--time", type=float, default=30.0)
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--momentum", choices=[m.value for m in Momentum],
                        default=Momentum.BALANCED.value, help="numerics.momentum")
    args = parser.parse_args(argv)
    rows = []
    for kind, q_in, crest2 in CASES:
        row = run_case(kind, q_in, crest2, args.spacing, args.time, Momentum(args.momentum))
        print(f"{kind:9s} Q={q_in:g} H_d/H_u={row['submergence']:.2f} H_u={row['H_u']:.4f} "
              f"(law {row['H_expected']:.4f}, {100 * row['error_H']:+.1f} %) "
              f"q={row['q_model']:.4f} vs {row['q_law']:.4f} ({100 * row['error_q']:+.1f} %) "
              f"{row['wall_s']:.0f} s", flush=True)
        rows.append(row)
    if args.out is not None:
        args.out.write_text(table(rows, args.spacing, args.time, args.momentum),
                            encoding="utf-8")
        print(f"wrote {args.out}")
    return rows


if __name__ == "__main__":
    main()
