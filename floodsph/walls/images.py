"""Mirror images of particles across walls (the model's wall boundary condition).

See ``floodsph.walls`` for the model: for a particle i near a wall segment, every neighbour j
on i's side (i itself included) contributes a mirror image x_j' = 2 f_j - x_j if the line from
i to the image passes through the segment; in a right-angled corner the point reflection
through the corner completes the kernel too.
"""

from __future__ import annotations

from numba import njit

from floodsph.walls.geometry import mirror
from floodsph.walls.sight import hides


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


@njit(inline="always", cache=True)
def moving_image(xi, yi, px, py, pu, pv, seg, s, s2):
    """(applies, x', y', u', v') of a point p moving at (pu, pv) [m s-1], imaged as seen from
    particle i: about segment s when s2 < 0 (:func:`wall_image`, free slip: the velocity's
    normal part reversed, v' = v - 2 (v . n) n), or through the corner of s and s2
    (:func:`corner_image`, the velocity reflected about both walls' normals in turn)."""
    if s2 < 0:
        xm, ym, _, nx, ny = mirror(px, py, seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
        vn = pu * nx + pv * ny
        return hides(xi, yi, xm, ym, seg, s), xm, ym, pu - 2.0 * vn * nx, pv - 2.0 * vn * ny
    xm, ym, ok = corner_image(px, py, seg, s, s2)
    _, _, _, n1x, n1y = mirror(px, py, seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
    _, _, _, n2x, n2y = mirror(px, py, seg[s2, 0], seg[s2, 1], seg[s2, 2], seg[s2, 3])
    vn = pu * n1x + pv * n1y
    um = pu - 2.0 * vn * n1x
    vm = pv - 2.0 * vn * n1y
    vn = um * n2x + vm * n2y
    return ok, xm, ym, um - 2.0 * vn * n2x, vm - 2.0 * vn * n2y
