"""Polygon checks and inside tests for scenario polygons, through shapely.

A polygon is a ``(k, 2)`` array of vertices; it may be given closed (first == last) or
open. :func:`check_polygon` refuses degenerate ones with a message naming the key path.
"""

from __future__ import annotations

import numpy as np
import shapely

from floodsph.errors import InputError


def check_polygon(points, name: str) -> np.ndarray:
    """Validate a polygon and return it as an open ``(k, 2)`` float64 array.

    Refused (InputError naming ``name``, e.g. ``initial_water[0].polygon``): not a list of
    [x, y] pairs, non-finite coordinates, fewer than 3 distinct vertices, or zero area
    (:func:`polygon_area`).
    """
    try:
        p = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a list of [x, y] pairs") from None
    if p.ndim != 2 or p.shape[1] != 2:
        raise InputError(f"{name}: expected a list of [x, y] pairs, got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise InputError(f"{name}: coordinates must be finite numbers")
    if len(p) > 1 and np.array_equal(p[0], p[-1]):
        p = p[:-1]
    if len(np.unique(p, axis=0)) < 3:
        raise InputError(f"{name}: a polygon needs at least 3 distinct points, got {len(p)}")
    if polygon_area(p) <= 0.0:
        raise InputError(f"{name}: the polygon has zero area (its points are collinear)")
    return np.ascontiguousarray(p)


def polygon_area(p: np.ndarray) -> float:
    """Area [m2] enclosed by the ring ``p`` (k, 2): the absolute shoelace sum
    A = 1/2 |sum(x_i y_(i+1) - x_(i+1) y_i)| that shapely computes for a polygon."""
    return float(shapely.area(shapely.polygons(np.asarray(p, dtype=np.float64))))


def points_in_polygon(x: np.ndarray, y: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """True where the point (x, y) lies inside the ring ``poly`` (k, 2) or on its outline.

    shapely's point locator counts the crossings of a ray from the point with the ring's
    edges, so a ring that describes a hole through a zero-width slit (a keyhole ring, out
    along the slit, round the hole, back) leaves the hole outside: the even-odd rule.
    """
    ring = shapely.polygons(np.asarray(poly, dtype=np.float64))
    shapely.prepare(ring)
    return shapely.intersects_xy(ring, np.asarray(x, dtype=np.float64),
                                 np.asarray(y, dtype=np.float64))
