"""Seeds of still water next to walls: settled, and their masses matched to the seeded depth.

Water is seeded on a square lattice of spacing dx with m_i = rho_w d_i dx^2
(``floodsph.inputs.initial_water``). In a full kernel support the SPH depth of such a lattice is the
seeded d, and still water is an equilibrium (``docs/method.md`` §2). Next to a wall the mirror
images (``floodsph.walls``) complete the support exactly only where the lattice rows run
along the wall, half a spacing from it. Along an oblique wall (a nodata chord, a user's
embankment) the seeds lie at every distance from it, and their images crowd them or leave
gaps. In a frictionless 2 m lake held by a rectangle of walls turned by 30 degrees (5 m
spacing, ``tests/walls/test_wall_seeding.py``) the seeds next to the walls read up to 0.84 m off,
and the lake sloshed: 95th-percentile speed 0.074 / 0.037 / 0.032 m/s after 20 / 100 / 200 s,
0.048 m/s at most after 200 s. A wall along the rows does the same where it is not half a
spacing from the last row: in Ritter's 100 m wide channel at a spacing of 10 / sqrt(7) m the
north wall lies 3.6 m beyond it, and the dam break's L1 depth error was 1.83 % (0.96 % at
5 m, where the wall is half a spacing away).

When the model is set up (``floodsph.model.wall_seeds.settle_at_walls``), the seeds next
to walls that are in still water and enclosed (below) are therefore

1. settled: moved by a_i dt^2 / 2 per round, with dt the model's CFL step, along the
   acceleration as in a steepest descent of the SPH energy, with the other particles held and
   walls reflecting the moves, each seed at most ``MAX_SHIFT`` spacings in all from where it
   was seeded (:func:`limited_move`), until |a_i| < ``SETTLED`` g or for ``SETTLE_STEPS``
   rounds. Each seed's own step cfl h_i / sqrt(g d_i), longer than the model's where the
   water is deeper or h longer elsewhere, settled the building of
   ``benchmarks/still_water_at_walls.py`` worse: 95th-percentile speed 0.108 m/s after 200 s,
   against 0.062;
2. matched: m_i <- m_i d*_i / d_i (Jacobi), with d* the seeded depth and d the SPH depth of
   the density solve, until max |d_i / d*_i - 1| < ``TOLERANCE`` or for ``ROUNDS`` rounds,
   each mass within [``MASS_MIN``, ``MASS_MAX``] times its seeded value.

In the lake above (300 rounds of settling), the depth is then within 1.2 % of 2 m and the
95th-percentile speed 0.018 / 0.009 / 0.006 m/s after 20 / 100 / 200 s, 0.014 m/s at most
after 200 s; the Ritter run above has an L1 error of 0.66 %. In the lake, settling alone gave
0.022 / 0.012 / 0.014 m/s (depth within 2 %); 100 rounds 0.019 / 0.009 / 0.009, 1,000 rounds
0.017 / 0.007 / 0.006. Matching alone (masses within 0.8-1.25 times) gave
0.032 / 0.020 / 0.020 m/s. Unbounded, it took some masses to 1.7 times their seed, and in the
nodata basin of ``tests/walls/test_nodata_walls.py`` such a particle, squeezed into a corner,
reached 12.8 m/s; after settling, the masses of the lake above stay within 0.95-1.08 times.

Which seeds: lattice seeds (m = rho_w d* dx^2: not inflow or split particles) with a wall in
their near list, out of open boundaries' zones, that are

* still (:func:`still_water`, :func:`with_neighbours`): every particle within two
  neighbour lists of the seed (about 4.4 h) is at rest, and its neighbours' seeded depths and
  bed elevations differ from its own by at most ``LEVEL_TOLERANCE`` times its depth. Where
  the water flows, or its depth or the bed changes across the kernel (a lake on a slope
  against a wall), a seed's acceleration is not the walls' error alone: settling moved the
  wall column of a lake on a 3 % slope, and the balance of the columns behind it went from
  below 1 % of g s to 3.7 %;
* enclosed (:func:`enclosed_seeds`): every lattice node within ``ENCLOSURE`` h of the seed is
  water (a seed within dx / 2 of it) or hidden behind a wall. Near a free shore or a dam
  break's front, the seed's neighbours are pulled by the front, and settling would move the
  water toward it.

Each settling round and each matching round solves density and forces for the seeds and
``RINGS`` rings of their listed neighbours alone (:func:`neighbourhood`): the other particles
do not move, and their density does not change. In a 2 km x 1.5 km lake around a turned
building (118,400 particles, 4,612 seeds, ``benchmarks/still_water_at_walls.py``) this cut the
set-up from the time of 321 steps to that of 101, with the seeds ending where they did.

The matching changes the seeded volume (+40 m3, 0.04 %, in the lake above); the model reports
the change (``State.volume_seed_adjustment``, ``volume_seed_adjustment_m3`` in
``run.json``) and the mass balance starts from the adjusted volume. Walls along the lattice
(a box, a building aligned with it) leave every seed as it was.

Units: x, y, h, dx [m]; a [m s-2]; m [kg]; rho [kg m-2].
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from scipy.spatial import cKDTree

from floodsph.walls.geometry import crosses

SETTLE_STEPS = 300
"""Largest number of settling rounds (each one density and force evaluation)."""
SETTLED = 1e-4
"""Acceleration, in units of g, below which every settled seed counts as at rest."""
MAX_SHIFT = 0.5
"""Largest distance, in spacings, a seed is moved from where it was seeded."""
TOLERANCE = 1e-3
"""Relative depth error |d / d* - 1| at which the matching stops."""
ROUNDS = 40
"""Largest number of density solves of the matching."""
MASS_MIN = 0.8
MASS_MAX = 1.25
"""Bounds of a matched mass, relative to its seeded value."""
ENCLOSURE = 4.0
"""Reach, in smoothing lengths, within which a settled seed's lattice nodes must all be water
or behind walls: its neighbours' kernel supports (2 h) are then complete too."""
LEVEL_TOLERANCE = 0.01
"""Largest difference of seeded depth, and of bed elevation, between a settled seed and its
neighbours, relative to its depth."""
RINGS = 2
"""Rings of listed neighbours around the seeds whose density and forces each settling round
solves: a seed moves at most ``MAX_SHIFT`` spacings, so a particle it may come within reach of
is in the second ring."""


