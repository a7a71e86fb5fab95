"""Well-balanced shores: the pressure force at the edge of the water on a rising bed.

The hydrostatic part of the variational pressure force (``floodsph.sph.forces``) splits into
a difference part and a push by the particle's own depth (sums of
``floodsph.sph.forces._subtract``, d = rho / rho_w):

    a_i^p = D_i + d_i E_i,   D_i = - sum_j w_ij (d_j - d_i) r_ij,   E_i = - sum_j w_ij r_ij,
    w_ij = (g / 2) (m_j / rho_j) (beta_i F_ij(h_i) + beta_j F_ij(h_j)),  F = (1/r) dW/dr.

In a full kernel support E_i = 0 and D_i = -g M_i grad d with M_i = -(1/g) sum w r r^T = I.
Where the support is cut by the edge of the water, E_i pushes outwards and M_i < I. On a flat
bed that push is what drives a wet/dry front (Ritter's dam break). At the shore of a lake it
is wrong: the water ends because the bed rises through its surface, the true depth falls to
zero, and the push together with the cut-down D_i cannot balance the bed's pull -g grad b, so
the shore slid down the slope (0.27 m s-2 on the 2.8 % bowl of
``tests/sph/test_sph_dynamics.py``).

The push is therefore limited by the hydrostatic reconstruction of Audusse, Bouchut, Bristeau,
Klein & Perthame (SIAM J. Sci. Comput. 25 (2004) 2050-2065) across the edge: the water at i
can push only with the depth its head stands above the bed beyond the edge,

    d_i* = min(max(d_i + (v_i . e_i)+^2 / (2 g) + b_i - b(x_i + h_i e_i), 0), d_i),
    e_i = E_i / |E_i|,

the bed sampled one smoothing length beyond i in the push's direction (about a particle
spacing: the neighbouring cell of the finite-volume reconstruction), and the head raised by
the run-up height (v . e)^2 / (2 g) of water moving towards the edge (Bernoulli), so that a
front running over a bump keeps its push while still water (v = 0) is balanced. Measured on
the sample valley's dam break against ANUGA's maximum-depth map (``benchmarks/
versus_grid_code.py``, CSI at 0.1 m, kappa = 1.3; 0.958 with no balance): 0.959 as here,
0.957 without the run-up height, 0.949 with the bed sampled at 2 h_i (bumps ahead stopped
thin fronts); 0.972 as here with the default kappa = 1.2.

Where the push is cut the difference part is renormalised (the corrected gradient of Bonet &
Lok, Comput. Methods Appl. Mech. Engrg. 180 (1999) 97-115) in the same proportion,
gamma_i = 1 - d_i* / d_i:

    a_i^p <- a_i^p - (d_i - d_i*) E_i + gamma_i (M_i^-1 - I) D_i,

so that at a lake's shore (d_i* = 0) the force is -g grad d, which balances -g grad b. On a
flat bed, and wherever the bed beyond the edge lies lower (a front running downhill),
d_i* = d_i and the force is the variational one, which conserves momentum. Supports too
empty to renormalise (det M_i < ``DET_MIN``) keep D_i. Particles with a full support,
|E_i| h_i / g < ``FULL_SUPPORT`` (in the dam break of ``benchmarks/speed_vs_error.py``'s
throughput block: below 0.0023 for nine particles in ten, 0.14 for the top one in a hundred,
at its edges), are left as they are: there E_i and M_i - I vanish. The same correction is
applied with the Riemann pressure option, whose still-water pressure is the hydrostatic one.

Units: accelerations [m s-2], E [s-2], d, b, h, x [m].
"""

from __future__ import annotations

import math

from numba import njit, prange

from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.sph.bed import BED, elevation_at
from floodsph.sph.sums import D_X, D_Y, E_X, E_Y, GM_XX, GM_XY, GM_YY

DET_MIN = 0.02  # det M below which a particle's support is too empty to renormalise D
FULL_SUPPORT = 0.01  # |E| h / g below which a support counts as full: not at an edge


@njit(inline="always", cache=True)
def moment_matrix(sums, i):
    """(M_xx, M_xy, M_yy, det M) [-] of particle i, from the g M of its ``sums``
    (``floodsph.sph.sums``)."""
    mxx = sums[i, GM_XX] / GRAVITY
    mxy = sums[i, GM_XY] / GRAVITY
    myy = sums[i, GM_YY] / GRAVITY
    return mxx, mxy, myy, mxx * myy - mxy * mxy


@njit(parallel=True, cache=True)
def balance_shores(rows, x, y, u, v, rho, h, bed, dx, dy, elevation, sums, walled, ax, ay):
    """Correct a^int (``ax``, ``ay``) of the particles ``rows`` at shores (module docstring).

    ``sums`` holds their D, E and g M (``floodsph.sph.sums``); velocities u, v [m s-1];
    ``bed`` is the sample of ``floodsph.sph.bed.sample_bed`` (column ``BED``, b_i [m]);
    ``elevation`` the node-centred DEM grid with spacings dx, dy [m]; particles flagged in
    ``walled`` are left alone (their force is the wall's,
    ``floodsph.sph.shadow.balance_walls``).
    """
    ny, nx = elevation.shape
    for k in prange(rows.shape[0]):
        i = rows[k]
        if walled[i]:
            continue
        ex = sums[i, E_X]
        ey = sums[i, E_Y]
        e = math.sqrt(ex * ex + ey * ey)
        if e * h[i] < FULL_SUPPORT * GRAVITY:
            continue
        d = rho[i] / RHO_WATER
        reach = h[i] / e
        b_out = elevation_at(x[i] + reach * ex, y[i] + reach * ey, dx, dy, elevation, nx, ny)
        ve = max(u[i] * ex + v[i] * ey, 0.0) / e
        cut = d - min(max(d + 0.5 * ve * ve / GRAVITY + bed[i, BED] - b_out, 0.0), d)
        if cut <= 0.0:
            continue
        ax[i] -= cut * ex
        ay[i] -= cut * ey
        mxx, mxy, myy, det = moment_matrix(sums, i)
        if det < DET_MIN:
            continue
        gamma = cut / d
        dpx = sums[i, D_X]
        dpy = sums[i, D_Y]
        ax[i] += gamma * ((myy * dpx - mxy * dpy) / det - dpx)
        ay[i] += gamma * ((mxx * dpy - mxy * dpx) / det - dpy)
