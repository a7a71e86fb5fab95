"""Numba kernels of dynamic refinement: particle splitting and coalescing.

Splitting (Vacondio, Rogers & Stansby, IJNMF 69 (2012) 1377-1410; ``docs/method.md`` §6).
A parent p becomes seven daughters k: one at the parent's position and six on a regular
hexagon of radius eps h_p (eps = 0.4) turned so that one vertex points along the parent's
velocity. Masses: m_vertex = f m_p with f = 0.136882287617319 and m_centre = (1 - 6 f) m_p,
so that sum_k m_k = m_p (the published centre fraction 0.178705766141917 loses 5e-7 of the
mass per split). Smoothing length h_k = a h_p with a = 0.9; velocity v_k = v_p, so that
sum_k m_k v_k = m_p v_p exactly.

Coalescing (Vacondio, Rogers, Stansby & Mignosa, Adv. Water Resour. 58 (2013) 10-23; notes
section 5). Two merge candidates a, b that are each other's nearest candidate merge into M with

    m_M = m_a + m_b,   x_M = (m_a x_a + m_b x_b) / m_M,   v_M = (m_a v_a + m_b v_b) / m_M,

which conserves mass and linear momentum. Its smoothing length keeps the SPH density at x_M:
the merged particle's self contribution must equal the two parents' contributions there,

    m_M W(0, h_M) = m_a W(|x_M - x_a|, h_a) + m_b W(|x_M - x_b|, h_b) = S.

For the 2-D cubic spline W(0, h) = sigma / h^2 with sigma = 10 / (7 pi), hence

    h_M = sqrt(sigma m_M / S) = sqrt(10 m_M / (7 pi S)).

(PySPH's ``FindMergeable`` codes sqrt((7 pi / 10) m_M / S): the inverse constant, which makes
h_M too large by the factor 7 pi / 10 ~ 2.2. Not used here.)

The condition keeps only the two parents' share of the density at x_M; the other neighbours
are then seen with h_M instead of h_a. When the parents are ordinary lattice-like particles
(r_ab ~ spacing, h ~ 1.3 spacing) h_M comes out near 1.1 h_a, well below the lattice value
kappa sqrt(A_M) ~ 1.41 h_a of the merged area A_M = m_M / rho_M, and the merged particle then
solves to a depth 5 - 10 % above the water around it (measured, kappa = 1.3). h_M is therefore
floored at kappa sqrt(m_M / rho_M), which brings that error to about 1 - 2 %. For
over-smoothed daughters of a split (h ~ 2.4 kappa sqrt(A)), r_ab << h and the condition
gives h_M ~ h_a above the floor: it is used as is.

Units: x, y, h [m]; u, v [m/s]; m [kg]; rho [kg m-2]; d [m].
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.sph.kernels import SIGMA_2D, w_cubic
from floodsph.walls.geometry import crosses

VERTEX_FRACTION = 0.136882287617319
"""Mass of each of the six hexagon daughters over the parent's mass [V12-split]."""
CENTRE_FRACTION = 1.0 - 6.0 * VERTEX_FRACTION
"""Mass of the centre daughter over the parent's mass, chosen so that mass is exact."""
DAUGHTERS = 7
"""Daughters per split: the centre one (index 0) and the hexagon (1..6)."""
EPS = 0.4
"""Hexagon radius over the parent's smoothing length [V12-split]."""
H_FACTOR = 0.9
"""Daughter smoothing length over the parent's [V12-split]."""
STILL_SPEED = 1e-3
"""Speed [m/s] below which the hexagon is not turned along the velocity (PySPH)."""


@njit(parallel=True, cache=True)
def daughters(xp, yp, up, vp, mp, hp, eps, still, x, y, m):
    """Positions and masses of the 7 daughters of each parent (gather: parent k writes 7k..7k+6).

    Parameters
    ----------
    xp, yp, up, vp, mp, hp : float64 arrays (n_parents,)
        Parent positions [m], velocities [m/s], masses [kg], smoothing lengths [m].
    eps : float
        Hexagon radius over h_p (0.4).
    still : float
        Speed [m/s] below which the hexagon is not turned along the velocity (1e-3).
    x, y, m : float64 arrays (7 n_parents,)
        Output daughter positions [m] and masses [kg]; daughter 0 of each parent is the centre.
    """
    for k in prange(xp.shape[0]):
        speed = math.hypot(up[k], vp[k])
        theta = math.atan2(vp[k], up[k]) if speed > still else 0.0
        radius = eps * hp[k]
        base = DAUGHTERS * k
        x[base] = xp[k]
        y[base] = yp[k]
        m[base] = CENTRE_FRACTION * mp[k]
        for j in range(6):
            angle = theta + j * math.pi / 3.0
            x[base + 1 + j] = xp[k] + radius * math.cos(angle)
            y[base + 1 + j] = yp[k] + radius * math.sin(angle)
            m[base + 1 + j] = VERTEX_FRACTION * mp[k]


