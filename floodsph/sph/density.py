"""Depth from SPH density: the Newton-Raphson solve of density and smoothing length.

Equations (Vacondio et al., Adv. Water Resour. 58 (2013) 10-23; Rodriguez-Paz & Bonet,
Comput. Struct. 83 (2005) 1396-1410; method notes sections 1.4-1.5):

    rho_i = sum_j m_j W(r_ij, h_i)                     (1)  gather summation, self included
    h_i   = h0_i (rho0_i / rho_i)^(1/2)                (2)  d_m = 2
    R_i   = rho_i - sum_j m_j W(r_ij, h_i(rho_i))           residual
    alpha_i = - sum_j m_j r_ij dW/dr(r_ij, h_i)             (= 2 rho_i on a regular lattice)
    rho_i <- rho_i [1 - 2 R_i / (2 R_i + alpha_i)]     (3)  Newton update

Units: rho [kg m-2] (= RHO_WATER * depth), h [m], m [kg], alpha [kg m-2].

Iteration stops per particle when |R_i| / rho_i < tol. A particle whose update is not positive
and finite falls back to the plain summation at its current h (SWE-SPHysics safeguard);
h is kept within [h0 / h_ratio, h0 * h_ratio] so that an isolated particle, whose self
contribution alone can never match its density, cannot grow without bound.
Mirror images across walls (``floodsph.sph.walls``) are part of the summation.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.sph.kernels import dwdr_cubic, w_cubic
from floodsph.sph.walls import blocked, corner_image, wall_image


@njit(inline="always", cache=True)
def _add_pair(rx, ry, mj, hi, acc):
    r = math.sqrt(rx * rx + ry * ry)
    acc[0] += mj * w_cubic(r, hi)
    acc[1] -= mj * r * dwdr_cubic(r, hi)


@njit(parallel=True, cache=True)
def summation(idx, x, y, m, h, nstart, nbr, wstart, wseg, seg, out_sum, out_alpha):
    """Density summation (1) and alpha at the particles listed in ``idx``, at their current h.

    Writes out_sum[i] = sum_j m_j W(r_ij, h_i) and out_alpha[i] for i in idx.
    """
    for k in prange(idx.shape[0]):
        i = idx[k]
        xi = x[i]
        yi = y[i]
        hi = h[i]
        acc = np.zeros(2)
        acc[0] = m[i] * w_cubic(0.0, hi)
        for q in range(nstart[i], nstart[i + 1]):
            j = nbr[q]
            if wstart[i + 1] > wstart[i] and blocked(xi, yi, x[j], y[j], wstart, wseg, seg, i):
                continue
            _add_pair(xi - x[j], yi - y[j], m[j], hi, acc)
        for w in range(wstart[i], wstart[i + 1]):
            s = wseg[w]
            _add_image(i, i, x, y, m, hi, seg, s, acc)
            for q in range(nstart[i], nstart[i + 1]):
                j = nbr[q]
                if blocked(xi, yi, x[j], y[j], wstart, wseg, seg, i):
                    continue
                _add_image(i, j, x, y, m, hi, seg, s, acc)
            for w2 in range(w + 1, wstart[i + 1]):
                s2 = wseg[w2]
                _add_corner(i, i, x, y, m, hi, seg, s, s2, acc)
                for q in range(nstart[i], nstart[i + 1]):
                    j = nbr[q]
                    if blocked(xi, yi, x[j], y[j], wstart, wseg, seg, i):
                        continue
                    _add_corner(i, j, x, y, m, hi, seg, s, s2, acc)
        out_sum[i] = acc[0]
        out_alpha[i] = acc[1]


@njit(inline="always", cache=True)
def _add_image(i, j, x, y, m, hi, seg, s, acc):
    xm, ym, ok = wall_image(x[i], y[i], x[j], y[j], seg, s)
    if ok:
        _add_pair(x[i] - xm, y[i] - ym, m[j], hi, acc)


@njit(inline="always", cache=True)
def _add_corner(i, j, x, y, m, hi, seg, s1, s2, acc):
    xc, yc, ok = corner_image(x[j], y[j], seg, s1, s2)
    if ok:
        _add_pair(x[i] - xc, y[i] - yc, m[j], hi, acc)


@njit(parallel=True, cache=True)
def newton_update(idx, rho, h, h0, rho0, s, alpha, tol, h_ratio, converged):
    """One Newton step (3) for the particles in ``idx``; flags converged ones.

    ``s`` and ``alpha`` are the summation and correction term at the current (rho, h).
    A particle already within ``tol`` keeps its (rho, h) and is flagged converged.
    """
    for k in prange(idx.shape[0]):
        i = idx[k]
        res = rho[i] - s[i]
        if abs(res) < tol * rho[i]:
            converged[i] = True
            continue
        new = rho[i] * (1.0 - 2.0 * res / (2.0 * res + alpha[i]))
        if not (new > 0.0) or not math.isfinite(new) or alpha[i] <= 0.0:
            new = s[i]
        h_new = h0[i] * math.sqrt(rho0[i] / new)
        h_new = min(max(h_new, h0[i] / h_ratio), h0[i] * h_ratio)
        rho[i] = new
        h[i] = h_new


@njit(parallel=True, cache=True)
def fallback(idx, rho, s):
    """Unconverged particles take the plain summation at their current h."""
    for k in prange(idx.shape[0]):
        i = idx[k]
        rho[i] = s[i]


@njit(parallel=True, cache=True)
def predict(rho, h, divv, dt):
    """Continuity-based initial guess: rho (1 - dt div v), h (1 + dt div v / 2)."""
    for i in prange(rho.shape[0]):
        f = max(1.0 - dt * divv[i], 0.5)
        rho[i] *= f
        h[i] *= 1.0 / math.sqrt(f)


def solve_density(p, nl, wstart, wseg, seg, tol=1e-3, max_iter=20, h_ratio=10.0, scratch=None):
    """Solve (1)-(3) for all particles of ``p`` in place; return (iterations, unconverged).

    ``p`` is the ParticleSet (its rho and h hold the initial guess); ``nl`` the NeighbourList.
    On return every particle has rho, h and alpha consistent with its neighbours to ``tol``,
    except the returned number of unconverged ones, which take the plain summation.
    """
    n = p.n
    s = np.empty(n) if scratch is None else scratch[0][:n]
    alpha = p.alpha
    converged = np.zeros(n, dtype=np.bool_)
    idx = np.arange(n, dtype=np.int64)
    iters = 0
    while idx.size and iters < max_iter:
        summation(idx, p.x, p.y, p.m, p.h, nl.start, nl.nbr, wstart, wseg, seg, s, alpha)
        newton_update(idx, p.rho, p.h, p.h0, p.rho0, s, alpha, tol, h_ratio, converged)
        idx = idx[~converged[idx]]
        iters += 1
    if idx.size:
        summation(idx, p.x, p.y, p.m, p.h, nl.start, nl.nbr, wstart, wseg, seg, s, alpha)
        fallback(idx, p.rho, s)
    return iters, int(idx.size)
