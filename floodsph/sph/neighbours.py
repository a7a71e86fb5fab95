"""Neighbour search: a cell-linked list built by a parallel counting sort, and CSR pair lists.

A pair (i, j) interacts when r_ij < 2 max(h_i, h_j) (support 2h of the cubic spline, taken
symmetrically so that the pressure force of Vacondio et al. 2013 eq. (4) is antisymmetric).
Smoothing lengths can differ by orders of magnitude (thin flood fronts), and a cell size set
by the largest h would put hundreds of candidates in every stencil. The particles are
therefore binned by h into levels: level 0 holds h <= LEVEL_BASE median(h), level L >= 1
holds h in (h_c 2^(L-1), h_c 2^L] with h_c = LEVEL_BASE median(h). Each level has its own
grid over its particles' bounding box, with cells the reach R_L of its largest h, and a
particle searches the 3 x 3 cells around it on every level within its reach (more rings
where its own h is larger); the candidates of a row of cells are contiguous in cell order.
The result is exact for any mix of h at a cost set by the local particle density.

The CSR lists are written in one search pass: chunks of ``CHUNK`` rows, one task each, write
their rows' neighbours into buffers sized from a sample of the rows' counts, and the buffers
are then copied into place; a chunk whose buffer is too small is counted and searched again.
(A count pass followed by a fill pass searched every row twice, a third of a build's time.)

The lists are Verlet lists (Verlet 1967; Allen & Tildesley, Computer Simulation of Liquids,
2nd ed. 2017, section 5.3): built with the relative ``skin`` on the reach,
R = 2 (1 + skin) max(h_i, h_j), they stay exact while particles move and h grows a little
(:meth:`NeighbourList.still_valid`), so one list serves the Newton-Raphson density solve and,
in slow flow, several time steps.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.sph.cells import chunks, counting_sort

LEVEL_BASE = 1.25
"""Level 0 of the search holds the particles with h <= LEVEL_BASE median(h)."""
CHUNK = 1024
"""Rows per task of the parallel list build."""
SAMPLE_STRIDE = 32
"""Every SAMPLE_STRIDE-th row is counted first, to size the build's buffers."""


@njit(cache=True)
def h_levels(x, y, h, h_c, level):
    """Search level of every particle into ``level``: 0 for h <= h_c, L >= 1 for h in
    (h_c 2^(L-1), h_c 2^L].

    Returns (hmax, box): the largest h of each level and its particles' bounding box
    (x0, y0, x1, y1); an empty level has hmax 0.
    """
    hmax = np.zeros(64)
    box = np.empty((64, 4))
    box[:, :2] = np.inf
    box[:, 2:] = -np.inf
    top = 0
    for i in range(h.shape[0]):
        lv = 0
        if h[i] > h_c:
            lv = min(int(math.ceil(math.log2(h[i] / h_c))), 63)
        level[i] = lv
        hmax[lv] = max(hmax[lv], h[i])
        box[lv, 0] = min(box[lv, 0], x[i])
        box[lv, 1] = min(box[lv, 1], y[i])
        box[lv, 2] = max(box[lv, 2], x[i])
        box[lv, 3] = max(box[lv, 3], y[i])
        top = max(top, lv)
    return hmax[: top + 1], box[: top + 1]


@njit(parallel=True, cache=True)
def _in_cell_order(order, x, y, h, xs, ys, hs):
    """x, y and h in cell order: ``xs[s] = x[order[s]]`` and alike."""
    for s in prange(order.shape[0]):
        j = order[s]
        xs[s] = x[j]
        ys[s] = y[j]
        hs[s] = h[j]


