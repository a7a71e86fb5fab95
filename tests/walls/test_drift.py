"""The drift's crossing guard: moves that would cross a wall are reflected, whatever their
length, and the wall index's candidate tables find the same wall as a test of every
segment."""

import numpy as np

from floodsph.walls.geometry import crosses, mirror
from floodsph.walls.index import WallIndex


def _drift_every(x, y, u, v, dt, seg):
    """The drift of one particle testing every segment in index order (the definition)."""
    x0, y0 = x, y
    x, y = x0 + dt * u, y0 + dt * v
    hits = 0
    for _ in range(3):
        hit = next((s for s in range(seg.shape[0]) if crosses(x0, y0, x, y, *seg[s])), -1)
        if hit < 0:
            break
        hits += 1
        x, y, _, nx, ny = mirror(x, y, *seg[hit])
        vn = u * nx + v * ny
        u, v = u - 2.0 * vn * nx, v - 2.0 * vn * ny
    if hits >= 3:
        return x0, y0, 0.0, 0.0
    return x, y, u, v


def _staircase() -> np.ndarray:
    """A staircase wall of 1 m steps, like a nodata border on a DEM of 1 m cells, and a
    closed box of 40 m."""
    steps = []
    for k in range(30):
        steps.append((5.0 + k, 5.0 + k, 6.0 + k, 5.0 + k))
        steps.append((6.0 + k, 5.0 + k, 6.0 + k, 6.0 + k))
    box = [(0.0, 0.0, 40.0, 0.0), (40.0, 0.0, 40.0, 40.0), (40.0, 40.0, 0.0, 40.0),
           (0.0, 40.0, 0.0, 0.0)]
    return np.array(steps + box)


def test_drift_matches_a_test_of_every_segment_for_short_and_long_moves():
    seg = _staircase()
    index = WallIndex(seg, (0.0, 0.0, 40.0, 40.0), bucket=2.0)
    rng = np.random.default_rng(7)
    n = 4000
    x = rng.uniform(0.5, 39.5, n)
    y = rng.uniform(0.5, 39.5, n)
    angle = rng.uniform(0.0, 2.0 * np.pi, n)
    # moves from 1 cm to 8 m: the fine buckets' (< 0.45 m), the level-0 buckets' (< 3.6 m)
    # and every segment's
    speed = 10.0 ** rng.uniform(-2.0, np.log10(8.0), n)
    u, v = speed * np.cos(angle), speed * np.sin(angle)
    expected = [_drift_every(x[i], y[i], u[i], v[i], 1.0, seg) for i in range(n)]
    xd, yd, ud, vd = x.copy(), y.copy(), u.copy(), v.copy()
    reflections = index.drift(xd, yd, ud, vd, 1.0)
    assert reflections > 200  # the case does reflect many moves, on every path
    np.testing.assert_array_equal(np.c_[xd, yd, ud, vd], np.array(expected))
    # and no particle is left beyond the box
    assert ((xd > 0.0) & (xd < 40.0) & (yd > 0.0) & (yd < 40.0)).all()
