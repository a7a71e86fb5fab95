"""The pair sums: what the force loop leaves per particle for the shore balance and the
pressure renormalisation, as named columns of one (n, SUMS) array.

``floodsph.sph.forces.internal_acceleration`` writes row i, with w the pair weight of the
hydrostatic pressure term, r = x_i - x_j and d = rho / rho_w (``docs/method.md`` §3.1, §4):

* ``D_X``, ``D_Y``: D = - sum w (d_j - d_i) r [m s-2], the pressure force's difference part;
* ``E_X``, ``E_Y``: E = - sum w r [s-2], its push per metre of i's own depth
  (a^p = D + d_i E);
* ``GM_XX``, ``GM_XY``, ``GM_YY``: g M = - sum w r r^T [s-2] (M = I in a full support);
* ``MOMENT_X``, ``MOMENT_Y``: e = - sum (m_j / rho_j) F(r, h_i) r [m-1], the first moment of
  i's own kernel gradient, 0 in a full support.

``floodsph.sph.shore`` reads D, E and g M; ``floodsph.sph.consistency`` reads E, g M and e.
"""

D_X, D_Y, E_X, E_Y, GM_XX, GM_XY, GM_YY, MOMENT_X, MOMENT_Y = range(9)
SUMS = 9
"""Columns of the pair sums."""