def limited_move(ax, ay, dt, sx, sy, limit):
    """Moves (mx, my) = f a dt^2 / 2 [m] of seeds with accelerations (ax, ay) [m s-2] and
    pseudo-time steps dt [s], now (sx, sy) [m] from where they were seeded: f <= 1 is the
    largest that keeps |s + m| <= ``limit`` [m], so a seed at the limit can still move along
    it or back. A move that a wall reflects ends nearer the seed than it would have (the seed
    lies on the wall's water side), so the bound holds after reflections too."""
    mx, my = 0.5 * dt * dt * ax, 0.5 * dt * dt * ay
    mm = mx * mx + my * my
    sm = sx * mx + sy * my
    room = np.maximum(limit * limit - sx * sx - sy * sy, 0.0)
    f = (np.sqrt(sm * sm + mm * room) - sm) / np.maximum(mm, 1e-300)
    f = np.minimum(1.0, f)
    return f * mx, f * my


def neighbourhood(rows, start, nbr, n, rings) -> np.ndarray:
    """The particles ``rows`` (indices) and, ``rings`` times over, every particle j < n their
    CSR lists (start, nbr) hold, sorted: with symmetric lists, the particles whose density a
    move of the rows may change, and (two rings) their neighbours."""
    out = np.unique(rows)
    for _ in range(rings):
        first, count = start[out], start[out + 1] - start[out]
        offset = np.repeat(first - np.cumsum(count) + count, count)
        listed = nbr[offset + np.arange(int(count.sum()))]
        out = np.union1d(out, listed[listed < n])
    return out


