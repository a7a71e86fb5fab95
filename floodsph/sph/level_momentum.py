"""The balanced momentum: the free-surface level's gradient as renormalised level differences.

``numerics.momentum = "balanced"``. With the level eta = d + b + o (d = rho / rho_w the
summation depth, b the bilinear bed at the particle, o the particle's level offset,
``floodsph.sph.level_offsets``), pressure and bed together are -g grad eta (de Saint-Venant), and
grad eta is the renormalised difference gradient (Randles & Libersky 1996; Bonet & Lok 1999):

    a_i^p = -g N_i^-1 S_i,
    S_i = sum_j w_ij (eta_j - eta_i) r_ij,   N_i = - sum_j w_ij r_ij r_ij^T,
    w_ij = (m_j / rho_j) (F(r_ij, h_i) + F(r_ij, h_j)) / 2,   F = (1/r) dW/dr < 0,
    r_ij = x_i - x_j.

It is exact for a linear level, and zero pair by pair for a level one: a lake whose particles
all carry the level L is an equilibrium whatever the bed, the particles' arrangement, h, the
walls or a shore. N_i's eigenvalues are lifted to at least ``N_MIN`` (1 in a full support)
where the support is nearly one-sided.

Walls: mirror images (``floodsph.walls.images.moving_image``) carry their particle's level
(the level is continued across the wall, not the depth) and its mirrored velocity.

Free edges. Where the water ends, the missing part of the support is dry ground, whose level
is the bed b_g there: with e_i = - sum_j w_ij r_ij (0 in a full support) the missing pairs
add (b_g - eta_i) (-e_i) to S_i and about |e_i| l e^ e^^T to N_i, e^ = e_i / |e_i|,
l = ``GHOST_REACH`` h_i (which completes N to the identity for a support cut through its
centre). The ghost acts only where |e_i| h_i >= ``EDGE_MIN`` and the water really ends,
tested at the point x_g = x_i + ``COVER_REACH`` h_i e^ beyond the particle, not at the
particle (whose own Shepard sum stays near 1 even at a front):

    1. no wall lies across [x_i, x_i + 2 h_i e^] (walls hold water through their images);
    2. the water's Shepard sum at x_g, sum_j (m_j / rho_j) W(|x_g - x_j|, h_j) over i and its
       unblocked neighbours and their wall images, is below ``COVER_MIN`` (inside the water
       it is near 1, at a front near 0.5 or less); water faster than ``EDGE_SPEED`` skips
       this test and the next, as the rows behind a moving front need the push;
    3. for still water, none of the points x_i + (1, 1.5, 2) h_i e^ lies in a DEM cell that
       held water at seeding or is nodata, or whose elevation is at or above eta_i: a lake's gaps
       between the seeded particles and its banks (a lattice cell emptied into a deeper
       neighbour, the sliver of a walled nodata cell) are not free edges, while the dry
       ground beyond a dam face is;
    4. the bed at x_i + 2 h_i e^ lies below eta_i + (v_i . e^)_+^2 / 2g: a still shore on
       rising ground holds its water.

Still water held by its banks. Tests 2 and 3 look at points and DEM cells that move with the
particle, so a lake at rest disturbed by a micrometre could switch its banks' ghosts on and
off (a Malpasset reservoir disturbed by 1e-6 m/s reached 3 m/s within 20 s, a shore
particle's ghost switched on in the first step). Water seeded at rest whose support had no
free edge at set-up therefore keeps none while it stays slower than ``EDGE_SPEED``
(``bank_held`` = ``floodsph.sph.level_offsets.HELD``, set by
``floodsph.model.builder.match_levels`` and released for good once the
particle reaches that speed; a departure of its level from its seeded level by
``HOLD_LEVEL`` ends the rest of the hold, ``floodsph.sph.level_offsets.BANKED``): its banks
were tested once, on the seeded lake. Where its support is cut (|e_i| h_i >=
``EDGE_MIN``), the missing part is a bank that holds water as a wall does: the level is
continued across it (no term in S_i; N_i is completed as for the dry ghost), and it stands
still, so that a particle moving into it is compressed: its pairs with the missing part add
sum_missing m_j F_ij (v_i . r_ij) ~ rho_i (v_i . e_i) to the divergence sum. A ghost at the
lake's seeded level instead left a particle whose level fell free to creep into the gap, and
Malpasset's reservoir disturbed by 1e-4 m/s left rest after 450 s (with it, 600 s pass).

Held water is also damped and tethered: at each drift v_i <- (v_i - k (x_i - x_i^seed) dt)
exp(-dt / ``HOLD_TIME``), k = ``HOLD_STIFFNESS``, x_i^seed where it was at set-up. Measured on
the Malpasset reservoir disturbed by 1e-6 m/s, with a bank ghost at the lake's level and the
held water's continuity depth and fixed offset (``floodsph.sph.level_offsets``) but neither
of these, a few
particles in pockets of the nodata border grew e-fold every 11 s (global steps): a one-sided
support whose particle moves away from its neighbours expands, its level falls and the level
difference pushes it further. With the damping alone one of them still crept away, its force
growing with its displacement (a negative stiffness of about 0.025 s-2), and was released
after 8 minutes. The tether's stiffness is four times that, and its period with the damping
(20 s) is long against a step. Both act only below 1 cm/s and within 1 cm of the seeded
level, where a lake is at rest.

The ghost's depth: d* = eta_i - b_g where the bed beyond is level or falls (b_g <= b_i), else
the hydrostatic reconstruction min(max(eta_i + run-up - b_g, 0), d_i) (Audusse et al. 2004,
SIAM J. Sci. Comput. 25, 2050-2065), b_g the bed at x_i + l e^.

Shock capturing is the Ata & Soulaimani term of ``floodsph.sph.forces`` (approaching pairs,
antisymmetric). The velocity divergence for the continuity guess of the depth is the one of
``floodsph.sph.forces``, div v_i = -(2 / alpha_i) sum_j m_j (v_i - v_j) . grad_i W(r_ij, h_i).

The bed enters only through the normal-force part of the bed term of Rodriguez-Paz & Bonet
(2005): ``floodsph.sph.forces.add_bed_acceleration`` with g_bed = 0 (zero at rest).
Momentum is conserved only to the gradient's consistency: a difference form cannot be both
exact for a level and antisymmetric.

Moving water. The level form's free edges push only the outermost row of a dry front, and a
front that thins into a train of equally deep particles then coasts (Ritter at 10 m: L1 7.9 %
against 1.9 %). Water faster than ``BLEND_SPEED`` therefore takes the variational force
(``floodsph.sph.forces``), and slower water a blend
(``floodsph.sph.momentum_blend.variational_weight``): a lake at rest is still exact, and a
flood wave keeps the variational force's accuracy.

Units: accelerations [m s-2], levels and depths [m], rho [kg m-2], m [kg], h and r [m].
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.sph.bed import BED, elevation_at
from floodsph.sph.kernels import beyond_support, dwdr_over_r_cubic, w_cubic
from floodsph.sph.level_offsets import FREE
from floodsph.walls.geometry import mirror
from floodsph.walls.images import moving_image
from floodsph.walls.sight import SIGHT_SLACK, hides

N_MIN = 0.25
"""Least eigenvalue of N_i used in its inverse [-] (1 in a full support)."""
EDGE_MIN = 0.02
"""|e_i| h_i [-] below which a support is taken as full (no ghost): 0.68 where a straight
edge runs through the particle, and round-off and lattice noise in the water."""
GHOST_REACH = 0.733
"""l / h_i: where the ghost stands beyond the particle; |e| h = 0.682 for a support cut
through its centre, and N_i then grows along e^ by 0.682 x 0.733 = 0.5, from 0.5 to 1."""
COVER_REACH = 0.75
"""|x_g - x_i| / h_i of the point where the ghost tests for water."""
COVER_MIN = 0.6
"""Shepard sum at x_g [-] at and above which there is water there (no ghost)."""
BLEND_SPEED = 0.1
"""Speed [m s-1] from which water takes the variational force alone
(``floodsph.sph.momentum_blend.variational_weight``)."""
HOLD_TIME = 1.0
"""Relaxation time [s] of the damping of still water held by its banks (module docstring;
``floodsph.sph.level_offsets.hold_still``)."""
HOLD_STIFFNESS = 0.1
"""Stiffness [s-2] of the tether of still water held by its banks to where it was seeded
(module docstring; ``floodsph.sph.level_offsets.hold_still``)."""
HOLD_LEVEL = 0.01
"""Departure [m] of a held particle's level from its seeded level at which it is released
(module docstring)."""
EDGE_SPEED = 0.01
"""Speed [m s-1] from which a particle's cut support is a free edge without the Shepard-sum
test (test 2): moving water's rows behind a front need the push."""


