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
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.constants import RHO_WATER
from floodsph.sph.bed import elevation_at


@njit(parallel=True, cache=True)
def levels(x, y, rho, offset, elevation, tdx, tdy, eta):
    """eta_i = rho_i / rho_w + b(x_i) + o_i [m] of every particle, b the bilinear sample of the
    terrain's node grid ``elevation`` of spacing (tdx, tdy) [m]."""
    ny, nx = elevation.shape
    for i in prange(x.shape[0]):
        b = elevation_at(x[i], y[i], tdx, tdy, elevation, nx, ny)
        eta[i] = rho[i] / RHO_WATER + b + offset[i]


@njit(parallel=True, cache=True)
def decay_offsets(u, v, h, dt, offset):
    """o_i <- o_i exp(-|v_i| dt / h_i): the offset fades over the distance travelled, in units of
    the smoothing length (module docstring)."""
    for i in prange(offset.shape[0]):
        if offset[i] != 0.0:
            offset[i] *= math.exp(-math.sqrt(u[i] * u[i] + v[i] * v[i]) * dt / h[i])


def match_offsets(eta_seed: np.ndarray, rho: np.ndarray, bed: np.ndarray,
                  offset: np.ndarray) -> int:
    """o = L - b - rho / rho_w for the particles seeded at rest (finite ``eta_seed`` = L [m]),
    0 for the others, into ``offset`` [m]; ``bed`` is b at the particles [m]. Returns the
    number of particles matched."""
    seeded = np.isfinite(eta_seed)
    offset[:] = np.where(seeded, eta_seed - bed - rho / RHO_WATER, 0.0)
    return int(seeded.sum())