@njit(cache=True)
def _level_grids(level, lv_hmax, box, reach):
    """The grid of each search level: its cell side [m], the reach R_L = ``reach`` times the
    level's largest h, or coarser, sqrt(area / (members + 1)), where that would give more
    cells than the level has particles; its cells across and along, and each level's offset
    in the cells of all levels. An empty level (hmax 0) has one cell of side 0.

    Returns (lv_cell, lv_ncx, lv_ncy, lv_off).
    """
    nlv = lv_hmax.shape[0]
    members = np.zeros(nlv, dtype=np.int64)
    for i in range(level.shape[0]):
        members[level[i]] += 1
    lv_cell = np.zeros(nlv)
    lv_ncx = np.ones(nlv, dtype=np.int64)
    lv_ncy = np.ones(nlv, dtype=np.int64)
    lv_off = np.zeros(nlv + 1, dtype=np.int64)
    for lv in range(nlv):
        if lv_hmax[lv] > 0.0:
            width = box[lv, 2] - box[lv, 0]
            height = box[lv, 3] - box[lv, 1]
            cell = max(reach * lv_hmax[lv], math.sqrt(width * height / (members[lv] + 1.0)))
            lv_cell[lv] = cell
            lv_ncx[lv] = int(math.floor(width / cell)) + 1
            lv_ncy[lv] = int(math.floor(height / cell)) + 1
        lv_off[lv + 1] = lv_off[lv] + lv_ncx[lv] * lv_ncy[lv]
    return lv_cell, lv_ncx, lv_ncy, lv_off


@njit(parallel=True, cache=True)
def _level_cell_ids(x, y, level, box, lv_cell, lv_ncx, lv_ncy, lv_off, out):
    """Cell index ``off_L + cy * ncx_L + cx`` of every point on its level's grid."""
    for i in prange(x.shape[0]):
        lv = level[i]
        cx = min(max(int((x[i] - box[lv, 0]) / lv_cell[lv]), 0), lv_ncx[lv] - 1)
        cy = min(max(int((y[i] - box[lv, 1]) / lv_cell[lv]), 0), lv_ncy[lv] - 1)
        out[i] = lv_off[lv] + cy * lv_ncx[lv] + cx


@njit(inline="always", cache=True)
def _search(i, x, y, h, xs, ys, hs, order, cell_start, box, lv_cell, lv_ncx, lv_ncy, lv_off,
            lv_hmax, reach, buf, fill):
    """Neighbours of particle i, itself included: their number and, if ``fill``, their
    indices in ``buf[:number]`` when ``buf`` holds one slot more than the number.

    ``xs, ys, hs`` are x, y, h in cell order (``xs[s] = x[order[s]]``): the candidates of a
    row of adjacent cells are one contiguous run. Each candidate is written unconditionally
    and kept by advancing the count, so the loop has no data-dependent jump; a shorter
    ``buf`` takes the writes past its end in its last slot (the caller sees that the number
    does not fit, and searches again).
    """
    xi = x[i]
    yi = y[i]
    hi = h[i]
    last = buf.shape[0] - 1
    k = 0
    for lv in range(lv_cell.shape[0]):
        cell = lv_cell[lv]
        rad = reach * max(hi, lv_hmax[lv])
        bx = max(box[lv, 0] - xi, xi - box[lv, 2], 0.0)
        by = max(box[lv, 1] - yi, yi - box[lv, 3], 0.0)
        if cell <= 0.0 or bx * bx + by * by >= rad * rad:
            continue
        ncx = lv_ncx[lv]
        ncy = lv_ncy[lv]
        rings = int(math.ceil(rad / cell))
        cx = min(max(int((xi - box[lv, 0]) / cell), 0), ncx - 1)
        cy = min(max(int((yi - box[lv, 1]) / cell), 0), ncy - 1)
        cx0 = max(cx - rings, 0)
        cx1 = min(cx + rings, ncx - 1)
        for gy in range(max(cy - rings, 0), min(cy + rings, ncy - 1) + 1):
            row = lv_off[lv] + gy * ncx
            for s in range(cell_start[row + cx0], cell_start[row + cx1 + 1]):
                dx = xs[s] - xi
                dy = ys[s] - yi
                r = reach * max(hi, hs[s])
                if fill:
                    buf[min(k, last)] = order[s]
                k += dx * dx + dy * dy < r * r
    return k


