"""Near-wall lists: which wall segments lie within each particle's reach.

:class:`WallIndex` buckets the static wall segments on a pyramid of grids; its
:meth:`WallIndex.near_lists` gives each particle's near segments (CSR arrays
``(wstart, wseg)``), built with the neighbour lists and the same skin, and each particle's
right-angled corners ``(cstart, cpair)``: the pairs of its near segments that meet at a right
angle, listed in ``wseg`` order (the corners that make double mirror images). Most particles
have none and pay nothing.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange
from scipy import ndimage

from floodsph.walls.geometry import segment_distance
from floodsph.walls.sight import drift

NEAR_BUCKETS = 2.0
"""Radius, in level-0 buckets, up to which a particle's near segments are found among its own
bucket's precomputed candidates (:func:`_near_scan`); larger radii walk the bucket pyramid."""
DRIFT_BUCKET = 0.25
"""Side of the buckets of the drift's finest candidate table, in level-0 buckets (half the
seeded smoothing length h0 when a level-0 bucket is 2 h0): a move shorter than that side
tests only the segments within it of its bucket (``floodsph.walls.sight.drift``)."""


class MapWalls(NamedTuple):
    """The walls as the maps see them (``floodsph.output.rasterise``): segments ``seg`` ((k, 4)
    x0, y0, x1, y1 [m]) and each particle's near segments, ``wseg[wstart[j]:wstart[j + 1]]``."""

    seg: np.ndarray
    wstart: np.ndarray
    wseg: np.ndarray


class NearWalls(NamedTuple):
    """CSR lists of each particle's near wall segments and of its wall corners.

    Particle i's near segments are ``wseg[wstart[i]:wstart[i + 1]]`` (rows of the model's
    ``seg``), and the pairs of them that meet at a right angle (the corners that make double
    images) are the rows ``cpair[cstart[i]:cstart[i + 1]]`` ((k, 2) segment indices).
    """

    wstart: np.ndarray
    wseg: np.ndarray
    cstart: np.ndarray
    cpair: np.ndarray


class DriftTable(NamedTuple):
    """A grid of candidate segments for the drift (``floodsph.walls.sight.drift``): ``nbx``
    x ``nby`` square buckets of side ``bucket`` [m] from (``xmin``, ``ymin``), bucket b
    listing ``items[start[b]:start[b + 1]]`` of the index's ``drift_items`` (in increasing
    index): every segment whose bounding box widened by ``radius`` [m] overlaps it."""

    start: np.ndarray
    xmin: float
    ymin: float
    bucket: float
    nbx: int
    nby: int
    radius: float


class WallLists(NamedTuple):
    """The walls near each particle, as the density and force kernels take them (one
    argument): the segments ``seg`` ((k, 4): x0, y0, x1, y1 [m]), the :class:`NearWalls`
    lists, and ``wdist`` [m], the distance from each listed particle to each of its listed
    segments (``floodsph.walls.sight.blocked_pairs``; infinite for a segment that makes no
    mirror image, as with ``wall_model = "integral"``)."""

    seg: np.ndarray
    wdist: np.ndarray
    wstart: np.ndarray
    wseg: np.ndarray
    cstart: np.ndarray
    cpair: np.ndarray


