"""SPH fields at arbitrary points (gauges, error norms, profiles).

Shepard-normalised SPH interpolation of the particles' depth and velocity, with V_j = m_j/rho_j:

    f(x) = sum_j V_j f_j W(|x - x_j|, h_j) / sum_j V_j W(|x - x_j|, h_j),  f = d, u, v

(Shepard 1968; the normalised SPH interpolant, e.g. Monaghan, Rep. Prog. Phys. 68 (2005)
1703-1759). The normalisation removes the ripples that the raw sum sum_j m_j W / rho_w shows
between rows of particles once a flow has stretched them apart further than h, and keeps still
water at its depth up to a wall; mirror images across walls (``floodsph.sph.walls``) are
included as in the solver's density. A point is dry (depth 0, velocity NaN) where no particle's
support reaches it. Units: d [m], velocity [m s-1].
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from floodsph.constants import RHO_WATER
from floodsph.sph.kernels import w_cubic
from floodsph.sph.neighbours import CellGrid
from floodsph.sph.walls import crosses, segment_distance, wall_image


@njit(parallel=True, cache=True)
def _field(qx, qy, x, y, u, v, m, rho, h, cell_start, order, xmin, ymin, cell, ncx, ncy, seg,
           out):
    for k in prange(qx.shape[0]):
        px = qx[k]
        py = qy[k]
        cx = min(max(int((px - xmin) / cell), 0), ncx - 1)
        cy = min(max(int((py - ymin) / cell), 0), ncy - 1)
        dsum = 0.0
        wsum = 0.0
        usum = 0.0
        vsum = 0.0
        for gy in range(max(cy - 1, 0), min(cy + 2, ncy)):
            for gx in range(max(cx - 1, 0), min(cx + 2, ncx)):
                c = gy * ncx + gx
                for s in range(cell_start[c], cell_start[c + 1]):
                    j = order[s]
                    sep = False
                    for w in range(seg.shape[0]):
                        if crosses(px, py, x[j], y[j], seg[w, 0], seg[w, 1], seg[w, 2], seg[w, 3]):
                            sep = True
                            break
                    if sep:
                        continue
                    wk = w_cubic(np.hypot(px - x[j], py - y[j]), h[j])
                    for w in range(seg.shape[0]):
                        if segment_distance(px, py, seg[w, 0], seg[w, 1], seg[w, 2],
                                            seg[w, 3]) < 2.0 * h[j]:
                            xm, ym, ok = wall_image(px, py, x[j], y[j], seg, w)
                            if ok:
                                wk += w_cubic(np.hypot(px - xm, py - ym), h[j])
                    vol = m[j] / rho[j] * wk
                    dsum += vol * rho[j]
                    wsum += vol
                    usum += vol * u[j]
                    vsum += vol * v[j]
        out[k, 0] = dsum / (RHO_WATER * wsum) if wsum > 0.0 else 0.0
        out[k, 1] = usum / wsum if wsum > 0.0 else np.nan
        out[k, 2] = vsum / wsum if wsum > 0.0 else np.nan


def sample_field(model_or_particles, qx, qy, seg=None) -> np.ndarray:
    """Depth [m] and Shepard velocity (u, v) [m s-1] at points (qx, qy), shape (k, 3).

    Accepts a ``FloodModel`` (its walls are used) or a ``ParticleSet`` with ``seg`` given.
    Velocity is NaN where no particle reaches.
    """
    p = getattr(model_or_particles, "particles", model_or_particles)
    if seg is None:
        seg = getattr(model_or_particles, "seg", np.zeros((0, 4)))
    qx = np.ascontiguousarray(qx, dtype=np.float64).ravel()
    qy = np.ascontiguousarray(qy, dtype=np.float64).ravel()
    out = np.zeros((qx.size, 3))
    if p.n == 0:
        out[:, 1:] = np.nan
        return out
    grid = CellGrid(p.x, p.y, 2.0 * float(p.h.max()))
    _field(qx, qy, p.x, p.y, p.u, p.v, p.m, p.rho, p.h, *grid.arrays(),
           np.ascontiguousarray(seg, dtype=np.float64).reshape(-1, 4), out)
    return out
