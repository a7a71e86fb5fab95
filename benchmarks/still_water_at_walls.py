"""Still water next to walls that do not run along the seeding lattice, with and without the
set-up of ``floodsph.walls.seeding`` (seeds settled, masses matched to the seeded depth).

Cases (flat, frictionless beds; walls as ``set_up_model(walls=...)`` polylines):

* ``turned-rectangle``: 2 m of water inside a 300 m x 180 m rectangle of walls turned by
  30 degrees, 5 m spacing (the lake of ``tests/walls/test_wall_seeding.py``);
* ``turned-building``: 3 m of water around a 200 m square footprint turned by 30 degrees,
  10 m spacing (four convex corners);
* ``large-building``: the same footprint in a 2 km x 1.5 km lake at 5 m spacing (118,400
  particles), for the set-up's cost on a larger domain;
* ``ritter-3.78m``: Ritter's dam break (``floodsph.verification.cases.ritter``) at the spacing
  10 / sqrt(7) m, where the channel's north wall lies 3.6 m beyond the last lattice row.

For each case and set-up it prints the largest depth error at t = 0, the seeds the set-up
selects (moved only when it is on), its volume change, its time in seconds and in time steps
(the set-up's time over the mean time of the run's first ten steps, measured in the same run;
the first case's set-up includes numba's compilation),
and the 95th-percentile and largest speed after each of ``--times`` (for Ritter, the L1 depth
error and the front's error at 50 s instead). "off" sets
``wall_seeding.SETTLE_STEPS`` and ``wall_seeding.ROUNDS`` to 0.

Usage: ``python benchmarks/still_water_at_walls.py [--times 20 100 200] [--cases ...]``
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from matplotlib.path import Path

from floodsph.constants import RHO_WATER
from floodsph.model.builder import set_up_model
from floodsph.model.flood_model import FloodModel
from floodsph.model.particles import ParticleSet
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Numerics
from floodsph.verification import cases as verification
from floodsph.walls import seeding as wall_seeding

CASES = ("turned-rectangle", "turned-building", "large-building", "ritter-3.78m")


def turned_square_polyline(angle_deg: float, centre, half) -> np.ndarray:
    """A closed polyline [m]: the rectangle of half-sides ``half`` around ``centre``, turned
    by ``angle_deg``."""
    t = math.radians(angle_deg)
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]]) * np.asarray(half)
    turn = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
    return corners @ turn.T + np.asarray(centre, dtype=float)


def lattice_lake(size, depth, dx, polyline, inside: bool) -> FloodModel:
    """Water ``depth`` [m] on a flat square lattice of spacing ``dx`` over [0, size[0]] x
    [0, size[1]] m, inside (or outside) the closed wall ``polyline``; closed grid edges."""
    x, y = np.meshgrid(np.arange(dx / 2, size[0], dx), np.arange(dx / 2, size[1], dx))
    x, y = x.ravel(), y.ravel()
    wet = Path(polyline).contains_points(np.column_stack([x, y])) == inside
    n = int(wet.sum())
    p = ParticleSet(n)
    p.append(x=x[wet], y=y[wet], m=np.full(n, RHO_WATER * depth * dx * dx),
             rho=np.full(n, RHO_WATER * depth), h=np.full(n, Numerics.kappa * dx))
    cells = (int(round(size[1] / 5.0)), int(round(size[0] / 5.0)))
    terrain = Terrain(np.zeros(cells), 5.0, 5.0, manning=0.0)
    return set_up_model(terrain, p, Numerics(particle_spacing_m=dx), walls=[polyline])


def build(case: str) -> tuple[FloodModel, float]:
    """The still-water case's model and its water depth [m]."""
    if case == "turned-rectangle":
        wall = turned_square_polyline(30.0, (200.0, 200.0), (150.0, 90.0))
        return lattice_lake((400.0, 400.0), 2.0, 5.0, wall, inside=True), 2.0
    if case == "turned-building":
        wall = turned_square_polyline(30.0, (400.0, 300.0), (100.0, 100.0))
        return lattice_lake((800.0, 600.0), 3.0, 10.0, wall, inside=False), 3.0
    wall = turned_square_polyline(30.0, (1000.0, 750.0), (100.0, 100.0))
    return lattice_lake((2000.0, 1500.0), 3.0, 5.0, wall, inside=False), 3.0


def still_water_row(case: str, times) -> str:
    t0 = time.perf_counter()
    model, depth = build(case)
    setup = time.perf_counter() - t0
    p = model.particles
    cells = [case, f"{np.abs(model.depth() - depth).max():.3f}",
             f"{model.state.counters['seeds_settled']}",
             f"{model.state.volume_seed_adjustment:+.1f}",
             f"{setup:.1f}"]
    t0 = time.perf_counter()
    for _ in range(10):
        model.step()
    cells.append(f"({10.0 * setup / (time.perf_counter() - t0):.0f} steps)")
    for t_end in times:
        while model.t < t_end - 1e-9:
            model.step(t_end - model.t)
        speed = np.hypot(p.u, p.v)
        cells.append(f"{np.percentile(speed, 95):.3f}/{speed.max():.3f}")
    return "  ".join(cells)


def ritter_row() -> str:
    r = verification.ritter(10.0 / math.sqrt(7.0))
    return f"ritter-3.78m  L1 {100 * r.l1:.2f} %, front {r.front_error_m:+.0f} m at 50 s"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--times", type=float, nargs="+", default=[20.0, 100.0, 200.0])
    ap.add_argument("--cases", nargs="+", choices=CASES, default=list(CASES))
    args = ap.parse_args(argv)
    settle_steps, rounds = wall_seeding.SETTLE_STEPS, wall_seeding.ROUNDS
    print("case  max|d - d0| at 0 s [m]  wall seeds  volume change [m3]  set-up [s] (steps)  "
          + "  ".join(f"p95/max speed at {t:g} s [m/s]" for t in args.times))
    for setup in ("off", "on"):
        wall_seeding.SETTLE_STEPS, wall_seeding.ROUNDS = ((0, 0) if setup == "off"
                                                          else (settle_steps, rounds))
        print(f"-- set-up {setup}")
        for case in args.cases:
            print(ritter_row() if case == "ritter-3.78m" else still_water_row(case, args.times),
                  flush=True)
    wall_seeding.SETTLE_STEPS, wall_seeding.ROUNDS = settle_steps, rounds


if __name__ == "__main__":
    main()
