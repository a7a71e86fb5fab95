"""Wall junctions: walls that cross or meet are cut there, so that they share a vertex.

The mirror images of ``floodsph.walls`` complete the kernel in a right-angled corner only
where the two segments share an end point (the corner's point reflection,
``walls.corner_image``). Walls from different sources meet elsewhere: a levee drawn across
the DEM border crosses the border's side segment, a wall may end on another (a T), and two
user walls may cross (an X). Without a shared vertex such a corner gets single images only,
and still water in it reads up to 6 % too shallow and starts to move (0.28 m/s within 5 s in
right-angled crossings of 5 m particles, 2 m deep: tests/sph/test_sph_dynamics.py).

:func:`split_at_junctions` cuts every segment at the points where another segment crosses its
interior or ends on it, at exactly the same coordinates for both, so that every junction is
a vertex of each wall through it. Collinear overlaps are left as they are.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _cut_points(seg, order, tol, fill, at, point):
    """Count (``fill`` False) or list the cuts of each segment: returns the count per segment.

    ``order`` sorts the segments by their smallest x, so that the pairs of a are swept only
    until a later segment starts beyond a's largest x. For segments a and b whose bounding
    boxes overlap (within ``tol``):

    * an end point of b within ``tol`` [m] of a's interior (more than ``tol`` from a's ends)
      cuts a at that end point (a T);
    * if no end of either lies on the other, the interiors crossing at P cut both at P,
      P = A1 + t (A2 - A1) with t from the 2 x 2 solve on a (an X).

    With ``fill`` the cuts of segment s are written to ``point[at[s] + k]`` (x, y), k counting
    from 0; ``at`` holds the offsets of a counting pass.
    """
    ns = seg.shape[0]
    count = np.zeros(ns, dtype=np.int64)
    for ka in range(ns):
        a = order[ka]
        ax1, ay1, ax2, ay2 = seg[a, 0], seg[a, 1], seg[a, 2], seg[a, 3]
        for kb in range(ka + 1, ns):
            b = order[kb]
            bx1, by1, bx2, by2 = seg[b, 0], seg[b, 1], seg[b, 2], seg[b, 3]
            if min(bx1, bx2) > max(ax1, ax2) + tol:
                break
            if (max(bx1, bx2) + tol < min(ax1, ax2) or max(ay1, ay2) + tol < min(by1, by2)
                    or max(by1, by2) + tol < min(ay1, ay2)):
                continue
            touched = False
            for first, second in ((a, b), (b, a)):
                for end in range(2):
                    ex, ey = seg[second, 2 * end], seg[second, 2 * end + 1]
                    if _on_interior(seg, first, ex, ey, tol):
                        if fill:
                            point[at[first] + count[first], 0] = ex
                            point[at[first] + count[first], 1] = ey
                        count[first] += 1
                        touched = True
            if touched or _shares_end(seg, a, b, tol):
                continue
            dx, dy = ax2 - ax1, ay2 - ay1
            fx, fy = bx2 - bx1, by2 - by1
            den = dx * fy - dy * fx
            if den == 0.0:
                continue
            qx, qy = bx1 - ax1, by1 - ay1
            t = (qx * fy - qy * fx) / den
            s = (qx * dy - qy * dx) / den
            if 0.0 < t < 1.0 and 0.0 < s < 1.0:
                px, py = ax1 + t * dx, ay1 + t * dy
                for s_cut in (a, b):
                    if fill:
                        point[at[s_cut] + count[s_cut], 0] = px
                        point[at[s_cut] + count[s_cut], 1] = py
                    count[s_cut] += 1
    return count


@njit(inline="always", cache=True)
def _on_interior(seg, s, px, py, tol):
    """True if (px, py) lies within tol of segment s and more than tol from both its ends."""
    x1, y1, x2, y2 = seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3]
    ex, ey = x2 - x1, y2 - y1
    length = np.sqrt(ex * ex + ey * ey)
    along = ((px - x1) * ex + (py - y1) * ey) / length
    across = abs((px - x1) * ey - (py - y1) * ex) / length
    return across <= tol and tol < along < length - tol


@njit(inline="always", cache=True)
def _shares_end(seg, a, b, tol):
    """True if an end point of a lies within tol of an end point of b."""
    for i in range(2):
        for j in range(2):
            if (abs(seg[a, 2 * i] - seg[b, 2 * j]) <= tol
                    and abs(seg[a, 2 * i + 1] - seg[b, 2 * j + 1]) <= tol):
                return True
    return False


def split_at_junctions(seg: np.ndarray, tol: float) -> np.ndarray:
    """Segments (ns, 4) cut at every junction with another segment (module docstring).

    ``tol`` [m]: an end point this close to another segment's interior lies on it. Each
    segment is replaced by its pieces between the sorted cut points, in order, in its own
    direction; pieces no longer than ``tol`` are dropped.
    """
    seg = np.ascontiguousarray(seg, dtype=np.float64).reshape(-1, 4)
    order = np.argsort(np.minimum(seg[:, 0], seg[:, 2]), kind="stable")
    count = _cut_points(seg, order, tol, False, np.zeros(0, np.int64), np.zeros((0, 2)))
    if not count.any():
        return seg
    at = np.concatenate([[0], np.cumsum(count)[:-1]])
    point = np.empty((int(count.sum()), 2))
    _cut_points(seg, order, tol, True, at, point)
    pieces = []
    for s, (x1, y1, x2, y2) in enumerate(seg):
        cuts = point[at[s]:at[s] + count[s]]
        along = (cuts[:, 0] - x1) * (x2 - x1) + (cuts[:, 1] - y1) * (y2 - y1)
        nodes = np.vstack([[x1, y1], cuts[np.argsort(along, kind="stable")], [x2, y2]])
        for p, q in zip(nodes[:-1], nodes[1:], strict=True):
            if np.hypot(*(q - p)) > tol:
                pieces.append((p[0], p[1], q[0], q[1]))
    return np.asarray(pieces, dtype=np.float64).reshape(-1, 4)
