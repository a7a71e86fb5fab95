"""The velocity gradient of each particle, exact for a linear velocity field.

The renormalised SPH gradient (Randles & Libersky 1996, Comput. Methods Appl. Mech. Engrg.
139, 375-408; Bonet & Lok 1999, ibid. 180, 97-115) of the depth-averaged velocity v = (u, v):

    G_i = [sum_j V_j (v_j - v_i) (grad_i W_ij)^T] L_i,    L_i = (sum_j V_j (x_j - x_i)
                                                                  (grad_i W_ij)^T)^-1,

with V_j = m_j / rho_j [m2], grad_i W_ij = F(r_ij, h_i) r_ij, F = (1/r) dW/dr and
r_ij = x_i - x_j. The correction L_i makes G_i exact for any linear field, however few the
neighbours or however disordered (at a front, a wall, after a split), where the plain sum falls
short. A particle whose neighbours do not span the plane (det of L_i^-1 below ``DET_MIN`` of a
full support's) gets G_i = 0. Mirror images are left out: L_i corrects for the truncated
support instead.

G = (du/dx, du/dy; dv/dx, dv/dy) [s-1] is what the "muscl" stabilisation
(``floodsph.sph.forces.reconstructed_jump``) carries velocities to a pair's midpoint with.
"""

from __future__ import annotations

import math

from numba import njit, prange

from floodsph.sph.kernels import dwdr_over_r_cubic

DET_MIN = 0.05
"""Smallest det(L^-1), relative to its value 1 in a full support, that is inverted."""


@njit(parallel=True, cache=True)
def velocity_gradient(rows, x, y, u, v, m, rho, h, nstart, nbr, blocked, dudx, dudy, dvdx,
                      dvdy):
    """Write G_i (module docstring) of the particles ``rows`` into (dudx, dudy, dvdx, dvdy).

    Gather form over i's neighbour list (``nstart``, ``nbr``); pairs beyond i's support 2 h_i
    and pairs flagged in ``blocked`` (a wall between them) are left out.
    """
    for k in prange(rows.shape[0]):
        i = rows[k]
        inv_h = 1.0 / h[i]
        reach2 = 4.0 * h[i] * h[i]
        # B = sum V_j (v_j - v_i) F r^T and A = L^-1 = sum V_j (x_j - x_i) F r^T = -sum V F r r^T
        bxx = bxy = byx = byy = 0.0
        axx = axy = ayy = 0.0
        for q in range(nstart[i], nstart[i + 1]):
            j = nbr[q]
            rx = x[i] - x[j]
            ry = y[i] - y[j]
            r2 = rx * rx + ry * ry
            if r2 >= reach2 or r2 <= 0.0 or blocked[q]:
                continue
            r = math.sqrt(r2)
            vf = m[j] / rho[j] * dwdr_over_r_cubic(r, 1.0 / r, inv_h)
            du = u[j] - u[i]
            dv = v[j] - v[i]
            bxx += vf * du * rx
            bxy += vf * du * ry
            byx += vf * dv * rx
            byy += vf * dv * ry
            axx -= vf * rx * rx
            axy -= vf * rx * ry
            ayy -= vf * ry * ry
        det = axx * ayy - axy * axy
        if det < DET_MIN:
            dudx[i] = 0.0
            dudy[i] = 0.0
            dvdx[i] = 0.0
            dvdy[i] = 0.0
            continue
        # L = A^-1 (A symmetric)
        lxx = ayy / det
        lxy = -axy / det
        lyy = axx / det
        dudx[i] = bxx * lxx + bxy * lxy
        dudy[i] = bxx * lxy + bxy * lyy
        dvdx[i] = byx * lxx + byy * lxy
        dvdy[i] = byx * lxy + byy * lyy