@njit(inline="always", cache=True)
def _add_pair(acc, rx, ry, vx, vy, deta, i, j, m, rho, h, inv_h, wave):
    """Add the pair of i and j (or j's image) at r = x_i - x_j, v = v_i - v_j, with the level
    difference deta = eta_j - eta_i [m], to i's sums ``acc``:
    0-1 shock-capturing acceleration [m s-2], 2-3 S [-], 4-6 -N (xx, xy, yy) [-],
    7-8 -e (x, y) [m-1], 9 the divergence sum, sum m_j F(r, h_i) (v . r) [kg m-2 s-1].
    ``inv_h`` and ``wave`` are every particle's 1 / h [m-1] and c = sqrt(g rho / rho_w)
    [m s-1] (:func:`_particle_factors`)."""
    r2 = rx * rx + ry * ry
    if r2 <= 0.0:
        return acc
    r = math.sqrt(r2)
    inv_r = 1.0 / r
    fi = dwdr_over_r_cubic(r, inv_r, inv_h[i])
    fj = dwdr_over_r_cubic(r, inv_r, inv_h[j])
    w = 0.5 * m[j] / rho[j] * (fi + fj)
    vr = vx * rx + vy * ry
    fv = 0.0
    if vr < 0.0:
        hbar = 0.5 * (h[i] + h[j])
        cbar = 0.5 * (wave[i] + wave[j])
        pi_ij = -cbar * vr / (0.5 * (rho[i] + rho[j]) * math.sqrt(r2 + 0.01 * hbar * hbar))
        fv = m[j] * 0.5 * pi_ij * (fi + fj)
    return (acc[0] - fv * rx, acc[1] - fv * ry, acc[2] + w * deta * rx, acc[3] + w * deta * ry,
            acc[4] + w * rx * rx, acc[5] + w * rx * ry, acc[6] + w * ry * ry,
            acc[7] + w * rx, acc[8] + w * ry, acc[9] + m[j] * fi * vr)