def lattice_offsets(reach: float, dx: float) -> np.ndarray:
    """Offsets (k, 2) [m] of the lattice nodes a dx (a, b), (a, b) != 0, within ``reach`` [m]."""
    r = int(np.floor(reach / dx))
    a, b = np.meshgrid(np.arange(-r, r + 1), np.arange(-r, r + 1))
    keep = (a * a + b * b > 0) & (np.hypot(a, b) * dx < reach)
    return np.column_stack([a[keep], b[keep]]).astype(np.float64) * dx


@njit(parallel=True, cache=True)
def open_nodes(owner, qx, qy, x, y, wstart, wseg, seg, visible):
    """For each query node k, set visible[k] = True unless a segment of its owner's near-wall
    list (``wseg[wstart[i]:wstart[i + 1]]``, i = owner[k]) crosses the line from
    (x_i, y_i) to (qx_k, qy_k) [m] (gather over the nodes)."""
    for k in prange(owner.shape[0]):
        i = owner[k]
        visible[k] = True
        for w in range(wstart[i], wstart[i + 1]):
            s = wseg[w]
            if crosses(x[i], y[i], qx[k], qy[k], seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3]):
                visible[k] = False
                break


@njit(parallel=True, cache=True)
def with_neighbours(rows, start, nbr, n, flag, out):
    """out[k] = True if particle i = rows[k] and all its listed neighbours j < n are flagged
    (gather over the rows)."""
    for k in prange(rows.shape[0]):
        i = rows[k]
        ok = flag[i]
        for q in range(start[i], start[i + 1]):
            j = nbr[q]
            if ok and j < n:
                ok = flag[j]
        out[k] = ok


@njit(parallel=True, cache=True)
def still_water(rows, start, nbr, n, u, v, b, d, tol, still):
    """For each row k (particle i = rows[k]), set still[k] = True if i and its listed
    neighbours j < n are at rest (u = v = 0), with seeded depths d_j [m] and bed elevations b_j
    [m] within tol d_i of i's (gather over the rows)."""
    for k in prange(rows.shape[0]):
        i = rows[k]
        ok = u[i] == 0.0 and v[i] == 0.0
        for q in range(start[i], start[i + 1]):
            j = nbr[q]
            if ok and j < n:
                ok = (u[j] == 0.0 and v[j] == 0.0 and abs(d[j] - d[i]) <= tol * d[i]
                      and abs(b[j] - b[i]) <= tol * d[i])
        still[k] = ok


def enclosed_seeds(x, y, reach, candidates, dx, wstart, wseg, seg) -> np.ndarray:
    """The ``candidates`` (indices) whose lattice nodes within reach_i [m] are all water (a
    seed within dx / 2) or hidden behind a wall of their list ``wseg[wstart[i]:wstart[i + 1]]``
    (which must hold every segment within reach_i of i)."""
    tree = cKDTree(np.column_stack([x, y]))
    rings = np.ceil(reach[candidates] / dx)
    keep = []
    for r in np.unique(rings):  # candidates of one ring count share the offsets
        group = candidates[rings == r]
        off = lattice_offsets(r * dx, dx)
        owner = np.repeat(group, off.shape[0])
        ox, oy = np.tile(off[:, 0], group.size), np.tile(off[:, 1], group.size)
        near = np.hypot(ox, oy) < reach[owner]
        owner, qx, qy = owner[near], x[owner[near]] + ox[near], y[owner[near]] + oy[near]
        dist, _ = tree.query(np.column_stack([qx, qy]), distance_upper_bound=0.5 * dx)
        dry = ~np.isfinite(dist)
        visible = np.empty(int(dry.sum()), dtype=np.bool_)
        open_nodes(owner[dry], qx[dry], qy[dry], x, y, wstart, wseg, seg, visible)
        keep.append(group[~np.isin(group, owner[dry][visible])])
    return np.concatenate(keep) if keep else candidates
