"""The boundary integral of floodsph.sph.shadow against a brute-force quadrature of the
kernel over the points that walls hide, and its continuity past vertices."""

import numpy as np
import pytest

from floodsph.sph.kernels import SIGMA_2D
from floodsph.sph.shadow import shadow, tail

H = 6.0


def hidden_weight(xi, yi, seg, h=H, n=900):
    """Kernel weight of the points of a fine grid whose sight line from (xi, yi) meets a
    segment: a midpoint rule over the support, independent of the angular integral."""
    g = (np.arange(n) + 0.5) / n * 4.0 * h - 2.0 * h
    px, py = np.meshgrid(g + xi, g + yi)
    q = np.hypot(px - xi, py - yi) / h
    f = np.where(q <= 1.0, 1.0 - 1.5 * q**2 + 0.75 * q**3, 0.25 * np.clip(2.0 - q, 0.0, None)**3)
    w = SIGMA_2D / h**2 * f
    hidden = np.zeros(px.shape, dtype=bool)
    for x1, y1, x2, y2 in seg:
        dx, dy = px - xi, py - yi
        ex, ey = x2 - x1, y2 - y1
        den = dx * ey - dy * ex
        qx, qy = x1 - xi, y1 - yi
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (qx * ey - qy * ex) / den
            s = (qx * dy - qy * dx) / den
        hidden |= (den != 0.0) & (t >= 0.0) & (t <= 1.0) & (s >= 0.0) & (s <= 1.0)
    return float((w * hidden).sum() * (4.0 * h / n) ** 2)


def test_tail_is_the_kernel_weight_beyond_a_radius():
    assert 2.0 * np.pi * tail(0.0) == pytest.approx(1.0, rel=1e-12)
    assert tail(2.0) == 0.0
    q = np.linspace(0.0, 2.0, 20001)
    f = np.where(q <= 1.0, 1.0 - 1.5 * q**2 + 0.75 * q**3, 0.25 * (2.0 - q) ** 3)
    integrand = SIGMA_2D * f * q
    for q0 in (0.3, 1.0, 1.6):
        keep = q >= q0
        assert tail(q0) == pytest.approx(np.trapezoid(integrand[keep], q[keep]), rel=1e-6)


CASES = [
    ("straight wall 3 m away", 0.0, 3.0, [(-100.0, 0.0, 100.0, 0.0)]),
    ("straight wall 0.5 m away", 0.0, 0.5, [(-100.0, 0.0, 100.0, 0.0)]),
    ("inside a right-angled corner", 0.3, 2.0, [(-100.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 100.0)]),
    ("outside a convex corner", 2.0, -1.0, [(-100.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 100.0)]),
    ("end of a short wall", 1.0, 2.0, [(0.0, 0.0, 5.0, 0.0)]),
    ("a wall behind another", 0.0, 5.0, [(-3.0, 0.0, 3.0, 0.0), (-10.0, -2.0, 10.0, -2.0)]),
    ("an acute corner", 4.0, 1.0, [(0.0, 0.0, 100.0, 0.0), (0.0, 0.0, 100.0, 60.0)]),
]


@pytest.mark.parametrize("label, xi, yi, seg", CASES, ids=[c[0] for c in CASES])
def test_shadow_matches_brute_force_quadrature(label, xi, yi, seg):
    seg = np.array(seg, dtype=np.float64)
    s = shadow(xi, yi, H, 0, seg.shape[0], np.arange(seg.shape[0]), seg)
    assert s == pytest.approx(hidden_weight(xi, yi, seg), abs=2e-3)


def test_shadow_is_continuous_past_a_vertex_and_independent_of_turning():
    # a bent wall: walking along it past the vertex, S changes by small steps only
    seg = np.array([(-100.0, 0.0, 0.0, 0.0), (0.0, 0.0, 30.0, -20.0)])
    xs = np.linspace(-3.0, 3.0, 601)
    s = np.array([shadow(x, 2.0, H, 0, 2, np.arange(2), seg) for x in xs])
    assert np.abs(np.diff(s)).max() < 5e-4
    # one straight wall at the same distance, turned by any angle, hides the same weight
    ref = None
    for angle in np.radians([0.0, 15.0, 30.0, 45.0, 77.0]):
        c, sn = np.cos(angle), np.sin(angle)
        wall = np.array([(-100.0 * c, -100.0 * sn, 100.0 * c, 100.0 * sn)])
        value = shadow(-2.5 * sn, 2.5 * c, H, 0, 1, np.arange(1), wall)
        ref = value if ref is None else ref
        assert value == pytest.approx(ref, rel=1e-12)