@njit(parallel=True, cache=True)
def _particle_factors(rho, h, inv_h, wave):
    """Each particle's 1 / h [m-1] into ``inv_h`` and wave speed c = sqrt(g rho / rho_w)
    [m s-1] into ``wave``: computed once per evaluation, not once per pair (the same
    numbers)."""
    for i in prange(h.shape[0]):
        inv_h[i] = 1.0 / h[i]
        wave[i] = math.sqrt(GRAVITY * rho[i] / RHO_WATER)


@njit(inline="always", cache=True)
def _add_images(acc, i, nstart, nbr, blocked, x, y, u, v, m, rho, h, inv_h, wave, eta, seg, s,
                s2, ds):
    """Add the images of i and of its unblocked neighbours about segment s (s2 < 0) or
    through the corner of s and s2 to i's sums (:func:`_add_pair`); ``ds`` is i's distance
    to s [m] (0 for a corner): images beyond the pair's support are skipped, by that bound
    and then by their own distance (``floodsph.sph.kernels.beyond_support``: their terms are
    exactly zero)."""
    hi = h[i]
    for q in range(nstart[i] - 1, nstart[i + 1]):
        if q < nstart[i]:
            j = i
            if ds >= 2.0 * hi + SIGHT_SLACK:
                continue
        else:
            j = nbr[q]
            if blocked[q] or ds >= 2.0 * max(hi, h[j]) + SIGHT_SLACK:
                continue
        ok, xm, ym, um, vm = moving_image(x[i], y[i], x[j], y[j], u[j], v[j], seg, s, s2)
        if ok and not beyond_support(x[i] - xm, y[i] - ym, max(hi, h[j])):
            acc = _add_pair(acc, x[i] - xm, y[i] - ym, u[i] - um, v[i] - vm, eta[j] - eta[i], i,
                            j, m, rho, h, inv_h, wave)
    return acc


@njit(inline="always", cache=True)
def _inverse(nxx, nxy, nyy):
    """Inverse (xx, xy, yy) of the symmetric 2x2 N with its eigenvalues lifted to at least
    ``N_MIN``."""
    half_tr = 0.5 * (nxx + nyy)
    det = nxx * nyy - nxy * nxy
    low = half_tr - math.sqrt(max(half_tr * half_tr - det, 0.0))
    if low < N_MIN:
        nxx += N_MIN - low
        nyy += N_MIN - low
        det = nxx * nyy - nxy * nxy
    return nyy / det, -nxy / det, nxx / det


