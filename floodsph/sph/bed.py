"""Bilinear sampling of the terrain grids (bed, slope, curvature, Manning n) at particles.

The grids are node-centred (node (i, j) at x = (j + 0.5) dx, y = (i + 0.5) dy, row 0 south;
see ``floodsph.model.terrain``). Bilinear interpolation reproduces any field that is linear in x and
y within a cell, so the gradient of a paraboloid (linear) and its Hessian (constant) are
sampled exactly; points beyond the outermost nodes take the value on the border (clamped).

Reference: the bed representation is the cheaper alternative to the
SPH bed particles of Vacondio et al. (2013) (``docs/method.md`` §3.5): gradient and
Hessian precomputed once on the static DEM and interpolated to the particles each step.
"""

from __future__ import annotations

import math

from numba import njit, prange

BED, SLOPE_X, SLOPE_Y, CURV_XX, CURV_XY, CURV_YY, MANNING = range(7)
"""The named columns of a bed sample (:func:`sample_bed`): b [m], b_x, b_y [-],
b_xx, b_xy, b_yy [m^-1], Manning's n [s m^-1/3]."""
BED_COLUMNS = 7


@njit(inline="always", cache=True)
def _weights(x, y, dx, dy, nx, ny):
    """Lower-left node (i0, j0) and fractions (tx, ty) in [0, 1] of the bilinear stencil
    around (x, y) [m] on an (ny, nx) node-centred grid of spacing (dx, dy) [m]:
    fx = x / dx - 1/2, j0 = floor(fx), tx = fx - j0 (likewise in y), clamped to the border
    (module docstring)."""
    fx = x / dx - 0.5
    fy = y / dy - 0.5
    j0 = min(max(int(math.floor(fx)), 0), nx - 2)
    i0 = min(max(int(math.floor(fy)), 0), ny - 2)
    tx = min(max(fx - j0, 0.0), 1.0)
    ty = min(max(fy - i0, 0.0), 1.0)
    return i0, j0, tx, ty


@njit(inline="always", cache=True)
def _lerp(g, i0, j0, tx, ty):
    """Bilinear interpolation of grid g (units of g) with the stencil of :func:`_weights`:
    (1 - ty) [(1 - tx) g00 + tx g01] + ty [(1 - tx) g10 + tx g11]."""
    return (
        (1.0 - ty) * ((1.0 - tx) * g[i0, j0] + tx * g[i0, j0 + 1])
        + ty * ((1.0 - tx) * g[i0 + 1, j0] + tx * g[i0 + 1, j0 + 1])
    )


@njit(inline="always", cache=True)
def elevation_at(x, y, dx, dy, grid, nx, ny):
    """Bilinear sample of the (ny, nx) node-centred ``grid`` at one point (x, y) [m]."""
    i0, j0, tx, ty = _weights(x, y, dx, dy, nx, ny)
    return _lerp(grid, i0, j0, tx, ty)


@njit(parallel=True, cache=True)
def sample_bed(rows, x, y, dx, dy, bed, bx, by, bxx, bxy, byy, manning, out):
    """Sample the seven bed grids at the particles ``rows`` into their rows of ``out``
    (n, ``BED_COLUMNS``), in the named columns ``BED`` ... ``MANNING``."""
    ny, nx = bed.shape
    for k in prange(rows.shape[0]):
        p = rows[k]
        i0, j0, tx, ty = _weights(x[p], y[p], dx, dy, nx, ny)
        out[p, BED] = _lerp(bed, i0, j0, tx, ty)
        out[p, SLOPE_X] = _lerp(bx, i0, j0, tx, ty)
        out[p, SLOPE_Y] = _lerp(by, i0, j0, tx, ty)
        out[p, CURV_XX] = _lerp(bxx, i0, j0, tx, ty)
        out[p, CURV_XY] = _lerp(bxy, i0, j0, tx, ty)
        out[p, CURV_YY] = _lerp(byy, i0, j0, tx, ty)
        out[p, MANNING] = _lerp(manning, i0, j0, tx, ty)
