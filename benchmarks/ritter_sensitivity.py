"""How the refined Ritter convergence study depends on the daughters' relaxed smoothing.

Runs ``floodsph.verification.cases.ritter`` (d0 = 10 m, t = 50 s) at 10, 5 and 2.5 m with
``split+coalesce`` (or ``--mode split``) for each value of ``Numerics.refine_smoothing_excess``
(split particles relax to h^2 rho = smoothing_excess kappa^2 m), and checks each row against
the targets of issue 2:

* L1 relative depth error at most 1.5 % at 5 m (not met if 5 m is not among ``--spacings``);
* observed order (least-squares slope of log L1 against log spacing) at least 0.8;
* the front (last x with d > 0.1 m) within two spacings at every spacing.

Prints a Markdown table and writes it, with the command, to ``--out`` (default
``results/ritter_sensitivity.md``). The runs are deterministic; the spread between
neighbouring values shows how close the targets lie to the scheme's split-and-merge noise.

First it prints two static density dipoles in a lake at rest: the one a split leaves
(:func:`split_column_dipole`: a column of particles split, the daughters' depth and that of the
unsplit particles beside them), and the one at a resolution interface with no split at all
(:func:`resolution_interface_dipole`: a flow-stretched lattice beside the lattice of its
daughters, the depth of the last coarse and the first fine column).

    python benchmarks/ritter_sensitivity.py [--excess 2 2.5 3 4] [--mode split+coalesce]
        [--spacings 10 5 2.5] [--out results/ritter_sensitivity.md]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from floodsph.constants import RHO_WATER
from floodsph.errors import InputError
from floodsph.model.builder import set_up_model
from floodsph.model.flood_model import FloodModel
from floodsph.model.particles import ParticleSet
from floodsph.model.refinement import Refiner
from floodsph.model.terrain import Terrain
from floodsph.output.tables import markdown
from floodsph.scenario.numerics import Numerics, Refinement
from floodsph.verification import cases, metrics

L1_AT_5M = 0.015
ORDER_MIN = 0.8
FRONT_SPACINGS = 2.0


def _still_lake(size, dx, d0, x, y, area, h) -> FloodModel:
    """Still water d0 [m] deep on a flat bed of ``size`` (width, height) [m]: particles at
    (x, y) [m] with areas ``area`` [m2] (mass rho_w d0 area) and smoothing lengths h [m]."""
    terrain = Terrain.from_function(lambda x, y: 0.0 * x, (0, size[0]), (0, size[1]), dx)
    p = ParticleSet(x.size)
    p.append(x=x, y=y, m=RHO_WATER * d0 * area, rho=np.full(x.size, RHO_WATER * d0), h=h)
    return set_up_model(terrain, p, Numerics(particle_spacing_m=dx))


def split_column_dipole(d0: float = 4.0, dx: float = 10.0) -> dict:
    """Depths [m] after splitting one column of a lake at rest (depth d0, spacing dx, 400 m x
    200 m, flat): the daughters' range and the range of the unsplit particles within 3 dx."""
    X, Y = np.meshgrid(np.arange(dx / 2, 400, dx), np.arange(dx / 2, 200, dx))
    model = _still_lake((400, 200), dx, d0, X.ravel(), Y.ravel(), np.full(X.size, dx * dx),
                        np.full(X.size, Numerics.kappa * dx))
    p = model.particles
    column = np.flatnonzero((np.abs(p.x - 205.0) < 1.0) & (p.y > 40.0) & (p.y < 160.0))
    Refiner(Numerics(particle_spacing_m=dx, refinement=Refinement.SPLIT, refine_area_max=0.5,
                     refine_area_min=0.2)).execute(model, column, [], [])
    model.step(1e-9)  # neighbour lists and the density solve, the particles all but unmoved
    d = p.rho / RHO_WATER
    middle = np.abs(p.y - 100.0) < 20.0
    beside = middle & (p.level == 0) & (np.abs(p.x - 205.0) < 3.0 * dx)
    split = middle & (p.level > 0)
    return {"depth": d0, "daughters": (d[split].min(), d[split].max()),
            "beside": (d[beside].min(), d[beside].max())}


