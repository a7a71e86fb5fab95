"""Shapes of the scenario's polygons and walls, checked when the scenario is loaded.

A polygon (``initial_water[i].polygon``, ``sinks[i].polygon``) needs 3 distinct points, a
non-zero area and an outline that does not cross itself; a wall (``walls[i].polyline``) needs
2 distinct points and must neither cross nor run back along itself, and a closed wall (first
point == last, a building footprint) must be a usable polygon.

A crossing is two segments meeting at a point inside both: a bow-tie reservoir or a figure-8,
a digitising error (two vertices swapped) whose even-odd fill is not the area the user drew.
Touching is allowed: an outline may meet itself at a vertex or run back along an edge, which
is how one ring describes an area with a hole (a keyhole ring: out along a bridge edge, round
the hole, back along the bridge; ``floodsph.io.polygons.points_in_polygon`` fills it by the
even-odd rule, hole outside). A wall may touch itself at a vertex (a loop closing onto its own
line) but not run back along itself.

Meetings are found with shapely (segment pairs from an STR tree). Where they lie on the DEM is
checked later (:mod:`floodsph.checks.placement`).
"""

from __future__ import annotations

import numpy as np
import shapely

from floodsph.io.polygons import polygon_area


def _distinct_path(points) -> np.ndarray:
    """The points as a (k, 2) array with consecutive repeats removed."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    keep = np.ones(len(p), dtype=bool)
    keep[1:] = np.any(p[1:] != p[:-1], axis=1)
    return p[keep]


def point_text(point) -> str:
    """``[x, y]`` to the millimetre (10 significant digits), for messages."""
    return f"[{point[0]:.10g}, {point[1]:.10g}]"


TOUCH_TOLERANCE_M = 1e-6
"""Two segments meeting within this distance [m] of a vertex of either touch there."""


def self_crossing(path: np.ndarray, closed: bool, overlaps: bool = False
                  ) -> tuple[float, float] | None:
    """A point where the line through ``path`` (no consecutive repeats) crosses itself, or
    None; with ``overlaps``, also a point where it runs back along itself.

    ``closed``: the last point joins the first (a ring; pass it without the repeated first
    point). Segments that meet at a vertex of either only touch.
    """
    ends = np.vstack([path, path[:1]]) if closed else path
    starts, stops = ends[:-1], ends[1:]
    segments = shapely.linestrings(np.stack([starts, stops], axis=1))
    if len(segments) < 2 or shapely.is_simple(shapely.linestrings(ends)):
        return None
    first, second = shapely.STRtree(segments).query(segments, predicate="intersects")
    for i, j in zip(first, second, strict=True):
        if j <= i:
            continue
        meet = shapely.intersection(segments[i], segments[j])
        point = shapely.get_coordinates(meet)[0]
        if meet.length > 0.0:
            if overlaps:
                return tuple(point)
            continue
        vertices = np.array([starts[i], stops[i], starts[j], stops[j]])
        if np.min(np.hypot(*(vertices - point).T)) > TOUCH_TOLERANCE_M:
            return tuple(point)
    return None


def polygon_problem(points) -> str | None:
    """Why ``points`` (a ring, closed or not) is not a usable polygon, or None."""
    path = _distinct_path(points)
    if len(path) > 1 and np.array_equal(path[0], path[-1]):
        path = path[:-1]
    distinct = len(np.unique(path, axis=0))
    if distinct < 3:
        return f"a polygon needs at least 3 distinct points, got {distinct}"
    if np.linalg.matrix_rank(path - path[0]) < 2:
        return "polygon encloses no area (its points are collinear)"
    crossing = self_crossing(path, closed=True)
    if crossing is not None:
        return (f"the polygon crosses itself near {point_text(crossing)}; draw its outline once "
                "around the area, without crossings")
    if polygon_area(path) <= 0.0:
        return "polygon encloses no area (its outline runs out and back along the same edges)"
    return None


def polyline_problem(points) -> str | None:
    """Why ``points`` is not a usable wall, or None; a closed one (first == last) is a
    footprint and must be a valid polygon."""
    path = _distinct_path(points)
    if len(path) < 2:
        return "the wall has zero length (all its points are the same)"
    if np.array_equal(path[0], path[-1]):
        problem = polygon_problem(path)
        return None if problem is None else f"closed wall (a footprint): {problem}"
    crossing = self_crossing(path, closed=False, overlaps=True)
    if crossing is not None:
        return (f"the wall crosses or runs back along itself near {point_text(crossing)}; split "
                "it into separate [[walls]] if the crossing is meant")
    return None
