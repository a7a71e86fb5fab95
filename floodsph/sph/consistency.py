"""Pressure renormalisation: a consistent pressure gradient where the flow has distorted the
particle lattice.

In a full kernel support the hydrostatic pressure force of ``floodsph.sph.forces`` is
(``floodsph.sph.shore``) a_i^p = D_i = - sum_j w_ij (d_j - d_i) r_ij = -g M_i grad d, with

    M_i = -(1/g) sum_j w_ij r_ij r_ij^T,
    w_ij = (g/2) (m_j/rho_j) (beta_i F(r_ij, h_i) + beta_j F(r_ij, h_j)),  F = (1/r) dW/dr,

and M_i = I on the square lattice the water is seeded on. Where the flow stretches the
lattice (a rarefaction pulls its rows apart along the flow), M_i leaves I and the force along
the stretch is too weak: in Ritter's dam break at 10 m spacing and kappa = 1.2, M_xx = 0.99 at
600 m, 0.97 at 920 m and 0.66 at 1100 m (h = 2 dx there). The stretch is the same at every
spacing for a given kappa, and so is the error it leaves: the depth was 0.09 m too deep at
740 m and 0.11 m too shallow at 920 m at 10, 5 and 2.5 m alike, and it capped the observed
order of convergence.

The pressure part f_ij r_ij of each pair force is therefore renormalised, in the manner of the
corrected gradient of Bonet & Lok (Comput. Methods Appl. Mech. Engrg. 180 (1999) 97-115),
with the mean of the pair's two corrections, so that the pair force stays antisymmetric and
linear momentum is conserved exactly:

    f_ij r_ij  ->  f_ij (I + (K_i + K_j) / 2) r_ij,   K_i = (M_i / sqrt(det M_i))^-1 - I.

Only M's shape is corrected, not its size (M / sqrt(det M) has det 1): where h varies over an
undistorted lattice (a lake over a bump) M_i = c I with c != 1, and the variational force's
other part, d_i E_i, already balances it; correcting c as well stirred the lake over the
Gaussian bump of ``tests/sph/test_sph_dynamics.py`` to 0.015 m/s in 200 s (0.004 m/s without
any renormalisation, 0.008 m/s with this one).

K_i = 0 where i's own kernel support is cut, |e_i| h_i >= ``EDGE`` with
e_i = - sum_j (m_j/rho_j) F(r_ij, h_i) r_ij (0 in a full support, of order 1/h at an edge:
fronts and shores), and where M_i is near singular (det M_i < ``DET_MIN``). On a bed that is
not flat, K_i = 0 also where the shore balance may act (|E_i| h_i / g >=
``floodsph.sph.shore.FULL_SUPPORT``, E_i the pair sum of that module): renormalised there,
the shore of the parabolic bowl of ``tests/sph/test_shore.py`` moved at 0.28 m/s after 200 s
(0.08 m/s without). E_i alone cannot tell edges: h's own gradient makes it as large in a
stretched rarefaction as at a front. With ``EDGE`` = 0.1, between the median 0.0005 of
Ritter's rarefaction at 600-740 m and the 0.09 of its 60 front-most particles (10 m), the
uniform Ritter L1 error at 10 / 5 / 2.5 m went from 2.32 / 1.42 / 1.01 % to
1.92 / 0.96 / 0.74 %. Cut off by |E_i| h_i / g instead (at 0.01 or 0.003), the correction
missed most of the stretched region: 2.22 % at 10 m, 0.95 % at 2.5 m.

K_i is set from the sums of i's force evaluation and used at its next one (one step behind:
M changes by the particles' motion in a step, at most cfl h). New particles start with K = 0.
A wall image carries its particle's K reflected with it. The shock-capturing term is not
renormalised.

Units: K, M [-]; e [m-1]; sums as in ``floodsph.sph.forces._subtract`` (g M [s-2]); h [m].
"""

from __future__ import annotations

import math

from numba import njit, prange

from floodsph.constants import GRAVITY
from floodsph.sph.shore import FULL_SUPPORT, moment_matrix
from floodsph.sph.sums import E_X, E_Y, MOMENT_X, MOMENT_Y

EDGE = 0.1  # |e| h at and above which i's own support counts as cut: no renormalisation
DET_MIN = 0.5  # det M below which a support is too distorted to renormalise


@njit(parallel=True, cache=True)
def update_renormalisation(rows, h, sums, shores, kxx, kxy, kyy):
    """Set K = (M / sqrt(det M))^-1 - I (kxx, kxy, kyy) of the particles ``rows`` from their
    sums (E, g M and e of ``floodsph.sph.sums``);
    K = 0 where the support is cut, with ``shores`` (a bed that is not flat) also where the
    shore balance may act, and where det M < ``DET_MIN`` (module docstring)."""
    for k in prange(rows.shape[0]):
        i = rows[k]
        kxx[i] = 0.0
        kxy[i] = 0.0
        kyy[i] = 0.0
        if math.hypot(sums[i, MOMENT_X], sums[i, MOMENT_Y]) * h[i] >= EDGE:
            continue
        if shores and math.hypot(sums[i, E_X], sums[i, E_Y]) * h[i] >= FULL_SUPPORT * GRAVITY:
            continue
        mxx, mxy, myy, det = moment_matrix(sums, i)
        if det < DET_MIN:
            continue
        s = math.sqrt(det)
        kxx[i] = myy / s - 1.0
        kxy[i] = -mxy / s
        kyy[i] = mxx / s - 1.0
