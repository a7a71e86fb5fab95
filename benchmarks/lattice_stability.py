"""Is still water seeded on the square lattice a stable state? Two measures per kappa = h0 / dx.

floodsph seeds water on a square lattice (``floodsph.inputs.initial_water``). In still water on a
flat
bed the lattice is an equilibrium; whether it is a stable one decides whether a lake stays
still or starts to stir itself after a few minutes.

1. **Curvature of the SPH energy.** Without flow, the shallow-water SPH Lagrangian leaves the
   potential energy E = (g / 2) sum_i m_i d_i (Vacondio et al., Adv. Water Resour. 58 (2013)
   10-23, with d_i from the summation density and h_i = h0 (rho0 / rho_i)^(1/2)). The
   lattice is stable if it is a minimum of E: the Hessian of E in the particle positions
   has no negative eigenvalue (two are zero: the translations). It is computed on a periodic
   n x n patch of unit spacing and unit masses by central differences; by the lattice's
   translation symmetry one particle's rows give the whole matrix. Reported: the lowest
   eigenvalue other than the two translations, in units of m g d0 / (2 dx^2), E's curvature
   for particles of mass m in water d0 deep at spacing dx (an unstable mode grows at the rate
   sqrt(-lambda g d0 / 2) / dx).
2. **A still lake in time.** 10 m of water on a flat, frictionless 1 km square (closed
   walls), particles at 20 m with positions perturbed by 2 cm (0.1 % of the spacing, random),
   run with ``FloodModel``; the maximum particle speed is printed every 80 s.
3. **A lake with a shore** (``--bowl-end-time``): the parabolic bowl of
   ``tests/sph/test_sph_dynamics.py``, b = 10 ((x - 500)^2 + (y - 500)^2) / 500^2 m, filled to
   the level 5 m (the shore on a 2.8 % slope at r = 354 m), 10 m particles, frictionless;
   the maximum and 95th-percentile speeds and the largest level error are printed every
   ``--bowl-every`` s.

Measured (README): of the kappa values tried, only 1.2 and 1.22 make the lattice a minimum;
it is a saddle at 1.0, 1.1, 1.15, 1.18, 1.25, 1.3, 1.4, 1.5, 1.6, 1.8 and 2.0. At 1.3 the
still lake reaches 5 cm/s within 240 s and 0.10 m/s by 640 s; at 1.2 it stays below 2 mm/s.

Measured (README, *Known limits*; ``--bowl-end-time 800 --bowl-every 200``): in the bowl the
shore rows reach 0.044 m/s at 200 s and 0.61 m/s at 400 s, and the level is 1.06 m off at
800 s.

Usage: ``python benchmarks/lattice_stability.py [--kappa 1.2 1.3] [--patch 8] [--end-time 640]
[--run-kappa 1.2 1.3] [--no-run] [--bowl-end-time 800] [--bowl-every 100]``
"""

from __future__ import annotations

import argparse
import math

import numpy as np
from numba import njit

from floodsph.inputs.initial_water import seed_particles
from floodsph.model.builder import set_up_model
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Momentum, Numerics
from floodsph.sph.kernels import w_cubic


@njit(cache=True)
def lattice_energy(x, y, side, kappa):
    """sum_i d_i [-] of unit masses at (x, y) in a periodic square of side ``side`` (unit
    spacing: d = 1 on the lattice), each d_i the summation density with
    h_i = kappa d_i^(-1/2), solved by fixed-point iteration to 1e-14."""
    n = x.shape[0]
    total = 0.0
    for i in range(n):
        d = 1.0
        for _ in range(500):
            h = kappa / math.sqrt(d)
            s = 0.0
            for j in range(n):
                rx = x[i] - x[j]
                ry = y[i] - y[j]
                rx -= side * math.floor(rx / side + 0.5)
                ry -= side * math.floor(ry / side + 0.5)
                s += w_cubic(math.sqrt(rx * rx + ry * ry), h)
            if abs(s - d) < 1e-14:
                break
            d = 0.5 * (d + s)
        total += s
    return total


def lowest_curvature(kappa: float, patch: int, eps: float = 2e-3) -> float:
    """Lowest eigenvalue of the Hessian of ``lattice_energy`` on a periodic patch x patch
    square lattice, the two translations (zero) left out."""
    if 2.0 * kappa >= patch / 2.0:
        raise ValueError(f"patch {patch} too small for kappa {kappa}: the support must stay "
                         f"within half the period")
    X, Y = np.meshgrid(np.arange(patch, dtype=float), np.arange(patch, dtype=float))
    z0 = np.concatenate([X.ravel(), Y.ravel()])
    n = patch * patch

    def energy(z):
        return lattice_energy(z[:n], z[n:], float(patch), kappa)

    rows = np.zeros((2, 2 * n))  # d2E / dz_a dz_b for a = x_0, y_0 (particle 0)
    for r, a in enumerate((0, n)):
        for b in range(2 * n):
            e = np.zeros(2 * n)
            e[a] += eps
            f = np.zeros(2 * n)
            f[b] += eps
            rows[r, b] = (energy(z0 + e + f) - energy(z0 + e - f) - energy(z0 - e + f)
                          + energy(z0 - e - f)) / (4.0 * eps * eps)
    # translation symmetry: block (i, j) of the Hessian is block (0, j - i)
    H = np.zeros((2 * n, 2 * n))
    ix, iy = np.meshgrid(np.arange(patch), np.arange(patch))
    ix, iy = ix.ravel(), iy.ravel()
    for i in range(n):
        j0 = ((iy - iy[i]) % patch) * patch + (ix - ix[i]) % patch  # j relative to i
        for a in range(2):
            H[a * n + i, :n] = rows[a, :n][j0]
            H[a * n + i, n:] = rows[a, n:][j0]
    w = np.linalg.eigvalsh(0.5 * (H + H.T))
    return float(np.delete(w, np.argsort(np.abs(w))[:2]).min())