class WallIndex:
    """Static buckets of wall segments for fast near-wall queries, on a pyramid of grids.

    Level L is a grid of square buckets of side ``bucket * 2**L``, up to one bucket over the
    domain; each bucket lists the segments whose bounding box overlaps it (buckets beyond the
    domain's bounds are clamped to the outermost ones). A query of radius R walks the finest
    level whose buckets are at least R / 2 wide (at most 5 x 5 buckets, however large R: a
    lone thin particle's smoothing length can be ten times the others', and every neighbour of
    it queries that far). It takes each segment in the first of its buckets that the segment and
    the query square share (:func:`query_box`, :func:`first_visit`), so no segment is seen
    twice and the cost follows the walls near the point, not their total.

    ``clear[b]`` is a lower bound [m] on the distance from any point of bucket b of level 0 to
    any segment: with e_b the Euclidean distance, in buckets, from b's centre to the centre of
    the nearest bucket that lists a segment (a distance transform of the bucket grid), two
    points in the two buckets are at least (e_b - sqrt 2) bucket apart. A particle whose
    radius is below it has no near segment and skips the bucket walk. Each bucket of level 0
    also lists its candidates, every segment whose box widened by ``near_radius``
    (``NEAR_BUCKETS`` buckets) overlaps it: a particle of that reach or less tests them alone,
    without the walk (on the dam break of ``benchmarks/step_cost.py`` at 4,000 particles, the
    lists took 0.24 ms a step instead of 0.79).
    """

    def __init__(self, seg: np.ndarray, bounds, bucket: float):
        self.seg = np.ascontiguousarray(seg, dtype=np.float64).reshape(-1, 4)
        xmin, ymin, xmax, ymax = bounds
        self.xmin, self.ymin = float(xmin), float(ymin)
        sizes, shapes, counts, items = [], [], [], []
        size = float(bucket)
        while True:
            nbx = max(1, int((xmax - xmin) / size) + 1)
            nby = max(1, int((ymax - ymin) / size) + 1)
            level_counts, level_items = _bucket_lists(self.seg, self.xmin, self.ymin, size,
                                                      nbx, nby)
            sizes.append(size)
            shapes.append((nbx, nby))
            counts.append(level_counts)
            items.append(level_items)
            if nbx == 1 and nby == 1:
                break
            size *= 2.0
        self.lv_bucket = np.array(sizes)
        self.lv_nbx = np.array([c for c, _ in shapes], dtype=np.int64)
        self.lv_nby = np.array([r for _, r in shapes], dtype=np.int64)
        self.lv_off = np.zeros(len(sizes) + 1, dtype=np.int64)
        np.cumsum(self.lv_nbx * self.lv_nby, out=self.lv_off[1:])
        self.start = np.zeros(self.lv_off[-1] + 1, dtype=np.int64)
        np.cumsum(np.concatenate(counts), out=self.start[1:])
        self.items = np.concatenate(items)
        nbx, nby = shapes[0]
        self.clear = _clearance(counts[0].reshape(nby, nbx) > 0, sizes[0])
        # per level-0 bucket, the segments whose box widened by near_radius overlaps it
        self.near_radius = NEAR_BUCKETS * sizes[0]
        self.near_start, self.near_items = _candidates(self.seg, self.xmin, self.ymin,
                                                       sizes[0], nbx, nby, self.near_radius)
        self.pstart, self.partner = _corner_partners(self.seg)
        fine = DRIFT_BUCKET * sizes[0]
        fine_nbx = max(1, int((xmax - xmin) / fine) + 1)
        fine_nby = max(1, int((ymax - ymin) / fine) + 1)
        fine_start, fine_items = _candidates(self.seg, self.xmin, self.ymin, fine, fine_nbx,
                                             fine_nby, fine)
        # one array of the drift's candidates: the fine table's, the near table's, then every
        # segment (for the longest moves)
        self.drift_items = np.concatenate([fine_items, self.near_items,
                                           np.arange(self.seg.shape[0], dtype=np.int64)])
        self.drift_tables = (
            DriftTable(fine_start, self.xmin, self.ymin, fine, fine_nbx, fine_nby, fine),
            DriftTable(self.near_start + fine_items.shape[0], self.xmin, self.ymin, sizes[0],
                       nbx, nby, self.near_radius))
        self.width = 16  # row width of the near-segment scan, widened when a row overflows

    def drift(self, x, y, u, v, dt: float) -> int:
        """Drift x <- x + dt v [m], reflecting the moves that would cross a segment
        (``floodsph.walls.sight.drift``, with this index's two :class:`DriftTable`: the fine
        buckets', then the level-0 buckets' candidates); returns the number of reflections."""
        return int(drift(x, y, u, v, dt, self.seg, *self.drift_tables, self.drift_items))

    def near_lists(self, x, y, h, nstart, nbr, reach, rows=None):
        """The :class:`NearWalls` lists of the segments within each particle's reach, and of its
        wall corners. The radius of particle i is reach * max(h_i, max_j h_j) over its
        neighbours j, so a wall between i and any neighbour is always in i's list (pair
        blocking is symmetric). ``rows``: list only these particles' segments (the others'
        lists are empty), as local time stepping needs them for the particles it updates
        alone; default every particle.
        """
        n = x.shape[0]
        wstart = np.zeros(n + 1, dtype=np.int64)
        cstart = np.zeros(n + 1, dtype=np.int64)
        if self.seg.shape[0] == 0 or n == 0:
            return NearWalls(wstart, np.zeros(0, dtype=np.int64), cstart,
                             np.zeros((0, 2), dtype=np.int64))
        listed = np.arange(n, dtype=np.int64) if rows is None else rows
        args = (listed, x, y, h, nstart, nbr, reach, self.seg, self.start, self.items,
                self.clear, self.near_radius, self.near_start, self.near_items, self.xmin,
                self.ymin, self.lv_bucket, self.lv_nbx, self.lv_nby, self.lv_off,
                float(h.max()))
        count = np.zeros(n, dtype=np.int64)
        while True:  # one scan into rows of ``width``; again, wider, if a row overflowed
            found = np.empty((listed.shape[0], self.width), dtype=np.int64)
            _near_scan(*args, found, count)
            widest = int(count.max())
            if widest <= self.width:
                break
            self.width = widest
        np.cumsum(count, out=wstart[1:])
        wseg = np.empty(wstart[-1], dtype=np.int64)
        _gather_rows(listed, found, wstart, wseg)
        corners = (wstart, wseg, self.pstart, self.partner, cstart)
        _corner_scan(*corners, np.zeros((0, 2), dtype=np.int64), False)
        np.cumsum(cstart, out=cstart)
        cpair = np.empty((cstart[-1], 2), dtype=np.int64)
        _corner_scan(*corners, cpair, True)
        return NearWalls(wstart, wseg, cstart, cpair)


