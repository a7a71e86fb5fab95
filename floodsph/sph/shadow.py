"""The part of a particle's kernel support that walls hide: a boundary integral.

A wall hides from particle i the points beyond it along i's sight lines. The fraction of i's
kernel that falls there, in polar coordinates (r, theta) about x_i, is

    S_i(h) = sum over the directions theta that meet a wall within 2h of
             integral B(r_w(theta) / h) d theta,                          (1)
    B(q)   = integral_q^2 w(q') q' dq'      (W(r, h) = w(r/h) / h^2),

with r_w(theta) the distance from x_i to the first wall along theta. For the 2-D cubic spline
(``floodsph.sph.kernels``, w = sigma f, sigma = 10 / (7 pi)), with T = 2 - q,

    B(q) = sigma [0.075 + 0.275 - q^2 / 2 + 0.375 q^4 - 0.15 q^5]    0 <= q <= 1
         = sigma 0.25 (T^4 / 2 - T^5 / 5)                              1 <  q <= 2,

and 2 pi B(0) = 1. Along a straight segment at distance delta from x_i, whose foot lies in the
direction theta_n, r_w = delta / cos(theta - theta_n), and the segment counts only where
|theta - theta_n| < acos(delta / 2h). Each segment covers an interval of directions; where
intervals overlap (a segment seen behind another) the nearer segment is taken, on each
sub-interval between the intervals' ends, and (1) is integrated there by Gauss-Legendre
quadrature (B is twice continuously differentiable). The ends of the sub-intervals move
continuously with x_i and h, so S_i does too: nothing switches as a particle passes a vertex or
as a wall turns against the lattice. This is the 2-D kernel-support integral of the
semi-analytical wall boundary conditions (Ferrand, Laurence, Rogers, Violeau & Kassiotis,
IJNMF 71 (2013) 446-472; Mayrhofer, Rogers, Violeau & Ferrand, Comput. Phys. Commun. 184
(2013) 2515-2527), here as an angular integral, which handles thin walls and corners alike.

gamma_i = 1 - S_i is the part of the support that holds water, and the SPH depth of a particle
near a wall is corrected by it (``floodsph.sph.density``).

Units: x, y, h, r [m]; S, gamma [-].
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.sph.kernels import SIGMA_2D

GAUSS_X = np.array([-0.9324695142031521, -0.6612093864662645, -0.2386191860831969,
                    0.2386191860831969, 0.6612093864662645, 0.9324695142031521])
"""Gauss-Legendre nodes of order 6 on [-1, 1] (Abramowitz & Stegun, table 25.4)."""
GAUSS_W = np.array([0.1713244923791704, 0.3607615730481386, 0.4679139345726910,
                    0.4679139345726910, 0.3607615730481386, 0.1713244923791704])
"""Gauss-Legendre weights of order 6."""
PIECES = 4
"""Equal parts of each smooth piece of (1), each integrated by ``GAUSS_X`` (B(delta / (h cos))
rises steeply towards the ends of a near wall's interval)."""
MAX_INTERVALS = 32
"""Most segments that may cover a particle's support (more are ignored: never met)."""
TWO_PI = 2.0 * math.pi


@njit(inline="always", cache=True)
def tail(q):
    """B(q) of (1) [-]: the kernel's weight beyond radius q h, per radian."""
    if q >= 2.0:
        return 0.0
    if q <= 1.0:
        q2 = q * q
        return SIGMA_2D * (0.35 - 0.5 * q2 + 0.375 * q2 * q2 - 0.15 * q2 * q2 * q)
    t = 2.0 - q
    t4 = t * t * t * t
    return SIGMA_2D * 0.25 * (0.5 * t4 - 0.2 * t4 * t)


@njit(inline="always", cache=True)
def _wrap(a):
    """An angle [rad] in [0, 2 pi)."""
    a = a % TWO_PI
    return a + TWO_PI if a < 0.0 else a


@njit(cache=True)
def shadow(xi, yi, h, k0, k1, wseg, seg):
    """S_i of (1) [-] for the particle at (xi, yi) with smoothing length h [m], over its near
    segments ``wseg[k0:k1]`` (rows of ``seg``: x1, y1, x2, y2 [m])."""
    n = k1 - k0
    if n == 0:
        return 0.0
    n = min(n, MAX_INTERVALS)
    lo = np.empty(n)      # interval start, measured from the reference direction [rad]
    span = np.empty(n)    # interval width [rad]
    foot = np.empty(n)    # direction of the foot on the line, from the reference [rad]
    dist = np.empty(n)    # distance to the line [m]
    ends = np.empty(2 * n)
    m = 0
    ref = 0.0
    reach = 2.0 * h
    for k in range(n):
        s = wseg[k0 + k]
        x1 = seg[s, 0] - xi
        y1 = seg[s, 1] - yi
        x2 = seg[s, 2] - xi
        y2 = seg[s, 3] - yi
        ex = x2 - x1
        ey = y2 - y1
        length = math.sqrt(ex * ex + ey * ey)
        delta = abs(x1 * ey - y1 * ex) / length
        if delta >= reach:
            continue
        a1 = math.atan2(y1, x1)
        a2 = math.atan2(y2, x2)
        width = _wrap(a2 - a1)
        if width > math.pi:  # take the segment from its other end
            a1, width = a2, TWO_PI - width
        if width <= 0.0 or width >= math.pi:
            continue  # seen edge-on, or i on the segment itself
        # the directions within 2h of i along the line: theta_n +/- acos(delta / 2h)
        t = -(x1 * ex + y1 * ey) / (length * length)
        fn = math.atan2(y1 + t * ey, x1 + t * ex) if delta > 0.0 else a1 + 0.5 * width
        half = math.acos(delta / reach)
        if m == 0:
            ref = a1
        start = _wrap(a1 - ref)
        stop = start + width
        c0 = start + _wrap(fn - half - ref - start + math.pi) - math.pi
        start = max(start, c0)
        stop = min(stop, c0 + 2.0 * half)
        if stop <= start:
            continue
        lo[m] = start
        span[m] = stop - start
        foot[m] = _wrap(fn - ref)
        dist[m] = delta
        m += 1
    if m == 0:
        return 0.0
    c = 0
    for k in range(m):
        ends[c] = _wrap(lo[k])
        ends[c + 1] = _wrap(lo[k] + span[k])
        c += 2
    ends = np.sort(ends[:c])
    total = 0.0
    for e in range(c):
        a = ends[e]
        b = ends[e + 1] if e + 1 < c else ends[0] + TWO_PI
        if b - a <= 1e-15:
            continue
        mid = 0.5 * (a + b)
        best = -1
        best_r = np.inf
        for k in range(m):
            off = _wrap(mid - lo[k])
            if off < span[k]:
                r = dist[k] / max(math.cos(mid - foot[k]), 1e-300)
                if r < best_r:
                    best_r = r
                    best = k
        if best < 0:
            continue
        # split where r_w = h (the kernel's kink), so each piece is smooth
        cuts = np.array([a, b, b, b])
        if dist[best] < h:
            inner = math.acos(dist[best] / h)
            centre = mid + ((foot[best] - mid + math.pi) % TWO_PI) - math.pi
            for j, kink in enumerate((centre - inner, centre + inner)):
                if a < kink < b:
                    cuts[1 + j] = kink
        cuts = np.sort(cuts)
        for piece in range(3):
            total += _piece(cuts[piece], cuts[piece + 1], foot[best], dist[best], h)
    return total


@njit(inline="always", cache=True)
def _piece(a, b, foot, delta, h):
    """Gauss-Legendre quadrature of B(r_w(theta) / h) over [a, b] for a line at distance
    delta [m] whose foot lies in the direction ``foot`` (eq. 1)."""
    if b <= a:
        return 0.0
    half_width = 0.5 * (b - a) / PIECES
    total = 0.0
    for k in range(PIECES):
        mid = a + (2 * k + 1) * half_width
        for g in range(GAUSS_X.shape[0]):
            cosine = math.cos(mid + half_width * GAUSS_X[g] - foot)
            if cosine > 0.0:
                total += GAUSS_W[g] * half_width * tail(delta / (cosine * h))
    return total


GRADIENT_STEP = 1e-4
"""Step [h] of the central differences of grad S."""


@njit(inline="always", cache=True)
def shadow_gradient(xi, yi, h, k0, k1, wseg, seg):
    """grad S_i [m-1] of (1) by central differences of ``GRADIENT_STEP`` h (S is smooth in
    x_i: its quadrature's ends move continuously)."""
    e = GRADIENT_STEP * h
    gx = (shadow(xi + e, yi, h, k0, k1, wseg, seg) - shadow(xi - e, yi, h, k0, k1, wseg, seg))
    gy = (shadow(xi, yi + e, h, k0, k1, wseg, seg) - shadow(xi, yi - e, h, k0, k1, wseg, seg))
    return gx / (2.0 * e), gy / (2.0 * e)


@njit(parallel=True, cache=True)
def balance_walls(rows, x, y, rho, h, wstart, wseg, seg, sums, ax, ay, walled):
    """The walls' pressure on the particles ``rows`` whose support a wall cuts.

    The hydrostatic part of the variational force is a_i^p = D_i + d_i E_i
    (``floodsph.sph.shore``); E_i, the push of i's own depth towards the part of its support
    that holds no particle, is g grad S_i in the continuum limit where a wall hides that part
    (E_i = -g sum_j V_j grad W_ij -> -g grad gamma_i). The wall pushes back with the pressure of
    i's depth on it, the boundary term of the semi-analytical walls (Ferrand et al., IJNMF 71
    (2013) 446-472, eq. 26):

        a_i^wall = - g d_i grad S_i,

    which grows as the particle nears the wall (|grad S| is largest at contact) and varies
    smoothly with its position and the wall's angle. ``walled[i]`` is set where S_i > 0.
    """
    for k in prange(rows.shape[0]):
        i = rows[k]
        walled[i] = False
        if wstart[i + 1] == wstart[i]:
            continue
        gx, gy = shadow_gradient(x[i], y[i], h[i], wstart[i], wstart[i + 1], wseg, seg)
        if gx == 0.0 and gy == 0.0:
            continue
        walled[i] = True
        d = rho[i] / RHO_WATER
        ax[i] -= GRAVITY * d * gx
        ay[i] -= GRAVITY * d * gy
