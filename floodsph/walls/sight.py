"""What a wall hides, and the crossing guard.

* :func:`hides`: does a segment lie across the sight line between two points (with a fixed tie
  shift, so a line through a vertex passes on one definite side of it).
* :func:`blocked_pairs`: particles on opposite sides of a wall do not interact.
* :func:`drift`: a drift step that would cross a wall is reflected about it (position and
  normal velocity), so no particle ever crosses, whatever the time step.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.walls.geometry import crosses, mirror, segment_distance

TIE_SHIFT = (0.6e-3, 0.8e-3)
"""Offset [m] of the sight lines of :func:`hides` (a fixed direction, 1 mm long). Particles
seeded on DEM cell centres see each other along lines through the cell corners, where a
walled nodata border has its vertices: the shift must exceed what a lake at rest moves under
a slight disturbance, or pairs flip between seen and hidden and the depth jumps by metres
(a Malpasset reservoir disturbed by 1e-6 m/s moved 5e-8 m in a step, across a 1e-7 m shift),
and stay far below a particle's size and the walls' own accuracy."""


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


NEAR_SHARE = 0.9
"""Share of a bucket's candidate radius up to which :func:`drift` tests the bucket's
candidates alone (the margin covers the rounding of the widened boxes)."""

SIGHT_SLACK = 1e-2
"""Slack [m] of the distance tests that skip far segments: a segment that :func:`hides` a
point at distance r from particle i lies within r + |TIE_SHIFT| (1 mm) of i, so one
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
def _first_crossing(x0, y0, x1, y1, seg, candidates, lo, hi):
    """The first segment of ``candidates[lo:hi]`` that the move (x0, y0) -> (x1, y1) crosses,
    or -1."""
    for q in range(lo, hi):
        s = candidates[q]
        if crosses(x0, y0, x1, y1, seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3]):
            return s
    return -1


@njit(inline="always", cache=True)
def _bucket_of(px, py, xmin, ymin, inv_bucket, nbx, nby):
    """Flat index of the bucket holding (px, py) on a grid of nbx x nby square buckets of
    side 1 / ``inv_bucket`` [m] from (xmin, ymin), or -1 outside it."""
    cx = (px - xmin) * inv_bucket
    cy = (py - ymin) * inv_bucket
    if 0.0 <= cx < nbx and 0.0 <= cy < nby:
        return int(cy) * nbx + int(cx)
    return -1


@njit(parallel=True, cache=True)
def drift(x, y, u, v, dt, seg, fine, near, items):
    """Drift x <- x + dt v, reflecting moves that cross a wall. Returns the reflection count.

    A move x_old -> x that crosses a segment is mirrored about the segment's line and the
    velocity's normal component reversed; after three reflections (a corner) the particle is
    put back to x_old with zero velocity. The segments tested, in increasing index, are the
    candidates of x_old's bucket in the ``fine`` candidate table of
    ``floodsph.walls.index.WallIndex`` (a ``DriftTable``: buckets of side ``bucket`` [m],
    bucket b listing ``items[start[b]:start[b + 1]]``, every segment whose box widened by
    ``radius`` [m] overlaps it) if the move's length L is below ``NEAR_SHARE`` times its
    radius, else in the ``near`` table on the same terms: each point of the move, and of its
    reflections, lies within L of x_old, so they hold every segment the move can cross. A
    longer move, or one from outside the buckets, tests every segment, the last
    ``seg.shape[0]`` entries of ``items``.
    """
    f_start, xmin, ymin, f_bucket, f_nbx, f_nby, f_radius = fine
    n_start, _, _, n_bucket, n_nbx, n_nby, n_radius = near
    f_reach2 = (NEAR_SHARE * f_radius) ** 2
    n_reach2 = (NEAR_SHARE * n_radius) ** 2
    f_inv = 1.0 / f_bucket
    n_inv = 1.0 / n_bucket
    every = items.shape[0] - seg.shape[0]
    total = 0
    for i in prange(x.shape[0]):
        x_old = x[i]
        y_old = y[i]
        x[i] = x_old + dt * u[i]
        y[i] = y_old + dt * v[i]
        travel2 = (x[i] - x_old) ** 2 + (y[i] - y_old) ** 2
        lo = every
        hi = items.shape[0]
        b = _bucket_of(x_old, y_old, xmin, ymin, f_inv, f_nbx, f_nby)
        if b >= 0 and travel2 < f_reach2:
            lo = f_start[b]
            hi = f_start[b + 1]
        else:
            b = _bucket_of(x_old, y_old, xmin, ymin, n_inv, n_nbx, n_nby)
            if b >= 0 and travel2 < n_reach2:
                lo = n_start[b]
                hi = n_start[b + 1]
        hits = 0
        while lo < hi and hits < 3:
            hit = _first_crossing(x_old, y_old, x[i], y[i], seg, items, lo, hi)
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
