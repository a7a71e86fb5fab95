"""Cell-linked lists: points binned into a uniform grid of square cells by a parallel
counting sort (one pass of counts per chunk of points, a prefix sum, one pass of placement),
so that the points of each cell are contiguous in ``order``.

Used by the neighbour search (``floodsph.sph.neighbours``) and by the model's periodic
re-sort of the particles into cell order.
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


def chunks(n: int) -> int:
    """Chunks of the parallel counting sort: one per thread, at least 4096 points each."""
    return max(1, min(nb.get_num_threads(), n // 4096 + 1))


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
        self.cell_start, self.order = counting_sort(cid, self.ncx * self.ncy, chunks(x.shape[0]))

    def arrays(self):
        """(cell_start, order, xmin, ymin, cell, ncx, ncy) as kernels take them."""
        return self.cell_start, self.order, self.xmin, self.ymin, self.cell, self.ncx, self.ncy