def _bucket_lists(seg: np.ndarray, xmin: float, ymin: float, bucket: float, nbx: int,
                  nby: int) -> tuple[np.ndarray, np.ndarray]:
    """Per bucket of one grid (flat, row-major), the count of the segments whose bounding box
    overlaps it, and those segments bucket by bucket in increasing index (bucket ranges as in
    :func:`query_box`)."""
    lo = np.minimum(seg[:, :2], seg[:, 2:])
    hi = np.maximum(seg[:, :2], seg[:, 2:])
    b0 = np.floor_divide(lo - (xmin, ymin), bucket)
    b1 = np.floor_divide(hi - (xmin, ymin), bucket)
    top = np.array([nbx - 1, nby - 1])
    b0 = np.clip(b0, 0, top).astype(np.int64)
    b1 = np.clip(b1, 0, top).astype(np.int64)
    wide = b1[:, 0] - b0[:, 0] + 1
    cover = wide * (b1[:, 1] - b0[:, 1] + 1)
    sid = np.repeat(np.arange(seg.shape[0]), cover)
    k = np.arange(sid.size) - np.repeat(np.cumsum(cover) - cover, cover)
    b = (b0[sid, 1] + k // wide[sid]) * nbx + b0[sid, 0] + k % wide[sid]
    order = np.argsort(b, kind="stable")
    return np.bincount(b, minlength=nbx * nby), sid[order]


def _candidates(seg: np.ndarray, xmin: float, ymin: float, bucket: float, nbx: int, nby: int,
                radius: float) -> tuple[np.ndarray, np.ndarray]:
    """CSR table (start, items) of each bucket's candidate segments on a grid of nbx x nby
    buckets of side ``bucket`` [m]: every segment whose bounding box widened by ``radius``
    [m] overlaps the bucket, in increasing index (:func:`_bucket_lists`)."""
    lo = np.minimum(seg[:, :2], seg[:, 2:]) - radius
    hi = np.maximum(seg[:, :2], seg[:, 2:]) + radius
    counts, items = _bucket_lists(np.hstack([lo, hi]), xmin, ymin, bucket, nbx, nby)
    start = np.zeros(nbx * nby + 1, dtype=np.int64)
    np.cumsum(counts, out=start[1:])
    return start, items


def _clearance(occupied: np.ndarray, bucket: float) -> np.ndarray:
    """Per bucket (flat, row-major), a lower bound [m] on the distance to any listed segment:
    bucket * (e - sqrt 2) with e the distance transform of the unoccupied buckets (inf when
    no bucket lists a segment)."""
    if not occupied.any():
        return np.full(occupied.size, np.inf)
    e = ndimage.distance_transform_edt(~occupied)
    return (bucket * np.maximum(e - math.sqrt(2.0), 0.0)).ravel()


@njit(inline="always", cache=True)
def query_box(x0, y0, x1, y1, xmin, ymin, bucket, nbx, nby):
    """Bucket index range (bx0, bx1, by0, by1) overlapped by the box [x0, x1] x [y0, y1]."""
    bx0 = min(max(int((x0 - xmin) // bucket), 0), nbx - 1)
    bx1 = min(max(int((x1 - xmin) // bucket), 0), nbx - 1)
    by0 = min(max(int((y0 - ymin) // bucket), 0), nby - 1)
    by1 = min(max(int((y1 - ymin) // bucket), 0), nby - 1)
    return bx0, bx1, by0, by1


@njit(inline="always", cache=True)
def first_visit(seg, s, bx, by, qbx0, qby0, xmin, ymin, bucket, nbx, nby):
    """True if bucket (bx, by) is the first bucket, of a query starting at bucket
    (qbx0, qby0), that lists segment s: the one holding the low corner of the overlap."""
    sbx0, _, sby0, _ = query_box(min(seg[s, 0], seg[s, 2]), min(seg[s, 1], seg[s, 3]),
                                 min(seg[s, 0], seg[s, 2]), min(seg[s, 1], seg[s, 3]),
                                 xmin, ymin, bucket, nbx, nby)
    return bx == max(sbx0, qbx0) and by == max(sby0, qby0)


@njit(parallel=True, cache=True)
def _near_scan(listed, x, y, h, nstart, nbr, reach, seg, bstart, items, clear, near_radius,
               near_start, near_items, xmin, ymin, lv_bucket, lv_nbx, lv_nby, lv_off, h_top,
               found, count):
    """Count (into ``count[i]``) and list (into ``found[r]``, in index order, as far as the row
    is wide) the segments of each particle ``i = listed[r]`` within reach * max(h_i, max_j
    h_j); a particle inside
    the level-0 grid whose radius is below its bucket's ``clear`` distance has none (tested
    first with the largest h of all, ``h_top``, before its neighbours are walked). One whose
    radius is at most ``near_radius`` tests its level-0 bucket's candidates
    (``near_items[near_start[b]:near_start[b + 1]]``, every segment within ``near_radius`` of
    the bucket, in index order); the others walk the buckets of the finest level at least
    half as wide as the radius."""
    width = found.shape[1]
    top = lv_bucket.shape[0] - 1
    for r in prange(listed.shape[0]):
        i = listed[r]
        row = found[r]
        count[i] = 0
        cx = (x[i] - xmin) / lv_bucket[0]
        cy = (y[i] - ymin) / lv_bucket[0]
        inside = 0.0 <= cx < lv_nbx[0] and 0.0 <= cy < lv_nby[0]
        b0 = int(cy) * lv_nbx[0] + int(cx)  # i's level-0 bucket, when inside
        if inside and reach * h_top < clear[b0]:
            continue
        hr = h[i]
        for k in range(nstart[i], nstart[i + 1]):
            hr = max(hr, h[nbr[k]])
        radius = reach * hr
        if inside and radius < clear[b0]:
            continue
        if inside and radius <= near_radius:
            k = 0
            for q in range(near_start[b0], near_start[b0 + 1]):
                k = _take_if_near(x[i], y[i], seg, near_items[q], radius, row, k)
            count[i] = k
            continue
        lv = 0
        while lv < top and lv_bucket[lv] < 0.5 * radius:
            lv += 1
        bucket = lv_bucket[lv]
        nbx = lv_nbx[lv]
        nby = lv_nby[lv]
        bx0, bx1, by0, by1 = query_box(x[i] - radius, y[i] - radius, x[i] + radius,
                                       y[i] + radius, xmin, ymin, bucket, nbx, nby)
        k = 0
        for by in range(by0, by1 + 1):
            for bx in range(bx0, bx1 + 1):
                b = lv_off[lv] + by * nbx + bx
                for q in range(bstart[b], bstart[b + 1]):
                    s = items[q]
                    if first_visit(seg, s, bx, by, bx0, by0, xmin, ymin, bucket, nbx, nby):
                        k = _take_if_near(x[i], y[i], seg, s, radius, row, k)
        count[i] = k
        if k <= width:
            _sort_run(row, 0, k)


@njit(inline="always", cache=True)
def _take_if_near(px, py, seg, s, radius, row, k):
    """Append segment s to ``row`` at position k (as far as the row is wide) if it lies within
    ``radius`` [m] of the point (px, py); return the new count."""
    if segment_distance(px, py, seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3]) < radius:
        if k < row.shape[0]:
            row[k] = s
        k += 1
    return k


@njit(parallel=True, cache=True)
def _gather_rows(listed, found, wstart, wseg):
    """Copy the first wstart[i + 1] - wstart[i] entries of row r of ``found`` into the CSR
    ``wseg``, for each particle ``i = listed[r]``."""
    for r in prange(listed.shape[0]):
        i = listed[r]
        for k in range(wstart[i + 1] - wstart[i]):
            wseg[wstart[i] + k] = found[r, k]


@njit(inline="always", cache=True)
def _sort_run(a, lo, hi):
    """Insertion sort of a[lo:hi] in place (a particle's few segments, in index order, so
    that the sums over them do not depend on the bucket path that found them)."""
    for k in range(lo + 1, hi):
        v = a[k]
        q = k - 1
        while q >= lo and a[q] > v:
            a[q + 1] = a[q]
            q -= 1
        a[q + 1] = v


@njit(inline="always", cache=True)
def right_corner(seg, s1, s2):
    """True if segments s1 and s2 share an end point and meet at a right angle
    (|cos| < 1e-6), the corners whose double mirror image completes the kernel."""
    e1x = seg[s1, 2] - seg[s1, 0]
    e1y = seg[s1, 3] - seg[s1, 1]
    e2x = seg[s2, 2] - seg[s2, 0]
    e2y = seg[s2, 3] - seg[s2, 1]
    dot = e1x * e2x + e1y * e2y
    if dot * dot > 1e-12 * (e1x * e1x + e1y * e1y) * (e2x * e2x + e2y * e2y):
        return False
    return share_vertex(seg, s1, s2)


@njit(inline="always", cache=True)
def share_vertex(seg, s1, s2):
    """True if segments s1 and s2 have an end point in common (exactly)."""
    for a in range(2):
        for b in range(2):
            if seg[s1, 2 * a] == seg[s2, 2 * b] and seg[s1, 2 * a + 1] == seg[s2, 2 * b + 1]:
                return True
    return False


def _corner_partners(seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """CSR table of the right corners of the walls: segment s meets the segments
    ``partner[pstart[s]:pstart[s + 1]]`` (each of higher index, in increasing order) at a
    right angle (:func:`right_corner`). Walls are static, so this is found once, and a
    particle's corners are then looked up among its near segments (:func:`_corner_scan`)."""
    ns = seg.shape[0]
    ends = seg.reshape(2 * ns, 2)  # rows 2 s and 2 s + 1: the two ends of segment s
    _, vertex = np.unique(ends, axis=0, return_inverse=True)
    vertex = vertex.ravel()
    order = np.argsort(vertex, kind="stable")
    cut = np.flatnonzero(np.diff(vertex[order])) + 1
    found: set[tuple[int, int]] = set()
    for group in np.split(order // 2, cut):
        for a in range(group.size):
            for b in range(a + 1, group.size):
                s1, s2 = sorted((int(group[a]), int(group[b])))
                if s1 != s2 and right_corner(seg, s1, s2):
                    found.add((s1, s2))
    pairs = np.array(sorted(found), dtype=np.int64).reshape(-1, 2)
    pstart = np.zeros(ns + 1, dtype=np.int64)
    np.cumsum(np.bincount(pairs[:, 0], minlength=ns), out=pstart[1:])
    return pstart, np.ascontiguousarray(pairs[:, 1])


@njit(parallel=True, cache=True)
def _corner_scan(wstart, wseg, pstart, partner, cstart, cpair, fill):
    """Count (fill False: into cstart[i + 1]) or list (fill True) each particle's corners.

    A corner is a pair of i's near segments that meet at a right angle: the partners
    (:func:`_corner_partners`) of each near segment looked up (``np.searchsorted``) among
    the later ones of i's sorted run. Listing them once per neighbour-list build spares the
    kernels a search over all pairs for every neighbour. At other angles the double image of
    a point (a rotation by twice the angle between the walls) can fall in the water, so those
    corners get the single images only.
    """
    for i in prange(wstart.shape[0] - 1):
        k = 0
        end = wstart[i + 1]
        for w in range(wstart[i], end):
            s = wseg[w]
            later = wseg[w + 1:end]
            for q in range(pstart[s], pstart[s + 1]):
                at = np.searchsorted(later, partner[q])
                if at < later.shape[0] and later[at] == partner[q]:
                    if fill:
                        cpair[cstart[i] + k, 0] = s
                        cpair[cstart[i] + k, 1] = partner[q]
                    k += 1
        if not fill:
            cstart[i + 1] = k