@njit(parallel=True, cache=True)
def _count(x, y, h, xs, ys, hs, order, cell_start, box, lv_cell, lv_ncx, lv_ncy, lv_off,
           lv_hmax, reach, rows, counts):
    """Number of neighbours of each particle ``rows[k]`` (itself excluded) into
    ``counts[k]``."""
    buf = np.zeros(0, dtype=np.int64)
    for k in prange(rows.shape[0]):
        counts[k] = _search(rows[k], x, y, h, xs, ys, hs, order, cell_start, box, lv_cell,
                            lv_ncx, lv_ncy, lv_off, lv_hmax, reach, buf, False) - 1


@njit(parallel=True, cache=True)
def _gather(x, y, h, xs, ys, hs, order, cell_start, box, lv_cell, lv_ncx, lv_ncy, lv_off,
            lv_hmax, reach, rows, chunk, chunks, base, counts, buf, fits):
    """Neighbours of the rows of the listed chunks, in one search pass.

    Chunk ``c = chunks[k]`` holds the rows ``rows[c chunk:(c + 1) chunk]``; their neighbours
    (each row's in search order, itself left out) go one row after another into
    ``buf[base[k]:base[k + 1]]`` and row r's number of neighbours into ``counts[r]``;
    ``fits[k]`` is False where a row and its spare slot did not fit (the chunk stops there).
    Parallel over the listed chunks, each writing its own range.
    """
    nrows = rows.shape[0]
    for k in prange(chunks.shape[0]):
        c = chunks[k]
        pos = base[k]
        end = base[k + 1]
        fits[k] = True
        for r in range(c * chunk, min(nrows, (c + 1) * chunk)):
            i = rows[r]
            found = _search(i, x, y, h, xs, ys, hs, order, cell_start, box, lv_cell, lv_ncx,
                            lv_ncy, lv_off, lv_hmax, reach, buf[pos:end], True)
            if found >= end - pos:  # the row and its spare slot need found + 1
                fits[k] = False
                break
            own = pos
            while buf[own] != i:
                own += 1
            for q in range(own, pos + found - 1):  # leave itself out, keeping the order
                buf[q] = buf[q + 1]
            counts[r] = found - 1
            pos += found - 1


@njit(parallel=True, cache=True)
def _scatter(rows, chunk, chunks, base, counts, buf, nbr_start, nbr):
    """Copy the neighbours that :func:`_gather` left in ``buf`` (chunk ``chunks[k]``'s from
    ``base[k]``) into their CSR place ``nbr[nbr_start[i]:nbr_start[i + 1]]``."""
    nrows = rows.shape[0]
    for k in prange(chunks.shape[0]):
        c = chunks[k]
        src = base[k]
        for r in range(c * chunk, min(nrows, (c + 1) * chunk)):
            dst = nbr_start[rows[r]]
            for q in range(counts[r]):
                nbr[dst + q] = buf[src + q]
            src += counts[r]


def _chunk_capacity(args, rows: np.ndarray) -> np.ndarray:
    """Slots for each chunk of ``CHUNK`` rows in :func:`_gather`, from the neighbour counts of
    every ``SAMPLE_STRIDE``-th row: 1.5 times the chunk's sampled mean per row times its
    rows, plus twice its sampled largest count and a margin, so that a chunk seldom has to be
    searched again."""
    sample = rows[::SAMPLE_STRIDE]
    if sample.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    found = np.empty(sample.shape[0], dtype=np.int64)
    _count(*args[:-1], sample, found)  # type: ignore[call-arg]  # a numba kernel
    return _capacity(found, rows.shape[0])


@njit(cache=True)
def _capacity(found, nrows):
    """Slots of each chunk of ``CHUNK`` of ``nrows`` rows (:func:`_chunk_capacity`) from the
    neighbour counts ``found`` of every ``SAMPLE_STRIDE``-th row."""
    per_chunk = CHUNK // SAMPLE_STRIDE
    nchunk = (found.shape[0] + per_chunk - 1) // per_chunk
    slots = np.empty(nchunk, dtype=np.int64)
    for c in range(nchunk):
        lo = c * per_chunk
        hi = min(found.shape[0], lo + per_chunk)
        total = 0
        most = 0
        for k in range(lo, hi):
            total += found[k]
            most = max(most, found[k])
        size = min(nrows - lo * SAMPLE_STRIDE, CHUNK)
        slots[c] = int(1.5 * size * (total / (hi - lo)) + 2.0 * most + 64.0)
    return slots