@njit(inline="always", cache=True)
def _walled(xi, yi, xf, yf, wstart, wseg, seg, i):
    """True if one of i's near wall segments lies across the line from x_i to (xf, yf)."""
    for k in range(wstart[i], wstart[i + 1]):
        if hides(xi, yi, xf, yf, seg, wseg[k]):
            return True
    return False


@njit(inline="always", cache=True)
def _cover(i, gx, gy, nstart, nbr, blocked, x, y, m, rho, h, wstart, wseg, seg):
    """The water's Shepard sum [-] at (gx, gy): sum_j (m_j / rho_j) W(|x_g - x_j|, h_j) over i
    and its unblocked neighbours, and over their mirror images about i's near walls that a
    wall hides from x_g (by a wall the images fill the support, as in the density)."""
    total = 0.0
    for q in range(nstart[i] - 1, nstart[i + 1]):
        j = i if q < nstart[i] else nbr[q]
        if q >= nstart[i] and blocked[q]:
            continue
        vol = m[j] / rho[j]
        total += vol * w_cubic(math.hypot(gx - x[j], gy - y[j]), h[j])
        for k in range(wstart[i], wstart[i + 1]):
            s = wseg[k]
            xm, ym, _, _, _ = mirror(x[j], y[j], seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
            r = math.hypot(gx - xm, gy - ym)
            if r < 2.0 * h[j] and hides(gx, gy, xm, ym, seg, s):
                total += vol * w_cubic(r, h[j])
    return total


@njit(inline="always", cache=True)
def _held_beyond(xi, yi, ux, uy, hi, eta_i, held, elevation, tdx, tdy):
    """True if one of the points x_i + (1, 1.5, 2) h_i e^ lies in a DEM cell that ``held``
    marks (water at seeding, or nodata) or whose elevation is at or above the level eta_i [m]
    (the cell's own value, as the seeding saw it): still water there is held by the seeded
    water's own banks (module docstring, test 3)."""
    ny, nx = elevation.shape
    for reach in (1.0, 1.5, 2.0):
        px = xi + reach * hi * ux
        py = yi + reach * hi * uy
        col = min(max(int(px / tdx), 0), nx - 1)
        row = min(max(int(py / tdy), 0), ny - 1)
        if held[row, col] or elevation[row, col] >= eta_i:
            return True
    return False


@njit(inline="always", cache=True)
def ghost_depth(i, ex, ey, hi, xi, yi, u, v, eta, bed, nstart, nbr, blocked, x, y, m, rho, h,
                wstart, wseg, seg, elevation, held, tdx, tdy):
    """d* [m] of the dry ghost beyond particle i, whose sums left e = (ex, ey) [m-1]; 0 where
    the support is full or the water does not end there (module docstring, tests 1-4)."""
    e = math.sqrt(ex * ex + ey * ey)
    if e * hi < EDGE_MIN:
        return 0.0
    ux = ex / e
    uy = ey / e
    xf = xi + 2.0 * hi * ux
    yf = yi + 2.0 * hi * uy
    if _walled(xi, yi, xf, yf, wstart, wseg, seg, i):
        return 0.0
    if u[i] * u[i] + v[i] * v[i] < EDGE_SPEED * EDGE_SPEED:
        gx = xi + COVER_REACH * hi * ux
        gy = yi + COVER_REACH * hi * uy
        if _cover(i, gx, gy, nstart, nbr, blocked, x, y, m, rho, h, wstart, wseg,
                  seg) >= COVER_MIN:
            return 0.0
        if _held_beyond(xi, yi, ux, uy, hi, eta[i], held, elevation, tdx, tdy):
            return 0.0
    ny, nx = elevation.shape
    toward = max(u[i] * ux + v[i] * uy, 0.0)
    run_up = 0.5 * toward * toward / GRAVITY
    if elevation_at(xf, yf, tdx, tdy, elevation, nx, ny) >= eta[i] + run_up:
        return 0.0
    reach = GHOST_REACH * hi
    b_g = elevation_at(xi + reach * ux, yi + reach * uy, tdx, tdy, elevation, nx, ny)
    b_i = bed[i, BED]
    if b_g <= b_i:
        return max(eta[i] - b_g, 0.0)
    return min(max(eta[i] + run_up - b_g, 0.0), eta[i] - b_i)


@njit(parallel=True, cache=True)
def balanced_acceleration(rows, x, y, u, v, m, rho, alpha, h, eta, bed, nstart, nbr, blocked,
                          walls, elevation, held, bank_held, tdx, tdy, ax, ay, divv, ghost):
    """a_i = -g N_i^-1 S_i + shock capturing, and div v_i, of the particles ``rows`` (gather
    form; module docstring), with the neighbour lists, blocked pairs and
    :class:`~floodsph.walls.index.WallLists` of ``floodsph.sph.forces.internal_acceleration``;
    ``eta`` [m] the particles' levels, ``bed`` their bed sample (``floodsph.sph.bed``),
    ``elevation`` the terrain's node grid of spacing (tdx, tdy) [m] and ``held`` its cells
    that held water at seeding or are nodata (test 3), ``bank_held`` the particles' flags of
    still water held by its banks (module docstring); ``ghost`` receives each
    particle's ghost depth d* [m] (0: no free edge)."""
    seg, wdist, wstart, wseg, cstart, cpair = walls
    inv_h = np.empty(h.shape[0])
    wave = np.empty(h.shape[0])
    _particle_factors(rho, h, inv_h, wave)
    for k in prange(rows.shape[0]):
        i = rows[k]
        xi = x[i]
        yi = y[i]
        hi = h[i]
        acc = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        h_reach = hi
        for q in range(nstart[i], nstart[i + 1]):
            j = nbr[q]
            rx = xi - x[j]
            ry = yi - y[j]
            h_reach = max(h_reach, h[j])
            hm = 2.0 * max(hi, h[j])
            if rx * rx + ry * ry >= hm * hm or blocked[q]:
                continue
            acc = _add_pair(acc, rx, ry, u[i] - u[j], v[i] - v[j], eta[j] - eta[i], i, j, m,
                            rho, h, inv_h, wave)
        w = wstart[i]
        cc = cstart[i]
        single = True
        while w < wstart[i + 1]:
            s = wseg[w]
            s2 = -1
            ds = wdist[w]
            if single:
                single = False
                if ds >= 2.0 * h_reach + SIGHT_SLACK:
                    continue
            elif cc < cstart[i + 1] and cpair[cc, 0] == s:
                s2 = cpair[cc, 1]
                ds = 0.0
                cc += 1
            else:
                w += 1
                single = True
                continue
            acc = _add_images(acc, i, nstart, nbr, blocked, x, y, u, v, m, rho, h, inv_h, wave,
                              eta, seg, s, s2, ds)
        nxx = -acc[4]
        nxy = -acc[5]
        nyy = -acc[6]
        sx = acc[2]
        sy = acc[3]
        ex = -acc[7]
        ey = -acc[8]
        bank_div = 0.0
        if bank_held[i] != FREE:  # held, banked or just released: no free edge
            d_ghost = 0.0
            e = math.sqrt(ex * ex + ey * ey)
            if e * hi >= EDGE_MIN:  # the bank: a wall
                reach = GHOST_REACH * hi
                bank_div = rho[i] * (u[i] * ex + v[i] * ey)
                nxx += reach * ex * ex / e
                nxy += reach * ex * ey / e
                nyy += reach * ey * ey / e
        else:
            d_ghost = ghost_depth(i, ex, ey, hi, xi, yi, u, v, eta, bed, nstart, nbr, blocked,
                                  x, y, m, rho, h, wstart, wseg, seg, elevation, held, tdx,
                                  tdy)
        ghost[i] = d_ghost
        if d_ghost > 0.0:
            e = math.sqrt(ex * ex + ey * ey)
            reach = GHOST_REACH * hi
            sx -= d_ghost * ex
            sy -= d_ghost * ey
            nxx += reach * ex * ex / e
            nxy += reach * ex * ey / e
            nyy += reach * ey * ey / e
        ixx, ixy, iyy = _inverse(nxx, nxy, nyy)
        ax[i] = acc[0] - GRAVITY * (ixx * sx + ixy * sy)
        ay[i] = acc[1] - GRAVITY * (ixy * sx + iyy * sy)
        beta = 2.0 * rho[i] / alpha[i] if alpha[i] > 0.0 else 1.0
        divv[i] = -beta * (acc[9] + bank_div) / rho[i]
