"""SPH interpolation of particle depth and velocity onto map cells or gauge points.

At a point x the Shepard-normalised (Shepard 1968) SPH estimate of a field f is

    f(x) = sum_j V_j f_j W(|x - x_j|, h_j) / S(x),     S(x) = sum_j V_j W(|x - x_j|, h_j),

with V_j = m_j / rho_j [m2] the area a particle represents, W the 2-D cubic spline
(:func:`floodsph.sph.kernels.w_cubic`, support 2 h_j) and f = d = rho / RHO_WATER [m],
u or v [m/s]. Normalisation makes a uniform field exact however the particles are placed.

Extent. Since V_j d_j = m_j / RHO_WATER, the numerator for depth is the plain SPH depth sum
sum_j m_j W / RHO_WATER, which falls smoothly to zero across the water's edge; the Shepard
depth instead keeps the depth of the nearest particles out to 2h beyond them, which would
paint a band of full-depth water up to two smoothing lengths outside the real shoreline. The
kernel sum S is the fraction of the kernel support covered by water: about 1 inside the
water (the density solve makes rho_i = sum_j m_j W_ij), 1/2 on the straight edge of a
uniform water body, 0 far away. Cells with ``S < min_support`` (default 0.5) are therefore
left unsupported (NaN): the mapped extent follows the half-support contour, which is where
the edge of the area the particles stand for lies, and inside it the depth is the exact
Shepard value. An isolated particle (S <= 10 / (7 pi kappa^2) ~ 0.32 for kappa = 1.2) is
not mapped: it carries a negligible volume.

Walls. A wall hides the water behind it: a particle adds nothing to a point that one of
its near wall segments hides from it (:func:`floodsph.walls.sight.hides`, the test of the
solver's pair blocking), given as a :class:`floodsph.walls.index.MapWalls`
(``FloodModel.map_walls``). Without it the kernel reaches across a levee into the cells
behind it wherever the water's half-support contour passes the wall.

Nodata. Cells without data (``OutputGrid.valid``) hold no water in the maps. The walled
nodata border runs through nodata cells, whose slivers are wet area for the solver, but a
map cell there has no ground: Malpasset's reservoir at rest painted 211 such cells (3.9 m
deep at the median) along its banks.

The loop gathers over the target points (iteration k writes only the sums of point k), so it
is race-free under ``prange``. Particles are binned with
:class:`floodsph.sph.cells.CellGrid` by the levels of h of the neighbour search
(:func:`floodsph.sph.neighbours.h_levels`: level 0 up to 1.25 median h, then factors of
2), each level in cells of twice its largest h, so that particles with a large h do not
inflate the cell size for all; each level is searched in the 3 x 3 cells around the point,
which hold every particle of it whose support reaches the point. (Two groups, split at twice
the mean h and merged into one when more than 5 % were above it, made a Malpasset map update
take 169 ms late in the run, with 8 % of the particles above and h up to ten times h0.)

A map grid is a regular lattice, so :func:`rasterise` gathers by bands of ``BAND_ROWS`` rows
instead (:func:`grid_sums`): a particle is listed in every band its support reaches, and
within a band each listed particle adds to the cells of the box around its support, about
4 / pi times the cells it reaches, where the point gather over 3 x 3 bins of twice the
largest h of a level tests three to ten times as many pairs. A band is owned by one
parallel iteration, which writes only that band's rows, so there are no races. (On EA test 4
at 10 m, where the envelopes are updated at nearly every step, the point gather took two
thirds of the run.)
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import njit, prange
from scipy import ndimage

from floodsph.constants import RHO_WATER
from floodsph.sph.cells import CellGrid
from floodsph.sph.kernels import w_cubic
from floodsph.sph.neighbours import LEVEL_BASE, h_levels
from floodsph.walls.index import MapWalls
from floodsph.walls.sight import hides


def _walls_for(walls: MapWalls | None, n: int) -> MapWalls:
    """``walls``, or lists with no segment for the n particles."""
    if walls is None:
        return MapWalls(np.zeros((0, 4)), np.zeros(n + 1, dtype=np.int64),
                        np.zeros(0, dtype=np.int64))
    return walls


@njit(inline="always", cache=True)
def _hidden(xj, yj, px, py, seg, near):
    """True if one of the segments ``near`` (rows of ``seg``) hides the point (px, py) from a
    particle at (xj, yj)."""
    for s in near:
        if hides(xj, yj, px, py, seg, s):
            return True
    return False


MIN_SUPPORT = 0.5
"""Default minimum kernel sum S = sum_j V_j W for a point to be mapped (see module doc)."""
BAND_ROWS = 4
"""Map rows per band of :func:`grid_sums` (the unit of work of one thread)."""


@njit(parallel=True, cache=True)
def accumulate_sums(px, py, x, y, h, vol, d, u, v, index, seg, wstart, wseg, cell_start, order,
                    xmin, ymin, cell, ncx, ncy, sums):
    """Add sum_j V_j W (1, d_j, u_j, v_j) at every point (px[k], py[k]) into ``sums[k, :]``,
    over the particles no wall hides it from (their near segments ``wseg[wstart[i]:wstart[i +
    1]]`` of ``seg``, i = ``index[j]`` their index in the lists).

    Every particle of the binned group must have 2 h_j <= ``cell``; the 3 x 3 cells around
    the point then hold all particles whose support reaches it.
    """
    for k in prange(px.shape[0]):
        xk = px[k]
        yk = py[k]
        cx = int(math.floor((xk - xmin) / cell))
        cy = int(math.floor((yk - ymin) / cell))
        if cx < -1 or cy < -1 or cx > ncx or cy > ncy:
            continue
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        s3 = 0.0
        for gy in range(max(cy - 1, 0), min(cy + 2, ncy)):
            for gx in range(max(cx - 1, 0), min(cx + 2, ncx)):
                c = gy * ncx + gx
                for s in range(cell_start[c], cell_start[c + 1]):
                    j = order[s]
                    rx = xk - x[j]
                    ry = yk - y[j]
                    r = math.sqrt(rx * rx + ry * ry)
                    if r < 2.0 * h[j]:
                        i = index[j]
                        if wstart[i + 1] > wstart[i] and _hidden(
                                x[j], y[j], xk, yk, seg, wseg[wstart[i]:wstart[i + 1]]):
                            continue
                        w = vol[j] * w_cubic(r, h[j])
                        s0 += w
                        s1 += w * d[j]
                        s2 += w * u[j]
                        s3 += w * v[j]
        sums[k, 0] += s0
        sums[k, 1] += s1
        sums[k, 2] += s2
        sums[k, 3] += s3


def kernel_sums(px, py, x, y, u, v, m, rho, h, level=None,
                walls: MapWalls | None = None) -> np.ndarray:
    """(n_points, 4) array of sum_j V_j W times (1, d_j, u_j, v_j) at the points [-, m, m/s];
    with ``level`` the particles' levels eta_j [m] take the place of d_j; ``walls`` hide
    points from particles (module docstring)."""
    px = np.ascontiguousarray(px, dtype=np.float64)
    py = np.ascontiguousarray(py, dtype=np.float64)
    sums = np.zeros((px.shape[0], 4), dtype=np.float64)
    if x.shape[0] == 0 or px.shape[0] == 0:
        return sums
    vol = m / rho
    d = rho / RHO_WATER if level is None else level
    seg, wstart, wseg = _walls_for(walls, x.shape[0])
    h_level = np.empty(x.shape[0], dtype=np.int64)
    lv_hmax, box = h_levels(x, y, h, LEVEL_BASE * float(np.median(h)), h_level)
    for lv in np.flatnonzero(lv_hmax > 0.0):
        group = h_level == lv
        index = np.flatnonzero(group)
        gx, gy, gh = x[group], y[group], h[group]
        grid = CellGrid(gx, gy, 2.0 * float(lv_hmax[lv]), tuple(box[lv]))
        k = np.flatnonzero(_reached(px, py, grid))
        part = np.zeros((k.size, 4), dtype=np.float64)
        accumulate_sums(px[k], py[k], gx, gy, gh, vol[group], d[group], u[group], v[group],  # type: ignore[call-arg]  # numba
                        index, seg, wstart, wseg, *grid.arrays(), part)
        sums[k] += part
    return sums


def _reached(px, py, grid: CellGrid) -> np.ndarray:
    """True for the points with a particle in the 3 x 3 cells around them: the only points
    :func:`accumulate_sums` can add to (a map grid is mostly dry, so the rest are skipped)."""
    cell_start, _, xmin, ymin, cell, ncx, ncy = grid.arrays()
    filled = np.zeros((ncy + 2, ncx + 2), dtype=bool)
    filled[1:-1, 1:-1] = (np.diff(cell_start) > 0).reshape(ncy, ncx)
    near = ndimage.binary_dilation(filled, structure=np.ones((3, 3), dtype=bool))
    cx = np.floor((px - xmin) / cell) + 1.0
    cy = np.floor((py - ymin) / cell) + 1.0
    inside = (cx >= 0) & (cx <= ncx + 1) & (cy >= 0) & (cy <= ncy + 1)
    out = np.zeros(px.shape, dtype=bool)
    out[inside] = near[cy[inside].astype(np.int64), cx[inside].astype(np.int64)]
    return out


def interpolate(px, py, x, y, u, v, m, rho, h, min_support: float = MIN_SUPPORT, level=None,
                bed=None, walls: MapWalls | None = None):
    """Shepard SPH depth d [m] and velocity (u, v) [m/s] at points (px, py) (local metres).

    With the particles' free-surface levels ``level`` [m] (the balanced momentum's,
    ``floodsph.model.flood_model.FloodModel.surface_levels``) and the bed ``bed`` [m] at the
    points, the depth is the Shepard level less the bed, max(eta(x) - b(x), 0): a lake at
    rest then maps at its level exactly, where the summed depth would show its smoothing.

    Parameters
    ----------
    px, py : float arrays
        Target points in the terrain's local coordinates [m].
    x, y, u, v, m, rho, h : float64 arrays
        Active particles: position [m], velocity [m/s], mass [kg], areal density [kg/m2],
        smoothing length [m].
    min_support : float
        Points with kernel sum S = sum_j V_j W below this are unsupported (NaN).
    walls : MapWalls or None
        Walls that hide points from particles (module docstring); None: no wall.

    Returns
    -------
    d, u, v, support : float64 arrays shaped like ``px``; NaN where unsupported.
    """
    sums = kernel_sums(np.ravel(px), np.ravel(py), x, y, u, v, m, rho, h, level, walls)
    d, u, v, support = _shepard(sums, min_support, np.shape(px))
    return _depth_below(d, level, bed), u, v, support


def rasterise(grid, x, y, u, v, m, rho, h, min_support: float = MIN_SUPPORT, level=None,
              walls: MapWalls | None = None):
    """Depth d [m] and velocity (u, v) [m/s] on an :class:`OutputGrid` (row 0 = south).

    The values of :func:`interpolate` at the cell centres (with ``level``, less the grid's
    bed; ``walls`` hiding cells from particles), summed by :func:`grid_sums`, NaN in the
    grid's cells without data (``OutputGrid.valid``); returns ``(d, u, v, support)``, each
    ``grid.shape``.
    """
    xc, yc = grid.cell_centres()
    sums = np.zeros((yc.shape[0], xc.shape[0], 4), dtype=np.float64)
    if x.shape[0]:
        band_start, band_items = band_lists(yc, y, h, BAND_ROWS)
        seg, wstart, wseg = _walls_for(walls, x.shape[0])
        grid_sums(xc, yc, x, y, h, m / rho, rho / RHO_WATER if level is None else level, u, v,
                  seg, wstart, wseg, band_start, band_items, BAND_ROWS,
                  numba.get_num_threads(), sums)
    d, u, v, support = _shepard(sums.reshape(-1, 4), min_support, grid.shape)
    if grid.valid is not None:  # no water over nodata (OutputGrid)
        for field in (d, u, v):
            field[~grid.valid] = np.nan
    return _depth_below(d, level, None if level is None else grid.bed), u, v, support


def _depth_below(d, level, bed):
    """The mapped depth [m]: ``d`` as it is, or with levels, the Shepard level ``d`` less the
    bed, never below 0 (NaN stays NaN)."""
    if level is None:
        return d
    return np.where(np.isnan(d), np.nan, np.maximum(d - bed, 0.0))


def _shepard(sums, min_support: float, shape):
    """(d, u, v, support) from kernel sums (n, 4): NaN where the support is short (or 0)."""
    fields = np.empty((3, sums.shape[0]))
    shepard_divide(sums, min_support, fields)
    return (fields[0].reshape(shape), fields[1].reshape(shape), fields[2].reshape(shape),
            sums[:, 0].reshape(shape))


@njit(parallel=True, cache=True)
def shepard_divide(sums, min_support, fields):
    """fields[c, k] = sums[k, c + 1] / sums[k, 0] (c = 0, 1, 2: d, u, v) where the kernel sum
    S = sums[k, 0] is at least ``min_support`` and positive; NaN elsewhere."""
    for k in prange(sums.shape[0]):
        support = sums[k, 0]
        ok = support >= min_support and support > 0.0
        for c in range(3):
            fields[c, k] = sums[k, c + 1] / support if ok else np.nan


@njit(cache=True)
def _span(c, reach, first, step, n):
    """Index range [lo, hi] of the lattice first + k step (k < n) within ``reach`` of c, with a
    margin of one index (the caller tests the distance); lo > hi if there is none."""
    lo = max(int(math.floor((c - reach - first) / step)), 0)
    hi = min(int(math.ceil((c + reach - first) / step)), n - 1)
    return lo, hi


@njit(cache=True)
def band_lists(yc, y, h, band_rows):
    """CSR lists (start, items) of the particles whose support 2 h_j reaches each band of
    ``band_rows`` map rows (row centres ``yc``, evenly spaced)."""
    ny = yc.shape[0]
    dy = yc[1] - yc[0] if ny > 1 else 1.0
    nbands = (ny + band_rows - 1) // band_rows
    start = np.zeros(nbands + 1, dtype=np.int64)
    for j in range(y.shape[0]):
        lo, hi = _span(y[j], 2.0 * h[j], yc[0], dy, ny)
        if lo > hi:
            continue
        for b in range(lo // band_rows, hi // band_rows + 1):
            start[b + 1] += 1
    for b in range(nbands):
        start[b + 1] += start[b]
    items = np.empty(start[nbands], dtype=np.int64)
    fill = start[:-1].copy()
    for j in range(y.shape[0]):
        lo, hi = _span(y[j], 2.0 * h[j], yc[0], dy, ny)
        if lo > hi:
            continue
        for b in range(lo // band_rows, hi // band_rows + 1):
            items[fill[b]] = j
            fill[b] += 1
    return start, items


@njit(parallel=True, cache=True)
def grid_sums(xc, yc, x, y, h, vol, d, u, v, seg, wstart, wseg, band_start, band_items,
              band_rows, chunks, sums):
    """Add sum_j V_j W(|x_cell - x_j|, h_j) (1, d_j, u_j, v_j) into ``sums[row, col, :]`` for
    every cell of the lattice (column centres ``xc``, row centres ``yc``, evenly spaced) that
    none of particle j's near wall segments (``wseg[wstart[j]:wstart[j + 1]]``, rows of
    ``seg``) hides from it.

    Gather form over row bands, race-free: parallel iteration c (of ``chunks``, one per
    thread) owns the bands b = c, c + chunks, ... (interleaved, which balances a flood
    covering a few bands) and writes only their rows; within a band the particles of
    ``band_lists`` add to the cells of their support box in index order, so the result does
    not depend on the number of threads.
    """
    nx = xc.shape[0]
    ny = yc.shape[0]
    dx = xc[1] - xc[0] if nx > 1 else 1.0
    dy = yc[1] - yc[0] if ny > 1 else 1.0
    nbands = band_start.shape[0] - 1
    for c in prange(chunks):
        for b in range(c, nbands, chunks):
            r_first = b * band_rows
            r_last = min(r_first + band_rows, ny) - 1
            for s in range(band_start[b], band_start[b + 1]):
                j = band_items[s]
                xj = x[j]
                yj = y[j]
                hj = h[j]
                reach = 2.0 * hj
                reach2 = reach * reach
                inv_h = 1.0 / hj
                w_j = vol[j] * inv_h * inv_h  # W(r, h) = W(r / h, 1) / h^2
                dj = d[j]
                uj = u[j]
                vj = v[j]
                near = wseg[wstart[j]:wstart[j + 1]]
                walled = near.shape[0] > 0
                lo, hi = _span(yj, reach, yc[0], dy, ny)
                c_lo, c_hi = _span(xj, reach, xc[0], dx, nx)
                for r in range(max(lo, r_first), min(hi, r_last) + 1):
                    ry = yc[r] - yj
                    for col in range(c_lo, c_hi + 1):
                        rx = xc[col] - xj
                        q2 = rx * rx + ry * ry
                        if q2 < reach2:
                            if walled and _hidden(xj, yj, xc[col], yc[r], seg, near):
                                continue
                            w = w_j * w_cubic(math.sqrt(q2) * inv_h, 1.0)
                            sums[r, col, 0] += w
                            sums[r, col, 1] += w * dj
                            sums[r, col, 2] += w * uj
                            sums[r, col, 3] += w * vj
