"""Depth from SPH density: the Newton-Raphson solve of density and smoothing length.

Equations (Vacondio et al., Adv. Water Resour. 58 (2013) 10-23; Rodriguez-Paz & Bonet,
Comput. Struct. 83 (2005) 1396-1410; ``docs/method.md`` §2):

    rho_i = sum_j m_j W(r_ij, h_i)                     (1)  gather summation, self included
    h_i   = h0_i (rho0_i / rho_i)^(1/2)                (2)  d_m = 2
    R_i   = rho_i - sum_j m_j W(r_ij, h_i(rho_i))           residual
    alpha_i = - sum_j m_j r_ij dW/dr(r_ij, h_i)             (= 2 rho_i on a regular lattice)
    rho_i <- rho_i [1 - 2 R_i / (2 R_i + alpha_i)]     (3)  Newton update

Units: rho [kg m-2] (= RHO_WATER * depth), h [m], m [kg], alpha [kg m-2].

Iteration stops per particle when |R_i| / rho_i < tol. A particle whose update is not positive
and finite falls back to the plain summation at its current h (SWE-SPHysics safeguard);
h is kept within [h0 / h_ratio, h0 * h_ratio] so that an isolated particle, whose self
contribution alone can never match its density, cannot grow without bound. In time steps
h is also kept within what the Verlet neighbour list holds (its skin): a particle that would
grow beyond it (a nearly isolated particle at a thin edge, whose solution can jump between
two roots 20 % apart) takes the summation at that h and catches up over the next steps,
instead of forcing a rebuild of every particle's list and a second solve. Likewise no h
shrinks in one step below ``H_SHRINK_MIN`` times its continuity guess: a particle that a
merge or a wall brings within a fraction of its h of a heavy neighbour has a second,
spurious root of (1)-(2) at a tiny h, where that neighbour's W(r, h) is near its peak. The
solve fell into it (in a refined dam break a 0.42 m deep particle became 30 m deep with
h = 0.9 m instead of 7.5 m in one step, and was shot off at 38 m/s, twice the bound
2 sqrt(g d0)); held at the bound, the pair repels and separates over the next steps.
Mirror images across walls (``floodsph.walls``) are part of the summation.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from floodsph.sph.kernels import beyond_support, w_cubic, w_dwdr_cubic
from floodsph.sph.shadow import shadow
from floodsph.walls.geometry import mirror
from floodsph.walls.images import corner_image
from floodsph.walls.sight import SIGHT_SLACK, hides

H_SHRINK_MIN = 0.8
"""In a time step, h_i >= H_SHRINK_MIN h_i(guess), i.e. rho_i at most 1.56 times its continuity
guess: a CFL step (cfl <= 0.3) moves no particle more than 0.3 h, so a genuine compression
stays well inside it."""


@njit(inline="always", cache=True)
def _pair(rx, ry, mj, hi):
    """m_j W(r, h_i) and m_j r dW/dr(r, h_i) of a pair at separation (rx, ry)."""
    r = math.sqrt(rx * rx + ry * ry)
    w, dw = w_dwdr_cubic(r, hi)
    return mj * w, mj * r * dw


@njit(inline="always", cache=True)
def _image(i, j, x, y, m, hi, seg, s):
    """m_j W(r, h_i) [kg m-2] and m_j r dW/dr [kg m-2] of j's mirror image across segment s
    (x_j' = 2 f_j - x_j, as ``floodsph.walls.images.wall_image`` places it) seen from i;
    (0, 0) when the wall does not hide that image's point from i (MVBP mirror particles,
    ``docs/method.md`` §7), or when the image is beyond i's support, where both terms are
    exactly zero (``floodsph.sph.kernels.beyond_support``; tested first, it spares most
    images their sight test)."""
    xm, ym, _, _, _ = mirror(x[j], y[j], seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
    rx = x[i] - xm
    ry = y[i] - ym
    if beyond_support(rx, ry, hi) or not hides(x[i], y[i], xm, ym, seg, s):
        return 0.0, 0.0
    return _pair(rx, ry, m[j], hi)


@njit(inline="always", cache=True)
def _corner(i, j, x, y, m, hi, seg, s1, s2):
    """m_j W(r, h_i) [kg m-2] and m_j r dW/dr [kg m-2] of j's point reflection through the
    right-angled corner of segments s1 and s2 (``floodsph.walls.images.corner_image``) seen from
    i; (0, 0) when that image does not apply (``docs/method.md`` §7)."""
    xc, yc, ok = corner_image(x[j], y[j], seg, s1, s2)
    if not ok:
        return 0.0, 0.0
    return _pair(x[i] - xc, y[i] - yc, m[j], hi)


@njit(inline="always", cache=True)
def _image_sums(rsum, alpha, i, hi, x, y, m, nstart, nbr, blocked, walls):
    """Add the mirror images' terms of particle i to its summation ``rsum`` and ``alpha``
    (:func:`summation`), segment by segment, each followed by the corners it opens."""
    seg, wdist, wstart, wseg, cstart, cpair = walls
    reach = 2.0 * hi + SIGHT_SLACK
    c = cstart[i]
    for k in range(wstart[i], wstart[i + 1]):
        s = wseg[k]
        if wdist[k] < reach:
            w, a = _image(i, i, x, y, m, hi, seg, s)
            rsum += w
            alpha -= a
            for q in range(nstart[i], nstart[i + 1]):
                if not blocked[q]:
                    w, a = _image(i, nbr[q], x, y, m, hi, seg, s)
                    rsum += w
                    alpha -= a
        while c < cstart[i + 1] and cpair[c, 0] == s:
            s2 = cpair[c, 1]
            w, a = _corner(i, i, x, y, m, hi, seg, s, s2)
            rsum += w
            alpha -= a
            for q in range(nstart[i], nstart[i + 1]):
                if not blocked[q]:
                    w, a = _corner(i, nbr[q], x, y, m, hi, seg, s, s2)
                    rsum += w
                    alpha -= a
            c += 1
    return rsum, alpha


@njit(inline="always", cache=True)
def summation(i, hi, x, y, m, nstart, nbr, blocked, walls):
    """Density summation (1) and alpha_i of particle i at smoothing length ``hi``.

    Returns (sum_j m_j W(r_ij, h_i), alpha_i), self and mirror images included; listed
    neighbours beyond the support 2 h_i are skipped (W = 0 there). Pairs flagged in
    ``blocked`` (:func:`floodsph.walls.sight.blocked_pairs`) are left out with their images.
    ``walls`` is the :class:`~floodsph.walls.index.WallLists` of the particles.
    A segment farther than 2 h_i from i (``walls.wdist``) makes no image
    within the support, so its single images are skipped (the sum is unchanged).
    Images are summed segment by segment, each segment followed by the corners it opens
    (``cpair`` lists them in that order), so the sum does not depend on list order.
    """
    wstart = walls.wstart
    xi = x[i]
    yi = y[i]
    rsum = m[i] * w_cubic(0.0, hi)
    alpha = 0.0
    support2 = 4.0 * hi * hi
    for q in range(nstart[i], nstart[i + 1]):
        j = nbr[q]
        rx = xi - x[j]
        ry = yi - y[j]
        if rx * rx + ry * ry >= support2 or blocked[q]:
            continue
        w, a = _pair(rx, ry, m[j], hi)
        rsum += w
        alpha -= a
    if wstart[i + 1] > wstart[i]:
        rsum, alpha = _image_sums(rsum, alpha, i, hi, x, y, m, nstart, nbr, blocked, walls)
    return rsum, alpha


GAMMA_MIN = 0.25
"""Least water fraction gamma = 1 - S of a support (``floodsph.sph.shadow``) that the
depth is corrected by: a particle pressed into a corner (gamma 0.25 at the vertex of a right
angle) is not made deeper still."""


@njit(inline="always", cache=True)
def wall_corrected(i, hi, rsum, alpha, x, y, wstart, wseg, seg):
    """The summation (1) and alpha_i of particle i divided by the water fraction of its support,
    gamma_i = 1 - S_i(h_i) (``floodsph.sph.shadow.shadow``, at least ``GAMMA_MIN``):
    rho_i = sum_j m_j W(r_ij, h_i) / gamma_i, the depth of water that fills the support up to the
    walls (Ferrand et al., IJNMF 71 (2013) 446-472, eq. 13). alpha_i is divided alike; the
    derivative of gamma in h is left out of it (the Newton update (3) then converges linearly
    next to walls; its residual is exact)."""
    if wstart[i + 1] == wstart[i]:
        return rsum, alpha
    gamma = max(1.0 - shadow(x[i], y[i], hi, wstart[i], wstart[i + 1], wseg, seg), GAMMA_MIN)
    return rsum / gamma, alpha / gamma


@njit(inline="always", cache=True)
def _h_of_rho(h0, rho0, rho, h_ratio):
    """h = h0 (rho0 / rho)^(1/2) of (2) [m], kept within [h0 / h_ratio, h0 h_ratio]."""
    return min(max(h0 * math.sqrt(rho0 / rho), h0 / h_ratio), h0 * h_ratio)


@njit(parallel=True, cache=True)
def solve(rows, x, y, m, rho, h, h0, rho0, alpha, nstart, nbr, blocked, walls, tol, max_iter,
          h_ratio, h_cap, h_shrink, integral, iters):
    """Newton-Raphson solve (1)-(3) of the particles ``rows``, in place (gather form).

    Only h_i changes the summation of particle i, so each particle iterates on its own to
    convergence. ``iters[i]`` receives the number of summations of particle i, negated when
    it did not converge in ``max_iter`` (it then takes the plain summation at its h).
    A particle already within ``tol`` at the start h (below) keeps its rho; alpha is that of the
    last summation.
    A particle whose iterate would exceed ``h_cap[i]`` (the most its neighbour list holds)
    stops at h_cap with the summation there, and ``iters[i]`` is set to 0 (capped). One whose
    iterate would fall below ``h_shrink`` times its incoming h stops there with the summation
    at that h, and ``iters[i]`` is set to ``max_iter + 1`` (held; ``h_shrink = 0``: no bound).
    With ``integral`` (``wall_model = "integral"``) each summation next to a wall is divided by
    the water fraction of the support (:func:`wall_corrected`).
    The iteration starts from h_i = h(rho_i) of (2) (within the bounds and the cap), not from
    the h it comes with: a particle that last took a plain summation (capped, unconverged, or
    at a bound of h) carries an h that does not satisfy (2), and an isolated one, whose
    summation is its own self term, would otherwise pass the residual test at once and keep
    that h for good (a lone particle thrown up a beach kept h0 / 10, and with it a time step
    ten times too short).
    """
    for k in prange(rows.shape[0]):
        i = rows[k]
        it = 0
        h_low = h_shrink * h[i]
        h_rho = _h_of_rho(h0[i], rho0[i], rho[i], h_ratio)
        capped = h_rho > h_cap[i]
        held = h_rho < h_low
        h[i] = min(max(h_rho, h_low), h_cap[i])
        while True:  # one summation call site: the solver compiles its loops once
            last = it >= max_iter or capped or held
            s, a = summation(i, h[i], x, y, m, nstart, nbr, blocked, walls)
            if integral:
                s, a = wall_corrected(i, h[i], s, a, x, y, walls.wstart, walls.wseg, walls.seg)
            alpha[i] = a
            if last:  # the plain summation at the h reached
                rho[i] = s
                iters[i] = 0 if capped else (max_iter + 1 if held else -it)
                break
            it += 1
            res = rho[i] - s
            if abs(res) < tol * rho[i]:
                iters[i] = it
                break
            new = rho[i] * (1.0 - 2.0 * res / (2.0 * res + alpha[i]))
            if not (new > 0.0) or not math.isfinite(new) or alpha[i] <= 0.0:
                new = s
            h_new = _h_of_rho(h0[i], rho0[i], new, h_ratio)
            capped = h_new > h_cap[i]
            held = h_new < h_low
            rho[i] = new
            h[i] = min(max(h_new, h_low), h_cap[i])


@njit(parallel=True, cache=True)
def predict(rho, h, divv, dt):
    """Continuity-based initial guess: rho (1 - dt div v), h (1 + dt div v / 2)."""
    for i in prange(rho.shape[0]):
        f = max(1.0 - dt * divv[i], 0.5)
        rho[i] *= f
        h[i] *= 1.0 / math.sqrt(f)


def solve_density(p, nl, blocked, walls, tol=1e-3, max_iter=20, h_ratio=10.0, cap=False,
                  integral=False, unmoved=False, skip=None):
    """Solve (1)-(3) in place for the particles of ``p`` that ``nl`` lists (``nl.rows``).

    ``p`` is the ParticleSet (its rho and h hold the initial guess); ``nl`` the NeighbourList;
    ``blocked`` its pairs separated by a wall (:func:`floodsph.walls.sight.blocked_pairs`);
    ``walls`` the :class:`~floodsph.walls.index.WallLists` of the particles.
    With ``cap`` (a time step), no h grows beyond what ``nl`` holds (:meth:`NeighbourList.h_cap`),
    so the lists stay valid through the solve, and none shrinks below ``H_SHRINK_MIN`` times its
    guess (see the module docstring); ``unmoved``: the particles are where ``nl`` was built.
    On return every particle has rho, h and alpha consistent with its neighbours to ``tol``,
    except the unconverged, capped and held ones, which take the plain summation at their h.
    ``skip``: a mask of particles left out, whose rho and h stay as they come (the balanced
    momentum's still water, ``floodsph.sph.level_offsets``).
    Returns the :class:`DensityOutcome` counts.
    """
    iters = np.ones(p.n, dtype=np.int64)  # rows not solved count as converged
    h_cap = nl.h_cap(p.x, p.y, unmoved) if cap else np.full(p.n, np.inf)
    rows = nl.rows if skip is None else nl.rows[~skip[nl.rows]]
    solve(rows, p.x, p.y, p.m, p.rho, p.h, p.h0, p.rho0, p.alpha, nl.start, nl.nbr, blocked,
          walls, tol, max_iter, h_ratio, h_cap, H_SHRINK_MIN if cap else 0.0, integral, iters)
    return DensityOutcome(*_outcome(iters, max_iter))


@njit(cache=True)
def _outcome(iters, max_iter):
    """(iterations, unconverged, capped, held) of :class:`DensityOutcome` from the codes
    ``iters`` of :func:`solve`, in one pass."""
    most = 0
    unconverged = 0
    capped = 0
    held = 0
    for k in iters:
        if k > max_iter:
            held += 1
        else:
            most = max(most, abs(k))
            unconverged += k < 0
            capped += k == 0
    return most, unconverged, capped, held


class DensityOutcome(NamedTuple):
    """What :func:`solve_density` did, decoded from the per-particle code ``iters`` of
    :func:`solve`: k > 0 converged in k summations, -k not converged in k, 0 capped at the
    lists' reach, > max_iter held at the shrink bound."""

    iterations: int
    """The largest number of summations a converged or unconverged particle needed."""
    unconverged: int
    """Particles not converged to ``tol`` in ``max_iter`` (plain summation at their h)."""
    capped: int
    """Particles whose h was capped at what the neighbour lists hold."""
    held: int
    """Particles held at ``H_SHRINK_MIN`` times their guessed h."""
