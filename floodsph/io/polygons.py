"""Polygon checks and point-in-polygon tests for scenario polygons (no shapely).

A polygon is a ``(k, 2)`` array of vertices; it may be given closed (first == last) or
open. :func:`check_polygon` refuses degenerate ones with a message naming the key path.
"""

from __future__ import annotations

import numpy as np

from floodsph.errors import InputError


def check_polygon(points, name: str) -> np.ndarray:
    """Validate a polygon and return it as an open ``(k, 2)`` float64 array.

    Refused (InputError naming ``name``, e.g. ``initial_water[0].polygon``): not a list of
    [x, y] pairs, non-finite coordinates, fewer than 3 distinct vertices, or zero area
    (shoelace formula A = 1/2 |sum(x_i y_{i+1} - x_{i+1} y_i)|).
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
    """Unsigned area of a simple polygon by the shoelace formula [m2]."""
    x, y = p[:, 0], p[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)))


def points_in_polygon(x: np.ndarray, y: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Even-odd rule: True where the point (x, y) is inside the polygon ``poly`` (k, 2).

    A horizontal ray from each point crosses edge (a, b) when the edge straddles the
    point's y (half-open test ``(ya > y) != (yb > y)``) and the crossing abscissa
    ``xa + (y - ya)(xb - xa)/(yb - ya)`` lies right of the point; inside = odd crossings.
    """
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    inside = np.zeros(np.broadcast(x, y).shape, dtype=bool)
    xa, ya = poly[:, 0], poly[:, 1]
    xb, yb = np.roll(xa, -1), np.roll(ya, -1)
    for k in range(len(poly)):
        if ya[k] == yb[k]:
            continue
        straddles = (ya[k] > y) != (yb[k] > y)
        x_cross = xa[k] + (y - ya[k]) * (xb[k] - xa[k]) / (yb[k] - ya[k])
        inside ^= straddles & (x < x_cross)
    return inside
