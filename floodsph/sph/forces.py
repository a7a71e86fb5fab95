"""Accelerations: the variational pressure force with shock capturing, and the bed.

Internal (pressure) acceleration with the grad-h correction (Vacondio et al. 2013 via
Rodriguez-Paz & Bonet 2005; ``docs/method.md`` §3.1), with beta_i = 2 rho_i / alpha_i:

    a_i^int = - sum_j m_j [ (g beta_i / (2 rho_w) + Pi_ij / 2) grad_i W(r_ij, h_i)
                          + (g beta_j / (2 rho_w) + Pi_ij / 2) grad_i W(r_ij, h_j) ]

Shock capturing (parameter-free, Ata & Soulaimani, IJNMF 47 (2005) 139-159; ``docs/method.md``
§3.2), active for approaching pairs (v_ij . x_ij < 0):

    Pi_ij = - cbar_ij (v_ij . x_ij) / (rhobar_ij sqrt(r_ij^2 + eta^2)),  eta^2 = 0.01 hbar^2

Option "riemann" (``docs/method.md`` §3.2, SWE-SPHysics): g rho_i^2 / (2 rho_w) in the pressure
term of both particles is replaced by the two-shock Riemann pressure p* = g rho_w d*^2 / 2
(Toro) of the pair, solved along the pair axis.

Option "muscl": Pi_ij acts on every pair, approaching or receding, with v_ij . x_ij replaced
by the jump left once both velocities are carried to the pair's midpoint along their
gradients, limited (:func:`reconstructed_jump`): no dissipation in a linear velocity field,
the full Lax-Friedrichs-type term across shocks and fronts. Measured in
``docs/reconstruction.md``.

The pressure part of each pair is renormalised by the mean of the pair's K where the particles
have left the lattice (``floodsph.sph.consistency``). All these forms are antisymmetric in
(i, j): internal forces conserve linear momentum exactly. The same loop sums
the hydrostatic pressure's parts that ``floodsph.sph.consistency`` renormalises with and that
``floodsph.sph.shore`` uses to balance it where the water ends on a rising bed.
Wall images (``floodsph.walls``) enter the same pair terms; a particle's own images
(across a wall, normal to it, and through a corner) with the kernel gradient held at its peak
below q = r/h = 2/3 (:func:`floodsph.sph.kernels.dwdr_over_r_floored`). With the plain cubic
the push of a particle's own image, at twice its distance to the wall, fades as the particle
nears the wall (at 10 m spacing and 3 m depth: 0.33 m s-2 at 2 m from the wall, 0.03 at
0.1 m), so particles crowded against a wall or into a corner stuck there, at several times the
depth around, and were shot off (seen at up to 14 m s-1 in still water between oblique walls).
With the floor the push grows as the wall comes closer. On a lattice a half spacing from a
straight wall the own image is at q = 1 / kappa = 0.83, so still water there is unchanged.
The images of other particles keep the plain gradient: their pair axis has a component along
the wall, and a floored gradient there would add to the pressure force along the wall what
the real neighbours do not (it sped up the thin front of a dam break in a 100 m channel).
The same loop returns the velocity divergence used for the continuity-based density guess,
div v_i = -(2 / alpha_i) sum_j m_j (v_i - v_j) . grad_i W(r_ij, h_i).

Bed (pointwise, ``docs/method.md`` §3.5):

    a_i = a_i^int - [(g + v.K.v + a_i^int . grad b) / (1 + |grad b|^2)] grad b

Friction and the time step's kicks are ``floodsph.sph.time_step``'s.

Units: accelerations [m s-2], rho [kg m-2], m [kg], h and r [m].
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.sph.bed import CURV_XX, CURV_XY, CURV_YY, SLOPE_X, SLOPE_Y
from floodsph.sph.kernels import dwdr_over_r_cubic, dwdr_over_r_floored
from floodsph.sph.sums import D_X, MOMENT_X, MOMENT_Y
from floodsph.walls.geometry import mirror
from floodsph.walls.images import corner_image
from floodsph.walls.sight import SIGHT_SLACK, hides

LAX_FRIEDRICHS = 0
RIEMANN = 1
MUSCL = 2

BETA, WAVE_SPEED, INV_H, HALF_G_AREA, K_XX, K_XY, K_YY, G_XX, G_XY, G_YX, G_YY = range(11)
"""Columns of the per-particle pair coefficients (:func:`pair_coefficients`): beta_i, c_i,
1 / h_i, g A_i / 2, the pressure renormalisation K_i (xx, xy, yy) and, under "muscl" only, the
velocity gradient G_i (du/dx, du/dy, dv/dx, dv/dy)."""
COEF_COLUMNS = 7
"""Columns of the pair coefficients under "lax-friedrichs" and "riemann"."""
COEF_COLUMNS_MUSCL = 11
"""Columns of the pair coefficients under "muscl" (with the velocity gradient)."""


@njit(inline="always", cache=True)
def riemann_pressure(d_l, d_r, u_l, u_r):
    """Two-shock approximate Riemann solver (Toro): star pressure p* [N m-1 = kg s-2].

    d0 = (1/g)[(c_l + c_r)/2 + (u_l - u_r)/4]^2, g_K = sqrt(g (d0 + d_K) / (2 d0 d_K)),
    d* = (g_l d_l + g_r d_r + u_l - u_r) / (g_l + g_r), p* = g rho_w d*^2 / 2.
    """
    c_l = math.sqrt(GRAVITY * d_l)
    c_r = math.sqrt(GRAVITY * d_r)
    s = 0.5 * (c_l + c_r) + 0.25 * (u_l - u_r)
    d0 = s * s / GRAVITY
    if d0 <= 0.0 or d_l <= 0.0 or d_r <= 0.0:
        return 0.0
    g_l = math.sqrt(0.5 * GRAVITY * (d0 + d_l) / (d0 * d_l))
    g_r = math.sqrt(0.5 * GRAVITY * (d0 + d_r) / (d0 * d_r))
    d_star = max((g_l * d_l + g_r * d_r + u_l - u_r) / (g_l + g_r), 0.0)
    return 0.5 * GRAVITY * RHO_WATER * d_star * d_star


@njit(parallel=True, cache=True)
def pair_coefficients(m, rho, alpha, h, kxx, kxy, kyy, dudx, dudy, dvdx, dvdy, coef):
    """Per-particle factors of the pair force, the named columns of ``coef[i]``: ``BETA``,
    ``WAVE_SPEED``, ``INV_H``, ``HALF_G_AREA``, ``K_XX``, ``K_XY``, ``K_YY`` and ``G_XX``,
    ``G_XY``, ``G_YX``, ``G_YY``.

    beta_i = 2 rho_i / alpha_i [-], c_i = sqrt(g rho_i / rho_w) [m s-1] (wave speed),
    1 / h_i [m^-1], g A_i / 2 [m3 s-2] with the area A_i = m_i / rho_i, and the pressure
    renormalisation K_i [-] of ``floodsph.sph.consistency``, and the velocity gradient
    G_i = (du/dx, du/dy; dv/dx, dv/dy) [s-1] of the last force evaluation (only when ``coef``
    has its ``COEF_COLUMNS_MUSCL`` columns: the "muscl" stabilisation's; the others take
    ``COEF_COLUMNS``). A particle with no
    neighbour within its support (alpha_i = 0, possible when its h is held back by its lists)
    takes beta_i = 1, the uncorrected force (alpha_i = 2 rho_i on a lattice).
    """
    for i in prange(rho.shape[0]):
        coef[i, BETA] = 2.0 * rho[i] / alpha[i] if alpha[i] > 0.0 else 1.0
        coef[i, WAVE_SPEED] = math.sqrt(GRAVITY * rho[i] / RHO_WATER)
        coef[i, INV_H] = 1.0 / h[i]
        coef[i, HALF_G_AREA] = 0.5 * GRAVITY * m[i] / rho[i]
        coef[i, K_XX] = kxx[i]
        coef[i, K_XY] = kxy[i]
        coef[i, K_YY] = kyy[i]
        if coef.shape[1] > COEF_COLUMNS:
            coef[i, G_XX] = dudx[i]
            coef[i, G_XY] = dudy[i]
            coef[i, G_YX] = dvdx[i]
            coef[i, G_YY] = dvdy[i]


@njit(inline="always", cache=True)
def pair_force(rx, ry, vx, vy, i, j, m, rho, h, coef, scheme, kj, gj, image=False):
    """Pair terms of a_i^int and of div v_i for separation r = x_i - x_j, v = v_i - v_j.

    j's properties (mass, density, h, ``coef`` of :func:`pair_coefficients`) are taken at
    index j, also for j's mirror images (whose r and v the caller passes), except j's
    pressure renormalisation ``kj`` = (K xx, xy, yy), reflected with the image, and its
    velocity gradient ``gj`` (xx, xy, yx, yy; zeros for an image, which keeps the raw jump
    under "muscl"). Returns (rx, ry, fx, fy, w, fd, af), summed by
    :func:`_subtract`: a_i^int takes - (fx, fy), the pressure part f_p r renormalised to
    f_p (I + (K_i + K_j) / 2) r (``floodsph.sph.consistency``) plus the shock-capturing part
    f_v r; the divergence sum
    sum_j m_j (v_i - v_j) . grad_i W(r_ij, h_i) takes - fd; and
    w = (g / 2) (m_j / rho_j) (beta_i F_i + beta_j F_j) [s-2 m-2] (F = (1/r) dW/dr) is the
    pair's hydrostatic weight, for the sums of ``floodsph.sph.shore`` and
    ``floodsph.sph.consistency``; af = (m_j / rho_j) F_i [m-2], for the latter's edge test.
    ``image``: j is i's own wall image (the floored kernel gradient).
    """
    r2 = rx * rx + ry * ry
    if r2 <= 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    r = math.sqrt(r2)
    inv_r = 1.0 / r
    if image:
        fi = dwdr_over_r_floored(r, inv_r, coef[i, INV_H])
        fj = dwdr_over_r_floored(r, inv_r, coef[j, INV_H])
    else:
        fi = dwdr_over_r_cubic(r, inv_r, coef[i, INV_H])
        fj = dwdr_over_r_cubic(r, inv_r, coef[j, INV_H])
    vr = vx * rx + vy * ry
    if scheme == RIEMANN:
        # axis from i to j: u_l = v_i . e, u_r = v_j . e, so u_l - u_r = -vr / r
        p_star = riemann_pressure(rho[i] / RHO_WATER, rho[j] / RHO_WATER, 0.0, vr * inv_r)
        fp = m[j] * p_star * (coef[i, BETA] * fi / (rho[i] * rho[i])
                              + coef[j, BETA] * fj / (rho[j] * rho[j]))
        fv = 0.0
    else:
        # Pi_ij for approaching pairs, computed for all and zero otherwise (no jump); with
        # "muscl" for every pair, from the limited jump at the midpoint
        hbar = 0.5 * (h[i] + h[j])
        cbar = 0.5 * (coef[i, WAVE_SPEED] + coef[j, WAVE_SPEED])
        if scheme == MUSCL:
            jump = reconstructed_jump(rx, ry, vr, coef[i, G_XX], coef[i, G_XY], coef[i, G_YX],
                                      coef[i, G_YY], gj)
        else:
            jump = min(vr, 0.0)
        pi_ij = -cbar * jump / (0.5 * (rho[i] + rho[j])
                                        * math.sqrt(r2 + 0.01 * hbar * hbar))
        fp = m[j] * (0.5 * GRAVITY / RHO_WATER) * (coef[i, BETA] * fi + coef[j, BETA] * fj)
        fv = m[j] * 0.5 * pi_ij * (fi + fj)
    kxx = 0.5 * fp * (coef[i, K_XX] + kj[0])
    kxy = 0.5 * fp * (coef[i, K_XY] + kj[1])
    kyy = 0.5 * fp * (coef[i, K_YY] + kj[2])
    f = fp + fv
    w = coef[j, HALF_G_AREA] * (coef[i, BETA] * fi + coef[j, BETA] * fj)
    return (rx, ry, f * rx + kxx * rx + kxy * ry, f * ry + kxy * rx + kyy * ry, w,
            m[j] * fi * vr, m[j] / rho[j] * fi)


@njit(inline="always", cache=True)
def _gradient(coef, j, scheme):
    """j's velocity gradient (xx, xy, yx, yy) [s-1] from ``coef`` under "muscl"; zeros for the
    other schemes, whose ``coef`` has no such columns."""
    if scheme == MUSCL:
        return (coef[j, G_XX], coef[j, G_XY], coef[j, G_YX], coef[j, G_YY])
    return (0.0, 0.0, 0.0, 0.0)


@njit(inline="always", cache=True)
def reconstructed_jump(rx, ry, vr, gxx, gxy, gyx, gyy, gj):
    """(v_i* - v_j*) . r [m2 s-1]: the pair's velocity jump with both velocities carried to the
    pair's midpoint along their limited gradients (a MUSCL-type reconstruction in the
    dissipative term only, as in Frontiere, Raskin & Owen 2017, J. Comput. Phys. 332, 160-209,
    and Rosswog 2020, ApJ 898, 60):

        v_i* = v_i - (phi / 2) G_i r,   v_j* = v_j + (phi / 2) G_j r,   r = x_i - x_j,
        (v_i* - v_j*) . r = vr - (phi / 2) (s_i + s_j),   s_k = r . G_k r,
        phi = min(1, 4 A / (1 + A)^2),  A = s_i / s_j > 0  (van Leer's limiter; phi = 0 when
        the two slopes differ in sign),

    G = (gxx, gxy; gyx, gyy) = (du/dx, du/dy; dv/dx, dv/dy) [s-1] being i's and ``gj`` j's
    (``floodsph.sph.velocity_gradient``).
    In a linear velocity field s_i = s_j = vr and the jump vanishes; where the two slopes
    differ (a shock, a front, particle noise) phi falls and the raw jump vr returns. A
    reconstructed jump of the other sign than vr is taken as 0, so that the term never
    feeds the relative motion (its dissipation rate, proportional to - jump * vr, stays >= 0).
    """
    s_i = rx * (gxx * rx + gxy * ry) + ry * (gyx * rx + gyy * ry)
    s_j = rx * (gj[0] * rx + gj[1] * ry) + ry * (gj[2] * rx + gj[3] * ry)
    if s_i * s_j <= 0.0:
        return vr
    a = s_i / s_j
    phi = min(1.0, 4.0 * a / ((1.0 + a) * (1.0 + a)))
    jump = vr - 0.5 * phi * (s_i + s_j)
    return jump if jump * vr > 0.0 else 0.0


@njit(parallel=True, cache=True)
def internal_acceleration(rows, x, y, u, v, m, rho, alpha, h, kxx, kxy, kyy, dudx, dudy, dvdx,
                          dvdy, nstart, nbr, blocked, walls, scheme, sums, ax, ay, divv):
    """a^int and div v of the particles ``rows`` (gather form), mirror images included.

    Listed neighbours beyond the support 2 max(h_i, h_j) are skipped (no force there); pairs
    flagged in ``blocked`` (:func:`floodsph.walls.sight.blocked_pairs`) are left out with
    their images, and a segment's single images skip the neighbours j whose pair support
    2 max(h_i, h_j) does not reach it (``walls.wdist``); ``walls`` is the
    :class:`~floodsph.walls.index.WallLists` of the particles. Images are summed segment by segment,
    each followed by the corners it opens, as in the density summation.

    Row i of ``sums`` (n, ``floodsph.sph.sums.SUMS``) receives particle i's sums of
    :func:`_subtract` (its terms 2-8, then 10-11, as the named columns of
    ``floodsph.sph.sums``), for ``floodsph.sph.shore`` and ``floodsph.sph.consistency``; the
    pressure renormalisation K (kxx, kxy, kyy) is the one the latter set from them at i's
    previous force evaluation. "muscl" reconstructs with the velocity gradient (dudx, dudy,
    dvdx, dvdy) of ``floodsph.sph.velocity_gradient``, current for the particles ``rows``.
    """
    seg, wdist, wstart, wseg, cstart, cpair = walls
    coef = np.empty((x.shape[0], COEF_COLUMNS_MUSCL if scheme == MUSCL else COEF_COLUMNS))
    pair_coefficients(m, rho, alpha, h, kxx, kxy, kyy, dudx, dudy, dvdx, dvdy, coef)
    for k in prange(rows.shape[0]):
        i = rows[k]
        xi = x[i]
        yi = y[i]
        hi = h[i]
        acc = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        h_reach = hi  # the largest h of i and its neighbours: no image beyond 2 h_reach
        for q in range(nstart[i], nstart[i + 1]):
            j = nbr[q]
            rx = xi - x[j]
            ry = yi - y[j]
            h_reach = max(h_reach, h[j])
            hm = 2.0 * max(hi, h[j])
            if rx * rx + ry * ry >= hm * hm or blocked[q]:
                continue
            kj = (coef[j, K_XX], coef[j, K_XY], coef[j, K_YY])
            acc = _subtract(acc, i, j, rho, pair_force(rx, ry, u[i] - u[j], v[i] - v[j], i, j, m,
                                                       rho, h, coef, scheme, kj,
                                                       _gradient(coef, j, scheme)))
        # each near segment's single images, then the corners it opens, in list order; one
        # call site, so that the image terms are compiled once into this kernel
        w = wstart[i]
        c = cstart[i]
        single = True  # segment w's single images still to take
        while w < wstart[i + 1]:
            s = wseg[w]
            s2 = -1
            ds = wdist[w]
            if single:
                single = False
                if ds >= 2.0 * h_reach + SIGHT_SLACK:
                    continue
            elif c < cstart[i + 1] and cpair[c, 0] == s:
                s2 = cpair[c, 1]
                ds = 0.0
                c += 1
            else:
                w += 1
                single = True
                continue
            acc = _subtract_images(acc, i, nstart, nbr, blocked, x, y, u, v, m, rho, h, coef,
                                   seg, s, s2, ds, scheme)
        ax[i] = acc[0]
        ay[i] = acc[1]
        for c in range(7):  # D, E and g M
            sums[i, D_X + c] = acc[2 + c]
        sums[i, MOMENT_X] = acc[10]
        sums[i, MOMENT_Y] = acc[11]
        divv[i] = coef[i, BETA] * acc[9] / rho[i]  # (2 / alpha_i) fd, with beta's fallback


@njit(inline="always", cache=True)
def _subtract(acc, i, j, rho, t):
    """Subtract the terms t = (rx, ry, fx, fy, w, fd, af) of :func:`pair_force` for the pair
    of i and j (or j's image) from i's sums ``acc``, a tuple, with d = rho / rho_w:

    0-1: a^int = - sum (fx, fy) [m s-2];
    2-3: D = - sum w (d_j - d_i) r [m s-2], the hydrostatic pressure force's difference part;
    4-5: E = - sum w r [s-2], its push per metre of i's own depth (a^p = D + d_i E);
    6-8: g M = - sum w r r^T, as xx, xy, yy [s-2] (M = I in a full support);
    9: the divergence sum, - sum fd;
    10-11: e = - sum (m_j / rho_j) F(r, h_i) r [m-1], the first moment of i's own kernel
    gradient, 0 in a full support (``floodsph.sph.consistency``).
    """
    rx, ry, fx, fy, w, fd, af = t
    wd = w * (rho[j] - rho[i]) * (1.0 / RHO_WATER)
    return (acc[0] - fx, acc[1] - fy, acc[2] - wd * rx, acc[3] - wd * ry,
            acc[4] - w * rx, acc[5] - w * ry, acc[6] - w * rx * rx, acc[7] - w * rx * ry,
            acc[8] - w * ry * ry, acc[9] - fd, acc[10] - af * rx, acc[11] - af * ry)


@njit(inline="always", cache=True)
def _subtract_images(acc, i, nstart, nbr, blocked, x, y, u, v, m, rho, h, coef, seg, s, s2, ds,
                     scheme):
    """Subtract from ``acc`` (:func:`_subtract`) the pair terms on particle i of the images of
    i and of its unblocked neighbours about segment s (s2 < 0) or about the corner of s and
    s2 (:func:`_image_state`), i's own image first.

    ``ds`` is the distance [m] from i to segment s (0 for a corner): the image of j about s
    is at least ds - SIGHT_SLACK from i, so for ds >= 2 max(h_i, h_j) + SIGHT_SLACK its pair
    term is zero and is skipped; so is an image that does not apply (its terms are zero).
    The pair term appears once here for every kind of image, and the force kernel calls this
    from one place: with a copy of the pair term for each image kind and each call, the
    kernel's cold compile took 66 s on two cores (``benchmarks/compile_time.py``).
    """
    hi = h[i]
    for q in range(nstart[i] - 1, nstart[i + 1]):
        if q < nstart[i]:  # i's own image
            j = i
            if ds >= 2.0 * hi + SIGHT_SLACK:
                continue
        else:
            j = nbr[q]
            if blocked[q] or ds >= 2.0 * max(hi, h[j]) + SIGHT_SLACK:
                continue
        ok, xm, ym, um, vm, kj = _image_state(i, j, x, y, u, v, coef, seg, s, s2)
        if ok:
            acc = _subtract(acc, i, j, rho, pair_force(x[i] - xm, y[i] - ym, u[i] - um,
                                                       v[i] - vm, i, j, m, rho, h, coef, scheme,
                                                       kj, (0.0, 0.0, 0.0, 0.0), image=j == i))
    return acc


@njit(inline="always", cache=True)
def _image_state(i, j, x, y, u, v, coef, seg, s, s2):
    """(applies, x', y', u', v', K') of j's image as seen from i (MVBP mirror particles,
    ``docs/method.md`` §7).

    About segment s (s2 < 0): position x_j' = 2 f_j - x_j (f_j the foot of j on the wall),
    free-slip velocity v_j' = v_j - 2 (v_j . n) n and renormalisation tensor R K_j R,
    R = I - 2 n n^T; it applies where the wall hides the image's point from i. Through the
    right-angled corner of s and s2: the point reflection, the velocity and K_j reflected
    about both walls' normals in turn (v' = R2 R1 v_j, K' = R2 R1 K_j R1 R2), where
    ``floodsph.walls.images.corner_image`` says it applies.
    """
    if s2 < 0:
        xm, ym, _, nx, ny = mirror(x[j], y[j], seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
        ok = hides(x[i], y[i], xm, ym, seg, s)
        vn = u[j] * nx + v[j] * ny
        um = u[j] - 2.0 * vn * nx
        vm = v[j] - 2.0 * vn * ny
        kj = _reflect(coef[j, K_XX], coef[j, K_XY], coef[j, K_YY], nx, ny)
        return ok, xm, ym, um, vm, kj
    xm, ym, ok = corner_image(x[j], y[j], seg, s, s2)
    _, _, _, n1x, n1y = mirror(x[j], y[j], seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
    _, _, _, n2x, n2y = mirror(x[j], y[j], seg[s2, 0], seg[s2, 1], seg[s2, 2], seg[s2, 3])
    vn = u[j] * n1x + v[j] * n1y
    um = u[j] - 2.0 * vn * n1x
    vm = v[j] - 2.0 * vn * n1y
    vn = um * n2x + vm * n2y
    um -= 2.0 * vn * n2x
    vm -= 2.0 * vn * n2y
    kxx, kxy, kyy = _reflect(coef[j, K_XX], coef[j, K_XY], coef[j, K_YY], n1x, n1y)
    kj = _reflect(kxx, kxy, kyy, n2x, n2y)
    return ok, xm, ym, um, vm, kj


@njit(inline="always", cache=True)
def _reflect(kxx, kxy, kyy, nx, ny):
    """The symmetric tensor K = (kxx, kxy, kyy) reflected about a line of unit normal n:
    R K R with R = I - 2 n n^T."""
    rxx = 1.0 - 2.0 * nx * nx
    rxy = -2.0 * nx * ny
    ryy = 1.0 - 2.0 * ny * ny
    axx = rxx * kxx + rxy * kxy  # A = R K
    axy = rxx * kxy + rxy * kyy
    ayx = rxy * kxx + ryy * kxy
    ayy = rxy * kxy + ryy * kyy
    return axx * rxx + axy * rxy, axx * rxy + axy * ryy, ayx * rxy + ayy * ryy


@njit(parallel=True, cache=True)
def add_bed_acceleration(rows, u, v, bed, max_slope, ax, ay, g_bed=GRAVITY, floor=0.0):
    """Add the bed term of (5) to the internal accelerations of the particles ``rows``:

        a_i <- a_i - max([(g_bed + v.K.v + a_i . grad b) / (1 + |grad b|^2)], floor) grad b.

    ``bed`` is the (n, 7) sample of ``floodsph.sph.bed.sample_bed``. The slope is limited to
    ``max_slope`` in magnitude. The variational force takes g_bed = g and floor = 0 (a
    column cannot be pulled into the bed); the balanced momentum, whose a_i already holds
    -g grad b through the level, takes only the normal-force part, g_bed = 0 and floor = -g
    (``floodsph.sph.level_momentum``; zero at rest).
    """
    for k in prange(rows.shape[0]):
        i = rows[k]
        bx = bed[i, SLOPE_X]
        by = bed[i, SLOPE_Y]
        s = math.sqrt(bx * bx + by * by)
        if s > max_slope:
            bx *= max_slope / s
            by *= max_slope / s
        vkv = (u[i] * (bed[i, CURV_XX] * u[i] + bed[i, CURV_XY] * v[i])
               + v[i] * (bed[i, CURV_XY] * u[i] + bed[i, CURV_YY] * v[i]))
        f = (g_bed + vkv + ax[i] * bx + ay[i] * by) / (1.0 + bx * bx + by * by)
        f = max(f, floor)
        ax[i] -= f * bx
        ay[i] -= f * by
