"""The free-surface level of the balanced momentum, and its offsets.

The balanced momentum (``floodsph.sph.level_momentum``) pushes water down differences of the
level eta_i = d_i + b(x_i) + o_i, with d_i = rho_i / rho_w the summation depth and b the
bilinear bed at the particle (``floodsph.sph.bed``). Seeded still water is level, but its
summation depth is the depth smoothed over the kernel's support, so on a sloping bed d_i + b_i
departs from the seeded level L_i by up to metres. The offset

    o_i = L_i - b(x_i) - rho_i / rho_w            (:func:`match_offsets`, once at set-up)

makes every particle seeded at rest carry its seeded level exactly, and a still lake an exact
equilibrium. L_i is the level of the particle's lattice cell, the area mean of d + z over its
wet DEM cells (``floodsph.inputs.initial_water.seed_particles``), and b the solver's own bed at
the particle. The offset belongs to the water at rest; once it moves it fades over the
distance travelled, o_i <- o_i exp(-|v_i| dt / h_i) (:func:`decay_offsets`), so that moving
water is pushed by its own depth's differences.

Still water held by its banks. A particle is a marker in the water: in a lake at rest the
level it reports must not change when it drifts a little, but the summation depth of a particle
between deep and shallow neighbours changes with where it stands among them, and a fading
offset turns speed into a change of level. Either drove a disturbed lake unstable next to its
banks. So while a particle is still water that its banks hold (``bank_held`` = ``HELD``, set at
set-up, ``floodsph.sph.level_momentum``):

* its depth follows continuity alone, d <- d (1 - dt div v) (the density solve leaves it),
  so that it rises under compression and falls under expansion;
* its offset does not fade;
* its velocity is damped, and it is tethered to where it was seeded (:func:`hold_still`).

When its level departs from its seeded level it is ``BANKED``: no longer damped or tethered,
it keeps the rest. When it moves (``RELEASED``), the density solve takes it again, and its
offset takes the difference between its continuity depth and its summation depth, so that
its level does not jump (:func:`release`); from then on the offset fades as for any moving
water, and never takes the level below the bed (:func:`floor_offsets`). (Released to the
summation depth by a change of level alone, a particle pressed against Malpasset's dam wall,
whose summation depth is 54 m where the water is 35 m deep, jumped between the solve's roots
and was thrown at 10 m/s.)
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.constants import RHO_WATER
from floodsph.sph.bed import elevation_at

FREE = 0
"""``bank_held`` of water that is not held by its banks (moving, or with a free edge)."""
HELD = 1
"""``bank_held`` of still water held by its banks (module docstring)."""
BANKED = 2
"""``bank_held`` of water released from ``HELD`` by a change of its level but still slower
than ``floodsph.sph.level_momentum.EDGE_SPEED``: it keeps its continuity depth and offset,
and its banks are not tested again, but it is no longer damped or tethered (module
docstring)."""
RELEASED = -1
"""``bank_held`` of water that left ``HELD`` in the last force evaluation, whose offset the
next density solve matches (:func:`release`)."""


@njit(parallel=True, cache=True)
def levels(x, y, rho, offset, elevation, tdx, tdy, eta):
    """eta_i = rho_i / rho_w + b(x_i) + o_i [m] of every particle, b the bilinear sample of the
    terrain's node grid ``elevation`` of spacing (tdx, tdy) [m]."""
    ny, nx = elevation.shape
    for i in prange(x.shape[0]):
        b = elevation_at(x[i], y[i], tdx, tdy, elevation, nx, ny)
        eta[i] = rho[i] / RHO_WATER + b + offset[i]


@njit(parallel=True, cache=True)
def decay_offsets(u, v, h, dt, bank_held, offset):
    """o_i <- o_i exp(-|v_i| dt / h_i): the offset fades over the distance travelled, in units of
    the smoothing length, except for the ``HELD`` and ``BANKED`` particles of ``bank_held``
    (module docstring)."""
    for i in prange(offset.shape[0]):
        if offset[i] != 0.0 and bank_held[i] != HELD and bank_held[i] != BANKED:
            offset[i] *= math.exp(-math.sqrt(u[i] * u[i] + v[i] * v[i]) * dt / h[i])


@njit(parallel=True, cache=True)
def hold_still(u, v, x, y, x_seed, y_seed, bank_held, dt, hold_time, stiffness):
    """The ``HELD`` particles' velocities [m s-1] over a step dt [s]: tethered to where they were
    at set-up (x_seed, y_seed) [m] by a spring of ``stiffness`` [s-2] and damped over
    ``hold_time`` [s], v <- (v - stiffness (x - x_seed) dt) exp(-dt / hold_time)
    (``floodsph.sph.level_momentum``, still water held by its banks)."""
    factor = math.exp(-dt / hold_time)
    for i in prange(u.shape[0]):
        if bank_held[i] == HELD:
            u[i] = (u[i] - stiffness * (x[i] - x_seed[i]) * dt) * factor
            v[i] = (v[i] - stiffness * (y[i] - y_seed[i]) * dt) * factor


@njit(parallel=True, cache=True)
def floor_offsets(rho, bank_held, offset):
    """o_i <- max(o_i, -rho_i / rho_w) [m] for the particles neither ``HELD`` nor ``BANKED``: the
    level d + b + o of moving water never falls below the bed. A negative offset carried by
    water that ran from a deep lake onto a shallow front would otherwise outlast the depth it
    corrects, and leave a particle with mass a level below the ground (module docstring)."""
    for i in prange(offset.shape[0]):
        if bank_held[i] != HELD and bank_held[i] != BANKED:
            offset[i] = max(offset[i], -rho[i] / RHO_WATER)


def release(bank_held: np.ndarray, rho_continuity: np.ndarray, rho: np.ndarray,
            offset: np.ndarray) -> None:
    """o <- o + (rho_continuity - rho) / rho_w [m] for the ``RELEASED`` particles, whose depth
    the density solve took from continuity (``rho_continuity``) to summation (``rho``) [kg
    m-2]; they become ``FREE`` (module docstring)."""
    released = bank_held == RELEASED
    offset[released] += (rho_continuity[released] - rho[released]) / RHO_WATER
    bank_held[released] = FREE


def match_offsets(eta_seed: np.ndarray, rho: np.ndarray, bed: np.ndarray,
                  offset: np.ndarray) -> int:
    """o = L - b - rho / rho_w for the particles seeded at rest (finite ``eta_seed`` = L [m]),
    0 for the others, into ``offset`` [m]; ``bed`` is b at the particles [m]. Returns the
    number of particles matched."""
    seeded = np.isfinite(eta_seed)
    offset[:] = np.where(seeded, eta_seed - bed - rho / RHO_WATER, 0.0)
    return int(seeded.sum())