@njit(parallel=True, cache=True)
def _within_support(x, y, h, nstart, nbr):
    """Number of listed directed pairs with r_ij < 2 max(h_i, h_j)."""
    total = 0
    for i in prange(x.shape[0]):
        k = 0
        for q in range(nstart[i], nstart[i + 1]):
            j = nbr[q]
            r = 2.0 * max(h[i], h[j])
            k += (x[j] - x[i]) ** 2 + (y[j] - y[i]) ** 2 < r * r
        total += k
    return total


@njit(parallel=True, cache=True)
def _motion(x, y, h, x_b, y_b, h_b):
    """max_i h_i / h_b,i and max_i |x_i - x_b,i| / h_b,i since the list was built."""
    grow = 0.0
    move = 0.0
    for i in prange(x.shape[0]):
        grow = max(grow, h[i] / h_b[i])
        move = max(move, math.hypot(x[i] - x_b[i], y[i] - y_b[i]) / h_b[i])
    return grow, move


def _lists(args, rows: np.ndarray, nbr_start: np.ndarray) -> np.ndarray:
    """The CSR lists of ``rows`` (``args``: the search arguments of :func:`_gather`): fills
    ``nbr_start`` (zeros on entry) and returns ``nbr``.

    One search pass (:func:`_gather`) into per-chunk buffers sized by
    :func:`_chunk_capacity`; a chunk that does not fit is counted exactly and searched again
    into a buffer of its size; the buffers are then copied into place (:func:`_scatter`).
    """
    counts = np.empty(rows.shape[0], dtype=np.int64)
    nchunk = (rows.shape[0] + CHUNK - 1) // CHUNK
    chunks = np.arange(nchunk, dtype=np.int64)
    base = np.zeros(nchunk + 1, dtype=np.int64)
    np.cumsum(_chunk_capacity(args, rows), out=base[1:])
    buf = np.empty(base[-1], dtype=np.int64)
    done = np.empty(nchunk, dtype=np.bool_)
    _gather(*args, CHUNK, chunks, base, counts, buf, done)  # type: ignore[call-arg]  # a numba kernel
    passes = [(chunks[done], base[:-1][done], buf)]
    redo = chunks[~done]
    if redo.size:
        again = np.concatenate([rows[c * CHUNK:(c + 1) * CHUNK] for c in redo])
        found = np.empty(again.shape[0], dtype=np.int64)
        _count(*args[:-1], again, found)  # type: ignore[call-arg]  # a numba kernel
        first = np.append(0, np.cumsum(np.minimum(rows.shape[0] - redo * CHUNK, CHUNK))[:-1])
        base2 = np.zeros(redo.size + 1, dtype=np.int64)
        np.cumsum(np.add.reduceat(found, first) + 2, out=base2[1:])
        buf2 = np.empty(base2[-1], dtype=np.int64)
        fits = np.empty(redo.size, dtype=np.bool_)
        _gather(*args, CHUNK, redo, base2, counts, buf2, fits)  # type: ignore[call-arg]  # a numba kernel
        if not fits.all():
            raise RuntimeError("neighbour lists: a chunk overflowed its exact size")
        passes.append((redo, base2[:-1], buf2))
    nbr_start[rows + 1] = counts
    np.cumsum(nbr_start, out=nbr_start)
    nbr = np.empty(nbr_start[-1], dtype=np.int64)
    for listed, start, buffer in passes:
        _scatter(rows, CHUNK, listed, start, counts, buffer, nbr_start, nbr)
    return nbr


