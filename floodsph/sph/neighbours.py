"""Neighbour search: a cell-linked list built by a parallel counting sort, and CSR pair lists.

A pair (i, j) interacts when r_ij < 2 max(h_i, h_j) (support 2h of the cubic spline, taken
symmetrically so that the pressure force of Vacondio et al. 2013 eq. (4) is antisymmetric).
With smoothing lengths that differ by orders of magnitude (thin flood fronts), a cell size set
by the largest h would put thousands of candidates in every stencil. The cell size is
therefore set by a cut-off ``h_cut`` near the bulk of the particles; the few "big" particles
with h > h_cut search as many rings of cells as their support needs and are found by the
others through an explicit list, so the result is exact for any mix of h.

The list is built with a relative ``skin`` so that it stays valid while the Newton-Raphson
density solve changes h a little (Verlet-list practice).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from numba import njit, prange


@njit(parallel=True, cache=True)
def cell_ids(x, y, xmin, ymin, cell, ncx, ncy, out):
    """Cell index ``cy * ncx + cx`` of every point (clamped to the grid) into ``out``."""
    for i in prange(x.shape[0]):
        cx = min(max(int((x[i] - xmin) / cell), 0), ncx - 1)
        cy = min(max(int((y[i] - ymin) / cell), 0), ncy - 1)
        out[i] = cy * ncx + cx


@njit(parallel=True, cache=True)
def counting_sort(cid, ncells, nchunk):
    """Stable counting sort of cell ids, parallel over ``nchunk`` contiguous chunks.

    Returns ``cell_start`` (ncells + 1; the points of cell c are ``order[cell_start[c]:
    cell_start[c + 1]]``) and ``order``. Each chunk histograms and scatters its own
    particles, so no two threads write the same counter.
    """
    n = cid.shape[0]
    counts = np.zeros((nchunk, ncells), dtype=np.int64)
    size = (n + nchunk - 1) // nchunk
    for c in prange(nchunk):
        for i in range(c * size, min(n, (c + 1) * size)):
            counts[c, cid[i]] += 1
    cell_start = np.zeros(ncells + 1, dtype=np.int64)
    offset = np.zeros((nchunk, ncells), dtype=np.int64)
    total = 0
    for k in range(ncells):
        cell_start[k] = total
        for c in range(nchunk):
            offset[c, k] = total
            total += counts[c, k]
    cell_start[ncells] = total
    order = np.empty(n, dtype=np.int64)
    for c in prange(nchunk):
        for i in range(c * size, min(n, (c + 1) * size)):
            k = cid[i]
            order[offset[c, k]] = i
            offset[c, k] += 1
    return cell_start, order


class CellGrid:
    """A uniform grid of square cells over a bounding box, with points binned into it."""

    def __init__(self, x, y, cell, bounds=None):
        if bounds is None:
            bounds = (x.min(), y.min(), x.max(), y.max()) if x.size else (0.0, 0.0, 1.0, 1.0)
        xmin, ymin, xmax, ymax = bounds
        self.cell = float(cell)
        self.xmin, self.ymin = float(xmin), float(ymin)
        self.ncx = max(1, int(math.floor((xmax - xmin) / cell)) + 1)
        self.ncy = max(1, int(math.floor((ymax - ymin) / cell)) + 1)
        cid = np.empty(x.shape[0], dtype=np.int64)
        cell_ids(x, y, self.xmin, self.ymin, self.cell, self.ncx, self.ncy, cid)
        nchunk = max(1, min(nb.get_num_threads(), x.shape[0] // 4096 + 1))
        self.cell_start, self.order = counting_sort(cid, self.ncx * self.ncy, nchunk)

    def arrays(self):
        """(cell_start, order, xmin, ymin, cell, ncx, ncy) as kernels take them."""
        return self.cell_start, self.order, self.xmin, self.ymin, self.cell, self.ncx, self.ncy


@njit(inline="always")
def _in_range(dx, dy, hi, hj, reach):
    r2 = dx * dx + dy * dy
    s = reach * max(hi, hj)
    return r2 < s * s


@njit(parallel=True, cache=True)
def _scan(x, y, h, big, big_idx, cell_start, order, xmin, ymin, cell, ncx, ncy, reach,
          h_cut, nbr_start, nbr, fill):
    """Count (fill=False) or write (fill=True) the neighbours of every particle."""
    n = x.shape[0]
    for i in prange(n):
        xi = x[i]
        yi = y[i]
        hi = h[i]
        k = 0
        pos = nbr_start[i]
        rings = int(math.ceil(reach * max(hi, h_cut) / cell))
        cx = min(max(int((xi - xmin) / cell), 0), ncx - 1)
        cy = min(max(int((yi - ymin) / cell), 0), ncy - 1)
        for gy in range(max(cy - rings, 0), min(cy + rings + 1, ncy)):
            for gx in range(max(cx - rings, 0), min(cx + rings + 1, ncx)):
                c = gy * ncx + gx
                for s in range(cell_start[c], cell_start[c + 1]):
                    j = order[s]
                    if j == i or big[j]:
                        continue
                    if _in_range(x[j] - xi, y[j] - yi, hi, h[j], reach):
                        if fill:
                            nbr[pos + k] = j
                        k += 1
        for s in range(big_idx.shape[0]):
            j = big_idx[s]
            if j == i:
                continue
            if _in_range(x[j] - xi, y[j] - yi, hi, h[j], reach):
                if fill:
                    nbr[pos + k] = j
                k += 1
        if not fill:
            nbr_start[i + 1] = k


class NeighbourList:
    """CSR neighbour lists: the neighbours of i are ``nbr[start[i]:start[i + 1]]``.

    Parameters
    ----------
    x, y, h : float64 arrays
        Positions [m] and smoothing lengths [m] of the active particles.
    skin : float
        Relative margin on the 2 max(h_i, h_j) support; the list stays exact while no h
        grows by more than this fraction (see :meth:`still_valid`).
    """

    def __init__(self, x, y, h, skin=0.1):
        n = x.shape[0]
        self.skin = skin
        self.reach = 2.0 * (1.0 + skin)
        self.h_built = h.copy()
        if n == 0:
            self.start = np.zeros(1, dtype=np.int64)
            self.nbr = np.zeros(0, dtype=np.int64)
            return
        h_max = float(h.max())
        h_cut = min(h_max, 2.0 * float(h.mean()))
        big = h > h_cut
        if big.sum() > 0.05 * n:
            h_cut = h_max
            big[:] = False
        big_idx = np.flatnonzero(big).astype(np.int64)
        grid = CellGrid(x, y, self.reach * h_cut)
        start = np.zeros(n + 1, dtype=np.int64)
        dummy = np.zeros(0, dtype=np.int64)
        args = (x, y, h, big, big_idx, *grid.arrays(), self.reach, h_cut)
        _scan(*args, start, dummy, False)
        np.cumsum(start, out=start)
        nbr = np.empty(start[-1], dtype=np.int64)
        _scan(*args, start, nbr, True)
        self.start = start
        self.nbr = nbr

    def still_valid(self, h) -> bool:
        """True while every h is within the skin of the h the list was built with."""
        return bool(np.all(h <= self.h_built * (1.0 + self.skin)))

    def count(self) -> int:
        """Number of directed pairs."""
        return int(self.nbr.shape[0])