def resolution_interface_dipole(d0: float = 5.0, dx: float = 5.0) -> dict:
    """Depths [m] across a resolution interface in a lake at rest, with no split at all.

    Flat, 400 m x 100 m, depth d0: for x < 200 m the lattice a thinning channel flow leaves
    just before its particles split (2 dx along the flow, dx across, mass rho_w d0 2 dx^2,
    h = kappa sqrt(2) dx); beyond, the lattice of its daughters (dx by dx, half the mass,
    h = kappa dx). Returns the mean depths, over the middle rows, of the coarse lattice
    (x 100-160 m), its last column and the first fine column. Any split pattern leaves such an
    interface: the coarse kernel spans under two spacings each way along the flow
    (2 h / (2 dx) = kappa / sqrt(2)), and the fine particles beside it weigh more in its sum
    than the coarse column they replace.
    """
    xc, yc = np.meshgrid(np.arange(dx, 200, 2 * dx), np.arange(dx / 2, 100, dx))
    xf, yf = np.meshgrid(np.arange(200 + dx / 2, 400, dx), np.arange(dx / 2, 100, dx))
    nc, nf = xc.size, xf.size
    model = _still_lake((400, 100), dx, d0, np.r_[xc.ravel(), xf.ravel()],
                        np.r_[yc.ravel(), yf.ravel()],
                        dx * dx * np.r_[np.full(nc, 2.0), np.full(nf, 1.0)],
                        Numerics.kappa * dx * np.r_[np.full(nc, np.sqrt(2.0)), np.full(nf, 1.0)])
    p = model.particles
    model.step(1e-9)  # neighbour lists and the density solve, the particles all but unmoved
    d = p.rho / RHO_WATER
    middle = np.abs(p.y - 50.0) < 15.0

    def mean_depth(a, b):
        return float(d[middle & (p.x > a) & (p.x < b)].mean())

    return {"depth": d0, "coarse": mean_depth(100.0, 160.0),
            "last coarse": mean_depth(200.0 - 2 * dx, 200.0),
            "first fine": mean_depth(200.0, 200.0 + dx)}


def study(excess: float, mode: str, spacings: list[float]) -> dict:
    """One convergence study: the row of the table for ``smoothing_excess = excess``."""
    results = [cases.ritter(dx, refinement=Refinement(mode), refine_smoothing_excess=excess)
               for dx in spacings]
    l1 = [r.l1 for r in results]
    order = metrics.observed_order(l1, spacings)
    fronts_ok = all(abs(r.front_error_m) <= FRONT_SPACINGS * r.spacing for r in results)
    at_5m = [r.l1 for r in results if r.spacing == 5.0]
    l1_ok = bool(at_5m) and at_5m[0] <= L1_AT_5M
    return {
        "smoothing_excess": excess,
        "L1 % at " + " / ".join(f"{dx:g}" for dx in spacings) + " m":
            " / ".join(f"{100 * e:.3f}" for e in l1),
        "order": f"{order:.3f}",
        "front m": " / ".join(f"{r.front_error_m:+.0f}" for r in results),
        "particles at the end": " / ".join(str(r.particles) for r in results),
        "wall s": f"{sum(r.wall_s for r in results):.0f}",
        "meets": ", ".join(name for name, ok in (("L1", l1_ok), ("order", order >= ORDER_MIN),
                                                 ("fronts", fronts_ok)) if ok) or "-",
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--excess", type=float, nargs="+", default=[2.0, 2.4, 2.5, 2.6, 3.0, 4.0])
    ap.add_argument("--mode", default="split+coalesce", choices=["split", "split+coalesce"])
    ap.add_argument("--spacings", type=float, nargs="+", default=[10.0, 5.0, 2.5])
    ap.add_argument("--out", type=Path, default=Path("results/ritter_sensitivity.md"))
    args = ap.parse_args(argv)
    if len(set(args.spacings)) < 2:
        ap.error(f"--spacings: an observed order needs two spacings or more, got {args.spacings}")
    for excess in args.excess:
        try:
            Numerics(refinement=Refinement(args.mode), refine_smoothing_excess=excess)
        except InputError as err:
            ap.error(f"--excess: {err}")
    dipole = split_column_dipole()
    dipole_line = ("one split column in a lake at rest, depth {depth} m: daughters "
                   "{0:.3f}-{1:.3f} m, unsplit particles beside them {2:.3f}-{3:.3f} m").format(
        *dipole["daughters"], *dipole["beside"], depth=dipole["depth"])
    interface = resolution_interface_dipole()
    dipole_line += ("; a stretched lattice beside its daughters' lattice, depth {depth} m: "
                    "stretched lattice {0:.3f} m, its last column {1:.3f} m, first fine column "
                    "{2:.3f} m").format(interface["coarse"], interface["last coarse"],
                                        interface["first fine"], depth=interface["depth"])
    print(dipole_line, flush=True)
    rows = []
    for excess in args.excess:
        rows.append(study(excess, args.mode, args.spacings))
        print(rows[-1], flush=True)
    table = markdown(rows)
    print(table)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(f"`python {' '.join(sys.argv)}`, mode {args.mode}\n\n{dipole_line}\n\n"
                        f"{table}\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