class NeighbourList:
    """CSR neighbour lists: the neighbours of i are ``nbr[start[i]:start[i + 1]]``.

    Every pair with r_ij < 2 (1 + skin) max(h_i, h_j) at the build is listed (a superset of
    the interacting pairs; kernels skip the listed pairs beyond the support).

    Parameters
    ----------
    x, y, h : float64 arrays
        Positions [m] and smoothing lengths [m] of the active particles.
    skin : float
        Relative margin on the 2 max(h_i, h_j) support (see :meth:`still_valid`).
    rows : int64 array, optional
        List only these particles' neighbours (among all particles); the other rows are
        empty. Local time stepping (``floodsph.sph.local_steps``) lists the particles that
        end a step. Default: every particle.
    """

    STATE = ("skin", "complete", "reach", "rows", "x_built", "y_built", "h_built", "start",
             "nbr")
    """The lists as a checkpoint holds them (``floodsph.simulation.state_arrays``): resuming
    with the lists of the interrupted run, not new ones, keeps the pairs in their order."""

    def __init__(self, x, y, h, skin=0.1, rows=None):
        n = x.shape[0]
        self.skin = skin
        self.complete = rows is None
        self.rows = np.arange(n, dtype=np.int64) if rows is None else rows
        self.reach = 2.0 * (1.0 + skin)
        self.x_built = x.copy()
        self.y_built = y.copy()
        self.h_built = h.copy()
        self.start = np.zeros(n + 1, dtype=np.int64)
        if n == 0:
            self.nbr = np.zeros(0, dtype=np.int64)
            return
        level = np.empty(n, dtype=np.int64)
        lv_hmax, box = h_levels(x, y, h, LEVEL_BASE * float(np.median(h)), level)
        lv_cell, lv_ncx, lv_ncy, lv_off = _level_grids(level, lv_hmax, box, self.reach)
        cid = np.empty(n, dtype=np.int64)
        _level_cell_ids(x, y, level, box, lv_cell, lv_ncx, lv_ncy, lv_off, cid)
        cell_start, order = counting_sort(cid, int(lv_off[-1]), chunks(n))
        xs, ys, hs = np.empty(n), np.empty(n), np.empty(n)
        _in_cell_order(order, x, y, h, xs, ys, hs)
        args = (x, y, h, xs, ys, hs, order, cell_start, box, lv_cell, lv_ncx, lv_ncy, lv_off,
                lv_hmax, self.reach, self.rows)
        self.nbr = _lists(args, self.rows, self.start)

    def still_valid(self, x, y, h) -> bool:
        """True while the list still holds every pair with r_ij < 2 max(h_i, h_j), and lists
        every particle's neighbours (:meth:`covers`, with every row listed)."""
        return self.complete and self.covers(x, y, h)

    def covers(self, x, y, h) -> bool:
        """True while the listed rows still hold every pair with r_ij < 2 max(h_i, h_j).

        With G = max h_i / h_b,i and D = max |x_i - x_b,i| / h_b,i (b: at the build), a pair
        within the support now was within 2 (G + D) max(h_b,i, h_b,j) at the build, so the
        list is exact while G + D <= 1 + skin (and the particle count is the same).
        """
        if x.shape[0] != self.x_built.shape[0]:
            return False
        if x.shape[0] == 0:
            return True
        grow, move = _motion(x, y, h, self.x_built, self.y_built, self.h_built)
        return grow + move <= 1.0 + self.skin

    def h_cap(self, x, y, unmoved: bool = False) -> np.ndarray:
        """Largest smoothing lengths [m] the list still holds at the current positions:
        h_b,i (1 + skin - D), so that G + D <= 1 + skin in :meth:`still_valid`.
        ``unmoved``: the caller knows that x, y are the positions of the build (D = 0)."""
        if x.shape[0] == 0:
            return self.h_built.copy()
        if unmoved:
            return self.h_built * (1.0 + self.skin - 0.0)
        _, move = _motion(x, y, self.h_built, self.x_built, self.y_built, self.h_built)
        return self.h_built * (1.0 + self.skin - move)

    def count(self) -> int:
        """Number of listed directed pairs (within the skin)."""
        return int(self.nbr.shape[0])

    def interactions(self, x, y, h) -> int:
        """Number of directed pairs that interact now, r_ij < 2 max(h_i, h_j)."""
        return int(_within_support(x, y, h, self.start, self.nbr))