@njit(parallel=True, cache=True)
def daughters_clear(xp, yp, x, y, wstart, wseg, seg, out):
    """out[k] = True when no wall segment separates parent k from any of its 7 daughters.

    ``(wstart, wseg)`` lists the segments near each parent, within its hexagon's radius
    (``floodsph.walls.index.WallIndex.near_lists``); a segment that crosses the line from the
    parent to a daughter is among them.
    """
    for k in prange(xp.shape[0]):
        base = DAUGHTERS * k
        ok = True
        for w in range(wstart[k], wstart[k + 1]):
            s = wseg[w]
            for j in range(1, DAUGHTERS):
                if crosses(xp[k], yp[k], x[base + j], y[base + j], seg[s, 0], seg[s, 1],
                           seg[s, 2], seg[s, 3]):
                    ok = False
        out[k] = ok


@njit(parallel=True, cache=True)
def nearest_of(rows, x, y, nstart, nbr, partner, out):
    """out[i] = the nearest j with ``partner[j]`` in the CSR list of each i in ``rows``, else
    -1 (ties to the lower index, so the result is deterministic).

    Pairing mutual nearest candidates (``partner`` the candidates, not particles of any kind)
    lets a small particle beside a large one still find a partner, and stays conflict-free.
    """
    for k in prange(rows.shape[0]):
        i = rows[k]
        best = -1
        best_r2 = np.inf
        for q in range(nstart[i], nstart[i + 1]):
            j = nbr[q]
            if not partner[j] or j == i:
                continue
            dx = x[j] - x[i]
            dy = y[j] - y[i]
            r2 = dx * dx + dy * dy
            if r2 < best_r2 or (r2 == best_r2 and j < best):
                best = j
                best_r2 = r2
        out[i] = best


@njit(cache=True)
def merged_h(m_a, m_b, r_a, r_b, h_a, h_b):
    """Smoothing length [m] of the merged particle from m_M W(0, h_M) = S (module docstring).

    r_a, r_b are the distances [m] from the merged position to the parents. Returns 0 when S
    is not positive (the merged position lies outside both parents' supports).
    """
    s = m_a * w_cubic(r_a, h_a) + m_b * w_cubic(r_b, h_b)
    if s <= 0.0:
        return 0.0
    return math.sqrt(SIGMA_2D * (m_a + m_b) / s)


@njit(parallel=True, cache=True)
def merge_pairs(a, b, x, y, u, v, m, rho, h, kappa, out):
    """State of the particle merged from each pair (a[k], b[k]) (gather over pairs).

    ``out[k]`` receives x_M, y_M [m], u_M, v_M [m/s], m_M [kg], rho_M [kg m-2] and h_M [m]
    (module docstring). rho_M is the mass-weighted mean of the parents' densities, the initial
    guess of the Newton-Raphson solve that follows. h_M is :func:`merged_h`, but not less than
    kappa sqrt(m_M / rho_M), the smoothing length of a lattice particle of the merged area
    (module docstring).
    """
    for k in prange(a.shape[0]):
        i = a[k]
        j = b[k]
        mm = m[i] + m[j]
        wa = m[i] / mm
        wb = m[j] / mm
        xm = wa * x[i] + wb * x[j]
        ym = wa * y[i] + wb * y[j]
        out[k, 0] = xm
        out[k, 1] = ym
        out[k, 2] = (m[i] * u[i] + m[j] * u[j]) / mm
        out[k, 3] = (m[i] * v[i] + m[j] * v[j]) / mm
        out[k, 4] = mm
        rm = wa * rho[i] + wb * rho[j]
        out[k, 5] = rm
        hm = merged_h(m[i], m[j], math.hypot(xm - x[i], ym - y[i]),
                      math.hypot(xm - x[j], ym - y[j]), h[i], h[j])
        out[k, 6] = max(hm, kappa * math.sqrt(mm / rm))

