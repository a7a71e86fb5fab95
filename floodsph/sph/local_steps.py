"""Local time stepping: each particle steps at its own power-of-two multiple of the finest step.

With one global step, dt = cfl min_i h_i / (|v_i| + c_i) (``docs/method.md`` §5) is set by the
fastest, finest particle, and every particle pays for it: at a breach the water is fast and
deep, while most of the flood plain is slow and thin. Here a big step Delta = 2^K dt_f is cut
into 2^K substeps of the finest step dt_f, and particle i advances with its own step
tau_i = s_i dt_f, where the stride s_i is the largest power of two with

    s_i dt_f <= dt_i = cfl h_i / (|v_i| + c_i),   1 <= s_i <= 2^K,

so that its own CFL condition holds (the block time steps of Aarseth, Gravitational N-Body
Simulations, 2003, and of Springel's GADGET-2, MNRAS 364 (2005) 1105). A particle is
updated (density, forces, kicks) only at the ends of its own steps; strides divide 2^K, so
every particle's last step ends with the big step. There all particles are synchronised,
and refinement, re-sorting and output happen. Between its updates a particle drifts with its
half-step velocity at every substep, and its density and h follow the continuity guess
rho (1 - dt div v) (the Newton-Raphson initial guess of ``floodsph.sph.density.predict``), so
that its neighbours see it move and thin or thicken.

A particle's stride is at most twice the smallest stride of its neighbours (the limiter of
Saitoh & Makino, ApJ 697 (2009) L99, with their factor 4 tightened to 2), so that a slow
particle next to a fast one is updated often enough to feel a wave arriving within a big step.
Particles in an open boundary's zone (an inflow's buffer, open edges) take stride 1.

K = ``Numerics.step_levels`` = 3 by default: EA test 4 at 5 m took 680, 602 and
624 s with K = 2, 3 and 4 on two cores (commit `91a6063`, before the implicit friction;
with K = 3, 609 s at `e2dbceb`, 604 s at `cf44f63` and 570 s at `5006322`), with the same
maps (CSI 0.993, 0.992 and 0.990 against the global step); a larger K saves synchronisations
but adds updates.

Mass is exact (particles keep their mass); linear momentum is conserved only to the order of
the step, because a pair's forces act on its two particles at their own times.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.sph.time_step import friction_factor


@njit(parallel=True, cache=True)
def strides(u, v, rho, h, cfl, dt_fine, max_stride, out):
    """Stride s_i = largest power of two <= min(max_stride, dt_i / dt_fine), at least 1.

    dt_i = cfl h_i / (|v_i| + c_i) with c_i = sqrt(g d_i) [s], the particle's own CFL step
    (:func:`floodsph.sph.time_step.stable_dt` is its minimum); ``dt_fine`` [s] the finest step.
    """
    for i in prange(u.shape[0]):
        w = math.sqrt(u[i] * u[i] + v[i] * v[i]) + math.sqrt(GRAVITY * rho[i] / RHO_WATER)
        s = 1
        if w > 0.0:
            ratio = cfl * h[i] / w / dt_fine
            while 2 * s <= max_stride and 2 * s <= ratio:
                s *= 2
        else:
            s = max_stride
        out[i] = s


@njit(parallel=True, cache=True)
def limit_strides(stride, nstart, nbr, n, out):
    """out_i = min(s_i, 2 min_j s_j) over the listed neighbours j < n of particle i < n.

    Gather form: each particle reads its neighbours' strides and writes its own.
    Neighbours with index >= n (boundary ghosts dropped after the list was built) are skipped.
    """
    for i in prange(n):
        s = stride[i]
        for q in range(nstart[i], nstart[i + 1]):
            j = nbr[q]
            if j < n:
                s = min(s, 2 * stride[j])
        out[i] = s


@njit(parallel=True, cache=True)
def kick(rows, stride, half_dt, u, v, ax, ay):
    """Half kick v_i <- v_i + (s_i half_dt) a_i of the particles ``rows`` (in place).

    ``half_dt`` is half the finest step [s]; a particle's half step is s_i half_dt.
    """
    for k in prange(rows.shape[0]):
        i = rows[k]
        dt = stride[i] * half_dt
        u[i] += dt * ax[i]
        v[i] += dt * ay[i]


@njit(parallel=True, cache=True)
def close_steps(rows, stride, dt_fine, u, v, ax, ay, rho, manning, d_floor):
    """End the own steps of the particles ``rows``: the half kick v += (s_i dt_f / 2) a_i, then
    implicit Manning friction over s_i dt_f (:func:`floodsph.sph.time_step.friction_factor`;
    n <= 0 means no friction), as steps 5 of ``floodsph.model.flood_model`` with each particle's
    own step."""
    for k in prange(rows.shape[0]):
        i = rows[k]
        dt = stride[i] * dt_fine
        u[i] += 0.5 * dt * ax[i]
        v[i] += 0.5 * dt * ay[i]
        if manning[i] > 0.0:
            f = friction_factor(u[i], v[i], rho[i], manning[i], dt, d_floor)
            u[i] *= f
            v[i] *= f


@njit(cache=True)
def step_ends(stride, k):
    """The particles one of whose own steps ends (and the next begins) at finest step k of
    the big step, k % s_i == 0 (strides divide the big step, so k = 0 and k = 2^K hold all)."""
    count = 0
    for i in range(stride.shape[0]):
        count += k % stride[i] == 0
    out = np.empty(count, dtype=np.int64)
    c = 0
    for i in range(stride.shape[0]):
        if k % stride[i] == 0:
            out[c] = i
            c += 1
    return out
