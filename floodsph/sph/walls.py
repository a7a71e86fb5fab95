"""Closed boundaries as wall segments: mirror particles, pair blocking and a crossing guard.

A wall is a polyline (a closed one is a solid footprint); the DEM border is four of them when
the edges are closed. Three mechanisms keep water on its side:

1. **Mirror particles.** For a particle i near a wall segment, every neighbour j on i's side
   (i itself included) whose foot point falls on the segment contributes a mirror image
   x_j' = 2 f_j - x_j (f_j its foot on the segment's line), with the same mass, density,
   alpha and h and the mirrored velocity v_j' = v_j - 2 (v_j . n) n (free slip). On a straight
   wall this completes the kernel exactly, so the depth and the pressure of still water along
   a wall are those of the interior (zero-order consistency, the property the modified virtual
   boundary particles of Vacondio, Rogers & Stansby, IJNMF 69 (2012) 226-253 approximate).
   An image counts only if the line from i to it passes through the segment that made it,
   so that behind a convex corner (a building's) each point is imaged once, not by both faces.
   In a corner where two near segments meet, j's foot on both gives a third image, the
   reflection of j's first image about the second wall (the point reflection through a
   right-angled corner), which completes the kernel there too.
2. **Pair blocking.** Particles on opposite sides of a wall do not interact.
3. **Crossing guard.** A drift step that would cross a wall is reflected about it (position and
   normal velocity), so no particle ever crosses, whatever the time step (:func:`drift`).

Near-wall lists are CSR arrays ``(wstart, wseg)`` built with the neighbour lists, with the
same skin, for the particles within the interaction radius of a segment (and kept as long as
the neighbour lists are: a wall within the support now was within the skinned radius at the
build); most particles have none and pay nothing.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange


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
    """Static buckets of wall segments for fast near-wall queries.

    Each square bucket of side ``bucket`` lists the segments whose bounding box, grown by
    ``margin``, overlaps it; a query of radius <= margin then needs only its own bucket.
    Queries of a larger radius scan all segments.
    """

    def __init__(self, seg: np.ndarray, bounds, bucket: float, margin: float):
        self.seg = np.ascontiguousarray(seg, dtype=np.float64).reshape(-1, 4)
        xmin, ymin, xmax, ymax = bounds
        self.xmin, self.ymin = float(xmin) - margin, float(ymin) - margin
        self.bucket = float(bucket)
        self.margin = float(margin)
        self.nbx = max(1, int((xmax - xmin + 2 * margin) / bucket) + 1)
        self.nby = max(1, int((ymax - ymin + 2 * margin) / bucket) + 1)
        lists = [[] for _ in range(self.nbx * self.nby)]
        for s, (x1, y1, x2, y2) in enumerate(self.seg):
            bx0 = int((min(x1, x2) - margin - self.xmin) // bucket)
            bx1 = int((max(x1, x2) + margin - self.xmin) // bucket)
            by0 = int((min(y1, y2) - margin - self.ymin) // bucket)
            by1 = int((max(y1, y2) + margin - self.ymin) // bucket)
            for by in range(max(by0, 0), min(by1, self.nby - 1) + 1):
                for bx in range(max(bx0, 0), min(bx1, self.nbx - 1) + 1):
                    lists[by * self.nbx + bx].append(s)
        counts = np.array([len(v) for v in lists], dtype=np.int64)
        self.start = np.zeros(len(lists) + 1, dtype=np.int64)
        np.cumsum(counts, out=self.start[1:])
        self.items = np.array([s for v in lists for s in v], dtype=np.int64)

    def near_lists(self, x, y, h, nstart, nbr, reach):
        """CSR lists (wstart, wseg) of the segments within each particle's reach.

        The radius of particle i is reach * max(h_i, max_j h_j) over its neighbours j, so a
        wall between i and any neighbour is always in i's list (pair blocking is symmetric).
        """
        n = x.shape[0]
        wstart = np.zeros(n + 1, dtype=np.int64)
        if self.seg.shape[0] == 0 or n == 0:
            return wstart, np.zeros(0, dtype=np.int64)
        args = (x, y, h, float(h.max()), nstart, nbr, reach, self.seg, self.start, self.items,
                self.xmin, self.ymin, self.bucket, self.nbx, self.nby, self.margin)
        _near_scan(*args, wstart, np.zeros(0, dtype=np.int64), False)
        np.cumsum(wstart, out=wstart)
        wseg = np.empty(wstart[-1], dtype=np.int64)
        _near_scan(*args, wstart, wseg, True)
        return wstart, wseg


@njit(inline="always", cache=True)
def segment_distance(px, py, x1, y1, x2, y2):
    """Distance [m] from point p to the segment (x1, y1)-(x2, y2)."""
    ex = x2 - x1
    ey = y2 - y1
    t = ((px - x1) * ex + (py - y1) * ey) / (ex * ex + ey * ey)
    t = min(max(t, 0.0), 1.0)
    return math.hypot(px - x1 - t * ex, py - y1 - t * ey)


@njit(parallel=True, cache=True)
def _near_scan(x, y, h, h_max, nstart, nbr, reach, seg, bstart, items, bxmin, bymin, bucket,
               nbx, nby, margin, wstart, wseg, fill):
    for i in prange(x.shape[0]):
        bx = min(max(int((x[i] - bxmin) // bucket), 0), nbx - 1)
        by = min(max(int((y[i] - bymin) // bucket), 0), nby - 1)
        b = by * nbx + bx
        if bstart[b] == bstart[b + 1] and reach * h_max <= margin:
            continue  # no segment within the margin, and no radius beyond it: none listed
        hr = h[i]
        for k in range(nstart[i], nstart[i + 1]):
            hr = max(hr, h[nbr[k]])
        radius = reach * hr
        k = 0
        if radius <= margin:
            for q in range(bstart[b], bstart[b + 1]):
                s = items[q]
                dist = segment_distance(x[i], y[i], seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
                if dist < radius:
                    if fill:
                        wseg[wstart[i] + k] = s
                    k += 1
        else:
            for s in range(seg.shape[0]):
                dist = segment_distance(x[i], y[i], seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
                if dist < radius:
                    if fill:
                        wseg[wstart[i] + k] = s
                    k += 1
        if not fill:
            wstart[i + 1] = k


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


@njit(inline="always", cache=True)
def blocked(xi, yi, xj, yj, wstart, wseg, seg, i):
    """True if a wall near particle i separates it from the point (xj, yj)."""
    for k in range(wstart[i], wstart[i + 1]):
        s = wseg[k]
        if crosses(xi, yi, xj, yj, seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3]):
            return True
    return False


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

    ok requires p's foot on the segment and the line from i to the image to pass through it.
    """
    xm, ym, on, _, _ = mirror(px, py, seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
    ok = on and crosses(xi, yi, xm, ym, seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
    return xm, ym, ok


@njit(inline="always", cache=True)
def corner_image(px, py, seg, s1, s2):
    """Double mirror image of p about segments s1 then s2 if they share a vertex.

    Returns (x'', y'', ok): ok is False unless the segments meet and p's foot lies on both.
    """
    shared = False
    for a in range(2):
        for b in range(2):
            if seg[s1, 2 * a] == seg[s2, 2 * b] and seg[s1, 2 * a + 1] == seg[s2, 2 * b + 1]:
                shared = True
    if not shared:
        return px, py, False
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


def mask_boundary_segments(valid: np.ndarray, dx: float, dy: float) -> np.ndarray:
    """Wall segments along the cell edges between valid and invalid (nodata) cells.

    Collinear unit edges are merged into runs, so a straight nodata border is one segment.
    The grid border itself is not included (see :func:`box_polyline`). Row 0 is south.
    """
    ok = np.asarray(valid, dtype=bool)
    ny, nx = ok.shape
    segs = []
    # vertical edges between columns j-1 and j (x = j dx), for j = 1..nx-1
    diff_v = ok[:, 1:] != ok[:, :-1]
    for j in range(nx - 1):
        segs.extend((
            ((j + 1) * dx, a * dy, (j + 1) * dx, b * dy) for a, b in _runs(diff_v[:, j])
        ))
    diff_h = ok[1:, :] != ok[:-1, :]
    for i in range(ny - 1):
        segs.extend((
            (a * dx, (i + 1) * dy, b * dx, (i + 1) * dy) for a, b in _runs(diff_h[i, :])
        ))
    return np.asarray(segs, dtype=np.float64).reshape(-1, 4)


def _runs(flags: np.ndarray):
    """(start, end) index pairs of the runs of True in a 1-D boolean array."""
    padded = np.concatenate(([False], flags, [False]))
    edges = np.flatnonzero(padded[1:] != padded[:-1])
    return zip(edges[0::2], edges[1::2], strict=True)
