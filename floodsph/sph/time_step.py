"""The leap-frog's kicks, implicit Manning friction and the CFL time step (pointwise kernels).

Friction (``docs/method.md`` §3.6), implicit Manning, :func:`friction_factor`:

    v  <- 2 v / (1 + sqrt(1 + 4 beta)),  beta = dt g n^2 |v| / max(d, d_floor)^(4/3)

Time step (``docs/method.md`` §5): dt = cfl min_i h_i / (|v_i| + c_i), c_i = sqrt(g d_i).

Units: velocities [m s-1], accelerations [m s-2], rho [kg m-2], h [m], dt [s].
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.constants import GRAVITY, RHO_WATER


@njit(inline="always", cache=True)
def friction_factor(u, v, rho, n, dt, d_floor):
    """Implicit Manning factor f = 2 / (1 + sqrt(1 + 4 beta)) [-] of one particle, with
    beta = dt g n^2 |v| / max(d, d_floor)^(4/3) (velocity v [m s-1] after the closing kick,
    rho [kg m-2], n [s m-1/3], dt [s], floor [m]).

    f v is the exact solution of the backward-Euler friction step
    v_new = v - dt g n^2 |v_new| v_new / d^(4/3): v_new is parallel to v, and its speed s
    solves s + (beta / |v|) s^2 = |v|. A particle kicked by a constant acceleration a then
    keeps Manning's terminal speed, a = g n^2 |v|^2 / d^(4/3), at any dt. The point-implicit
    factor 1 / (1 + beta) of the reference codes (``docs/method.md`` §3.6) settles at
    u_e (sqrt(beta_e^2 + 4) - beta_e) / 2 with beta_e = dt g n^2 u_e / d^(4/3): 5 % slow at
    beta_e = 0.1, which the long steps of slow, thin particles under local time stepping reach
    on a flood plain. Like it, f lies in (0, 1], so friction cannot reverse the flow, for any dt.
    """
    d = max(rho / RHO_WATER, d_floor)
    speed = math.sqrt(u * u + v * v)
    beta = dt * GRAVITY * n * n * speed / d ** (4.0 / 3.0)
    return 2.0 / (1.0 + math.sqrt(1.0 + 4.0 * beta))


@njit(inline="always", cache=True)
def _dt_bound(u, v, rho, h):
    """h / (|v| + c) [s] of one particle (c = sqrt(g d)), inf if it is still and dry."""
    c = math.sqrt(GRAVITY * rho / RHO_WATER)
    w = math.sqrt(u * u + v * v) + c
    return h / w if w > 0.0 else np.inf


@njit(parallel=True, cache=True)
def stable_dt(u, v, rho, h, cfl):
    """CFL time step dt = cfl min_i h_i / (|v_i| + c_i), c_i = sqrt(g d_i) [s]."""
    best = np.inf
    for i in prange(u.shape[0]):
        best = min(best, _dt_bound(u[i], v[i], rho[i], h[i]))
    return cfl * best


@njit(parallel=True, cache=True)
def kick(u, v, ax, ay, half):
    """Half kick v <- v + a dt / 2 of every particle (``half`` = dt / 2 [s])."""
    for i in prange(u.shape[0]):
        u[i] += half * ax[i]
        v[i] += half * ay[i]


@njit(parallel=True, cache=True)
def close_step(u, v, ax, ay, half, rho, h, manning, dt, d_floor, cfl):
    """The end of a step in one pass: the closing half kick (:func:`kick`), implicit Manning
    friction over dt (v <- f v, :func:`friction_factor`; none where n <= 0), and the next CFL
    step of :func:`stable_dt`, which is returned [s]."""
    best = np.inf
    for i in prange(u.shape[0]):
        u[i] += half * ax[i]
        v[i] += half * ay[i]
        n = manning[i]
        if n > 0.0:
            k = friction_factor(u[i], v[i], rho[i], n, dt, d_floor)
            u[i] *= k
            v[i] *= k
        best = min(best, _dt_bound(u[i], v[i], rho[i], h[i]))
    return cfl * best