def still_lake(kappa: float, end_time: float, side: float = 1000.0, spacing: float = 20.0,
               perturbation: float = 0.02, seed: int = 1, every: float = 80.0,
               momentum: Momentum = Momentum.VARIATIONAL):
    """(t [s], max particle speed [m/s]) every ``every`` s of a 10 m still lake on a flat,
    frictionless, closed square of ``side`` [m] (module docstring), under the variational
    momentum whose energy the study's Hessian is, unless ``momentum`` says otherwise."""
    terrain = Terrain.from_function(lambda x, y: 0.0 * x, (0.0, side), (0.0, side), 10.0)
    p = seed_particles(terrain, np.full(terrain.shape, 10.0), spacing, kappa)
    rng = np.random.default_rng(seed)
    p.x[:p.n] += rng.normal(0.0, perturbation, p.n)
    p.y[:p.n] += rng.normal(0.0, perturbation, p.n)
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=spacing, kappa=kappa,
                                              momentum=momentum))
    out = []
    for t_end in np.arange(every, end_time + 1e-9, every):
        while model.t < t_end - 1e-9:
            model.step(t_end - model.t)
        out.append((float(t_end), float(np.hypot(p.u[:p.n], p.v[:p.n]).max())))
    return out


def bowl_lake(end_time: float, every: float = 100.0, spacing: float = 10.0,
              level: float = 5.0):
    """(t [s], max speed [m/s], 95th-percentile speed [m/s], max |level - ``level``| [m])
    every ``every`` s of the still lake in the parabolic bowl (module docstring), seeded as
    runs seed water (``floodsph.inputs.initial_water.seed_particles``) at ``spacing`` [m]."""

    def bowl(x, y):
        return 10.0 * ((x - 500.0) ** 2 + (y - 500.0) ** 2) / 500.0**2

    terrain = Terrain.from_function(bowl, (0.0, 1000.0), (0.0, 1000.0), 10.0)
    p = seed_particles(terrain, np.maximum(level - terrain.elevation, 0.0), spacing,
                       Numerics.kappa)
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=spacing))
    out = []
    for t_end in np.arange(every, end_time + 1e-9, every):
        while model.t < t_end - 1e-9:
            model.step(t_end - model.t)
        speed = np.hypot(p.u[:p.n], p.v[:p.n])
        off = np.abs(model.depth() + model.state.bed[:p.n, 0] - level).max()
        out.append((float(t_end), float(speed.max()), float(np.percentile(speed, 95)),
                    float(off)))
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kappa", type=float, nargs="+",
                    default=[1.0, 1.1, 1.15, 1.18, 1.2, 1.22, 1.25, 1.3, 1.4, 1.5, 1.6, 1.8])
    ap.add_argument("--patch", type=int, default=8, help="periodic patch side [particles]")
    ap.add_argument("--end-time", type=float, default=640.0, help="still-lake run [s]")
    ap.add_argument("--run-kappa", type=float, nargs="+", default=[1.2, 1.3],
                    help="kappa values of the still-lake runs")
    ap.add_argument("--no-run", action="store_true", help="no flat still-lake runs")
    ap.add_argument("--bowl-end-time", type=float, default=0.0,
                    help="run the lake in the parabolic bowl this long [s] (0: not at all)")
    ap.add_argument("--bowl-every", type=float, default=100.0, help="its report interval [s]")
    args = ap.parse_args(argv)
    if args.bowl_end_time < 0.0 or args.bowl_every <= 0.0:
        ap.error(f"--bowl-end-time must be >= 0 and --bowl-every > 0, got "
                 f"{args.bowl_end_time:g} and {args.bowl_every:g}")
    print("| kappa | lowest curvature | lattice |\n| --- | --- | --- |")
    for kappa in args.kappa:
        c = lowest_curvature(kappa, args.patch)
        print(f"| {kappa:g} | {c:+.4f} | {'stable' if c > 0 else 'saddle'} |", flush=True)
    for kappa in [] if args.no_run else args.run_kappa:
        speeds = still_lake(kappa, args.end_time)
        print(f"\nstill lake, kappa {kappa:g}: max speed [m/s] at t [s]")
        print(" ".join(f"{t:.0f}: {v:.4f}" for t, v in speeds), flush=True)
    if args.bowl_end_time > 0.0:
        print("\n| t s | max speed m/s | 95th percentile m/s | level off by m |\n"
              "| --- | --- | --- | --- |")
        for t, vmax, v95, off in bowl_lake(args.bowl_end_time, args.bowl_every):
            print(f"| {t:.0f} | {vmax:.4f} | {v95:.4f} | {off:.4f} |", flush=True)


if __name__ == "__main__":
    main()
