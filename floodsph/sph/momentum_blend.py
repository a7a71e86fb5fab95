"""The balanced momentum's blend with the variational force, and the release of still water.

Under ``numerics.momentum = "balanced"`` (``floodsph.sph.level_momentum``) a particle's
acceleration is

    a = lambda a_variational + (1 - lambda) a_balanced,
    lambda = s^2 (3 - 2 s),   s = min(|v| / BLEND_SPEED, 1)              (smoothstep, [-])

(the velocity divergence alike), so that a lake at rest takes the balanced form alone and a
flood wave the variational one. Before the forces, still water held by its banks
(``floodsph.sph.level_offsets``) whose level has left its seeded level by ``HOLD_LEVEL`` is
banked, and held or banked water that moves at ``EDGE_SPEED`` is released.

These are per-particle kernels over the rows of a force evaluation (gather form), in place
of array expressions that took a serial pass each: the same arithmetic, so the same numbers
to the last bit. Units: speeds [m s-1], levels [m], accelerations [m s-2].
"""

from __future__ import annotations

import math

from numba import njit, prange

from floodsph.sph.level_momentum import BLEND_SPEED, EDGE_SPEED, HOLD_LEVEL
from floodsph.sph.level_offsets import BANKED, HELD, RELEASED


@njit(inline="always", cache=True)
def variational_weight(u, v):
    """lambda [-] of the module docstring for the velocity (u, v) [m s-1]."""
    s = min(math.hypot(u, v) / BLEND_SPEED, 1.0)
    return s * s * (3.0 - 2.0 * s)


@njit(parallel=True, cache=True)
def variational_weights(rows, u, v, weight):
    """``weight[k]`` = lambda of particle ``rows[k]`` (:func:`variational_weight`)."""
    for k in prange(rows.shape[0]):
        i = rows[k]
        weight[k] = variational_weight(u[i], v[i])


@njit(parallel=True, cache=True)
def release(rows, u, v, eta, eta_seed, bank_held):
    """Among the particles ``rows``: a ``HELD`` one whose level ``eta`` [m] departs from its
    seeded level ``eta_seed`` by ``HOLD_LEVEL`` or more becomes ``BANKED``, and a ``HELD``
    or ``BANKED`` one moving at ``EDGE_SPEED`` or faster becomes ``RELEASED`` (both tests on
    its state as it comes)."""
    for k in prange(rows.shape[0]):
        i = rows[k]
        state = bank_held[i]
        if state == HELD and abs(eta[i] - eta_seed[i]) >= HOLD_LEVEL:
            bank_held[i] = BANKED
        if (state == HELD or state == BANKED) and u[i] ** 2 + v[i] ** 2 >= EDGE_SPEED ** 2:
            bank_held[i] = RELEASED


@njit(parallel=True, cache=True)
def blend(moving, weight, ax_var, ay_var, divv_var, ax, ay, divv):
    """a_i <- lambda_i a_variational,i + (1 - lambda_i) a_i for the particles ``moving[k]``
    of weight ``weight[k]`` = lambda > 0, whose variational accelerations and divergence are
    ``ax_var[k]``, ``ay_var[k]``, ``divv_var[k]`` and whose balanced ones are in (ax, ay,
    divv) (they are the variational ones where lambda = 1)."""
    for k in prange(moving.shape[0]):
        i = moving[k]
        w = weight[k]
        ax[i] = w * ax_var[k] + (1.0 - w) * ax[i]
        ay[i] = w * ay_var[k] + (1.0 - w) * ay[i]
        divv[i] = w * divv_var[k] + (1.0 - w) * divv[i]
