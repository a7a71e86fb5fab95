"""Closed boundaries as wall segments: mirror particles, pair blocking and a crossing guard.

A wall is a polyline (a closed one is a solid footprint); the DEM border is four of them when
the edges are closed. Three mechanisms keep water on its side:

1. **Mirror particles.** For a particle i near a wall segment, every neighbour j on i's side
   (i itself included) contributes a mirror image x_j' = 2 f_j - x_j (f_j its foot on the
   segment's line), with the same mass, density, alpha and h and the mirrored velocity
   v_j' = v_j - 2 (v_j . n) n (free slip), if the line from i to the image passes through the
   segment: the images fill the part of i's support hidden from i behind the wall. On a
   straight wall this completes the kernel exactly, so the depth and the pressure of still
   water along a wall are those of the interior (zero-order consistency, the property the
   modified virtual boundary particles of Vacondio, Rogers & Stansby, IJNMF 69 (2012) 226-253
   approximate). Behind a convex corner (a building's) each hidden point is imaged once, by
   the face the line passes through. j's foot need not fall on the segment: where a wall
   bends, a point hidden behind one segment may be the image of a particle in front of the
   next (an earlier version required the foot on the segment, and lost those images near every
   vertex of a polyline). A sight line exactly through a vertex is settled by a fixed shift of
   1e-7 m (:func:`hides`), so that point is imaged once. In a right-angled corner where two
   near segments meet, j's foot on both gives a third image, the reflection of j's first image
   about the second wall (the point reflection through the corner), which completes the kernel
   there too.
2. **Pair blocking.** Particles on opposite sides of a wall do not interact.
3. **Crossing guard.** A drift step that would cross a wall is reflected about it (position and
   normal velocity), so no particle ever crosses, whatever the time step (:func:`drift`).

Near-wall lists are CSR arrays ``(wstart, wseg)`` built with the neighbour lists, with the
same skin, for the particles within the interaction radius of a segment (and kept as long as
the neighbour lists are: a wall within the support now was within the skinned radius at the
build), together with each particle's corners ``(cstart, cpair)``: the pairs of its near
segments that meet at a right angle, listed in ``wseg`` order. Most particles have none and pay
nothing. Which listed pairs a wall separates is found once per step (:func:`blocked_pairs`)
for the density iterations and the forces.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange
from scipy import ndimage


def segments_from_polylines(polylines) -> np.ndarray:
    """Stack polylines ((k, 2) arrays, local metres) into segments (ns, 4): x1, y1, x2, y2."""
    segs = []
    for line in polylines:
        pts = np.asarray(line, dtype=np.float64)
        for a, b in zip(pts[:-1], pts[1:], strict=True):
            if np.hypot(*(b - a)) > 0.0:
                segs.append((a[0], a[1], b[0], b[1]))
    return np.asarray(segs, dtype=np.float64).reshape(-1, 4)


def box_polyline(xmin, ymin, xmax, ymax) -> np.ndarray:
    """A closed rectangle as a polyline (the DEM border of a closed domain)."""
    return np.array([[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax], [xmin, ymin]])


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
    radius is below it has no near segment and skips the bucket walk.
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
        self.pstart, self.partner = _corner_partners(self.seg)
        self.width = 16  # row width of the near-segment scan, widened when a row overflows

    def near_lists(self, x, y, h, nstart, nbr, reach):
        """CSR lists of the segments within each particle's reach, and of its wall corners.

        Returns (wstart, wseg, cstart, cpair): particle i's near segments are
        ``wseg[wstart[i]:wstart[i + 1]]``, and the pairs of them that meet at a right
        angle (the corners that make double images) are the rows ``cpair[cstart[i]:cstart[i + 1]]``.
        The radius of particle i is reach * max(h_i, max_j h_j) over its neighbours j, so a
        wall between i and any neighbour is always in i's list (pair blocking is symmetric).
        """
        n = x.shape[0]
        wstart = np.zeros(n + 1, dtype=np.int64)
        cstart = np.zeros(n + 1, dtype=np.int64)
        if self.seg.shape[0] == 0 or n == 0:
            return (wstart, np.zeros(0, dtype=np.int64), cstart,
                    np.zeros((0, 2), dtype=np.int64))
        args = (x, y, h, nstart, nbr, reach, self.seg, self.start, self.items, self.clear,
                self.xmin, self.ymin, self.lv_bucket, self.lv_nbx, self.lv_nby, self.lv_off,
                float(h.max()))
        count = np.empty(n, dtype=np.int64)
        while True:  # one scan into rows of ``width``; again, wider, if a row overflowed
            rows = np.empty((n, self.width), dtype=np.int64)
            _near_scan(*args, rows, count)
            widest = int(count.max())
            if widest <= self.width:
                break
            self.width = widest
        np.cumsum(count, out=wstart[1:])
        wseg = np.empty(wstart[-1], dtype=np.int64)
        _gather_rows(rows, wstart, wseg)
        corners = (wstart, wseg, self.pstart, self.partner, cstart)
        _corner_scan(*corners, np.zeros((0, 2), dtype=np.int64), False)
        np.cumsum(cstart, out=cstart)
        cpair = np.empty((cstart[-1], 2), dtype=np.int64)
        _corner_scan(*corners, cpair, True)
        return wstart, wseg, cstart, cpair


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


def _clearance(occupied: np.ndarray, bucket: float) -> np.ndarray:
    """Per bucket (flat, row-major), a lower bound [m] on the distance to any listed segment:
    bucket * (e - sqrt 2) with e the distance transform of the unoccupied buckets (inf when
    no bucket lists a segment)."""
    if not occupied.any():
        return np.full(occupied.size, np.inf)
    e = ndimage.distance_transform_edt(~occupied)
    return (bucket * np.maximum(e - math.sqrt(2.0), 0.0)).ravel()


@njit(inline="always", cache=True)
def segment_distance(px, py, x1, y1, x2, y2):
    """Distance [m] from point p to the segment (x1, y1)-(x2, y2)."""
    ex = x2 - x1
    ey = y2 - y1
    t = ((px - x1) * ex + (py - y1) * ey) / (ex * ex + ey * ey)
    t = min(max(t, 0.0), 1.0)
    return math.hypot(px - x1 - t * ex, py - y1 - t * ey)


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
def _near_scan(x, y, h, nstart, nbr, reach, seg, bstart, items, clear, xmin, ymin, lv_bucket,
               lv_nbx, lv_nby, lv_off, h_top, rows, count):
    """Count (into ``count[i]``) and list (into ``rows[i]``, in index order, as far as the row
    is wide) each particle's segments within reach * max(h_i, max_j h_j); a particle inside
    the level-0 grid whose radius is below its bucket's ``clear`` distance has none (tested
    first with the largest h of all, ``h_top``, before its neighbours are walked). The
    buckets walked are those of the finest level at least half as wide as the radius."""
    width = rows.shape[1]
    top = lv_bucket.shape[0] - 1
    for i in prange(x.shape[0]):
        count[i] = 0
        cx = (x[i] - xmin) / lv_bucket[0]
        cy = (y[i] - ymin) / lv_bucket[0]
        inside = 0.0 <= cx < lv_nbx[0] and 0.0 <= cy < lv_nby[0]
        if inside and reach * h_top < clear[int(cy) * lv_nbx[0] + int(cx)]:
            continue
        hr = h[i]
        for k in range(nstart[i], nstart[i + 1]):
            hr = max(hr, h[nbr[k]])
        radius = reach * hr
        if inside and radius < clear[int(cy) * lv_nbx[0] + int(cx)]:
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
                    if not first_visit(seg, s, bx, by, bx0, by0, xmin, ymin, bucket, nbx, nby):
                        continue
                    if segment_distance(x[i], y[i], seg[s, 0], seg[s, 1], seg[s, 2],
                                        seg[s, 3]) < radius:
                        if k < width:
                            rows[i, k] = s
                        k += 1
        count[i] = k
        if k <= width:
            _sort_run(rows[i], 0, k)


@njit(parallel=True, cache=True)
def _gather_rows(rows, wstart, wseg):
    """Copy the first wstart[i + 1] - wstart[i] entries of each row into the CSR ``wseg``."""
    for i in prange(rows.shape[0]):
        for k in range(wstart[i + 1] - wstart[i]):
            wseg[wstart[i] + k] = rows[i, k]


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
    pairs = set()
    for group in np.split(order // 2, cut):
        for a in range(group.size):
            for b in range(a + 1, group.size):
                s1, s2 = sorted((int(group[a]), int(group[b])))
                if s1 != s2 and right_corner(seg, s1, s2):
                    pairs.add((s1, s2))
    pairs = np.array(sorted(pairs), dtype=np.int64).reshape(-1, 2)
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


@njit(inline="always", cache=True)
def crosses(ax, ay, bx, by, x1, y1, x2, y2):
    """True if the segment a-b meets the wall segment (x1, y1)-(x2, y2)."""
    dx = bx - ax
    dy = by - ay
    ex = x2 - x1
    ey = y2 - y1
    den = dx * ey - dy * ex
    if den == 0.0:
        return False
    qx = x1 - ax
    qy = y1 - ay
    t = (qx * ey - qy * ex) / den
    s = (qx * dy - qy * dx) / den
    return 0.0 <= t <= 1.0 and 0.0 <= s <= 1.0


TIE_SHIFT = (0.6e-7, 0.8e-7)
"""Offset [m] of the sight lines of :func:`hides` (a fixed direction, 1e-7 m long)."""


@njit(inline="always", cache=True)
def hides(ax, ay, bx, by, seg, s):
    """True if segment s lies across the sight line from a to b.

    The test is :func:`crosses` on the line shifted by ``TIE_SHIFT``: a line through an end
    point of s, such as a vertex two segments share (common where vertices lie on DEM cell
    corners and particles on cell centres), then passes on one definite side of it. Pair
    blocking and the mirror images use this one test, so a hidden point is imaged through one
    segment only, and a neighbour is either seen or replaced by its image, never both.
    """
    dx, dy = TIE_SHIFT
    return crosses(ax + dx, ay + dy, bx + dx, by + dy, seg[s, 0], seg[s, 1], seg[s, 2],
                   seg[s, 3])


SIGHT_SLACK = 1e-6
"""Slack [m] of the distance tests that skip far segments: a segment that :func:`hides` a
point at distance r from particle i lies within r + |TIE_SHIFT| (1e-7 m) of i, so one
farther than r + SIGHT_SLACK neither blocks the pair nor makes an image within r (the margin
also covers rounding, ~1e-10 m at 1e5 m from the origin)."""


@njit(parallel=True, cache=True)
def blocked_pairs(rows, x, y, nstart, nbr, wstart, wseg, seg, out, wdist):
    """out[q] = True when a wall near particle i separates it from its neighbour nbr[q], for
    the particles i in ``rows`` (those whose neighbours are listed).

    Also ``wdist[k]``, the distance [m] from particle i to its near segment wseg[k]: a segment
    farther from i than r_ij + SIGHT_SLACK cannot hide j (:func:`hides`), and the density
    summation and the forces skip the images of segments beyond their support the same way.
    Computed once per step (positions fixed) for the density iterations and the forces, which
    then skip blocked pairs and their mirror images at the cost of a lookup.
    """
    for r in prange(rows.shape[0]):
        i = rows[r]
        xi = x[i]
        yi = y[i]
        nearest = np.inf
        for k in range(wstart[i], wstart[i + 1]):
            s = wseg[k]
            wdist[k] = segment_distance(xi, yi, seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
            nearest = min(nearest, wdist[k])
        if wstart[i + 1] == wstart[i]:
            out[nstart[i]:nstart[i + 1]] = False
            continue
        for q in range(nstart[i], nstart[i + 1]):
            j = nbr[q]
            rx = xi - x[j]
            ry = yi - y[j]
            reach = math.sqrt(rx * rx + ry * ry) + SIGHT_SLACK
            hit = False
            if reach >= nearest:  # else no segment is that close, and none hides j
                for k in range(wstart[i], wstart[i + 1]):
                    if wdist[k] <= reach and hides(xi, yi, x[j], y[j], seg, wseg[k]):
                        hit = True
                        break
            out[q] = hit


@njit(inline="always", cache=True)
def mirror(px, py, x1, y1, x2, y2):
    """Mirror image of p about the wall's line, and whether p's foot lies on the segment.

    Returns (x', y', on_segment, nx, ny) with (nx, ny) the unit normal of the wall.
    """
    ex = x2 - x1
    ey = y2 - y1
    ll = ex * ex + ey * ey
    t = ((px - x1) * ex + (py - y1) * ey) / ll
    fx = x1 + t * ex
    fy = y1 + t * ey
    inv = 1.0 / math.sqrt(ll)
    return 2.0 * fx - px, 2.0 * fy - py, 0.0 <= t <= 1.0, -ey * inv, ex * inv


@njit(inline="always", cache=True)
def wall_image(xi, yi, px, py, seg, s):
    """Mirror image of p about segment s as seen from particle i: (x', y', ok).

    ok: s hides the image from i (:func:`hides`: the line from i to it passes through the
    segment); p's foot may fall beyond the segment's ends.
    """
    xm, ym, _, _, _ = mirror(px, py, seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
    ok = hides(xi, yi, xm, ym, seg, s)
    return xm, ym, ok


@njit(inline="always", cache=True)
def corner_image(px, py, seg, s1, s2):
    """Double mirror image of p about segments s1 then s2, which share a vertex.

    Returns (x'', y'', ok): ok is False unless p's foot lies on both segments.
    """
    x1, y1, on1, _, _ = mirror(px, py, seg[s1, 0], seg[s1, 1], seg[s1, 2], seg[s1, 3])
    _, _, on2, _, _ = mirror(px, py, seg[s2, 0], seg[s2, 1], seg[s2, 2], seg[s2, 3])
    x2, y2, _, _, _ = mirror(x1, y1, seg[s2, 0], seg[s2, 1], seg[s2, 2], seg[s2, 3])
    return x2, y2, on1 and on2


@njit(parallel=True, cache=True)
def drift(x, y, u, v, dt, wstart, wseg, seg):
    """Drift x <- x + dt v, reflecting moves that cross a wall. Returns the reflection count.

    A move x_old -> x that meets a segment of the particle's near-wall list is mirrored about
    the segment's line and the velocity's normal component reversed; after three reflections
    (a corner) the particle is put back to x_old with zero velocity.
    """
    total = 0
    for i in prange(x.shape[0]):
        x_old = x[i]
        y_old = y[i]
        x[i] = x_old + dt * u[i]
        y[i] = y_old + dt * v[i]
        hits = 0
        for _ in range(3):
            hit = -1
            for k in range(wstart[i], wstart[i + 1]):
                s = wseg[k]
                if crosses(x_old, y_old, x[i], y[i], seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3]):
                    hit = s
                    break
            if hit < 0:
                break
            hits += 1
            xm, ym, _, nx, ny = mirror(x[i], y[i], seg[hit, 0], seg[hit, 1], seg[hit, 2],
                                       seg[hit, 3])
            x[i] = xm
            y[i] = ym
            vn = u[i] * nx + v[i] * ny
            u[i] -= 2.0 * vn * nx
            v[i] -= 2.0 * vn * ny
        if hits >= 3:
            x[i] = x_old
            y[i] = y_old
            u[i] = 0.0
            v[i] = 0.0
        total += hits
    return total
