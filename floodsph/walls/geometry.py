"""Wall geometry: segments from polylines, distances, crossings and reflections.

Walls are straight segments (ns, 4): x1, y1, x2, y2 in local metres. These small kernels are
shared by the near-wall index (``floodsph.walls.index``), the sight tests and the crossing
guard (``floodsph.walls.sight``), the mirror images (``floodsph.walls.images``) and the
refinement's daughter placement.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


def segments_from_polylines(polylines) -> np.ndarray:
    """Stack polylines ((k, 2) arrays, local metres) into segments (ns, 4): x1, y1, x2, y2."""
    segs = []
    for line in polylines:
        pts = np.asarray(line, dtype=np.float64)
        for a, b in zip(pts[:-1], pts[1:], strict=True):
            if np.hypot(*(b - a)) > 0.0:
                segs.append((a[0], a[1], b[0], b[1]))
    return np.asarray(segs, dtype=np.float64).reshape(-1, 4)


@njit(inline="always", cache=True)
def segment_distance(px, py, x1, y1, x2, y2):
    """Distance [m] from point p to the segment (x1, y1)-(x2, y2)."""
    ex = x2 - x1
    ey = y2 - y1
    t = ((px - x1) * ex + (py - y1) * ey) / (ex * ex + ey * ey)
    t = min(max(t, 0.0), 1.0)
    return math.hypot(px - x1 - t * ex, py - y1 - t * ey)


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
