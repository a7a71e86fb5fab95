"""The cubic-spline kernel and the neighbour search (exact against a k-d tree, mixed h)."""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.spatial import cKDTree

from floodsph.sph.kernels import SIGMA_2D, dwdr_cubic, w_cubic
from floodsph.sph.neighbours import NeighbourList


@pytest.mark.parametrize("h", [0.3, 1.0, 13.0])
def test_kernel_is_normalised_and_compact(h):
    area = quad(lambda r: 2 * np.pi * r * w_cubic(r, h), 0, 2 * h, points=[h])[0]
    assert area == pytest.approx(1.0, abs=1e-10)
    assert w_cubic(2.0 * h, h) == 0.0 and w_cubic(2.0001 * h, h) == 0.0
    assert w_cubic(0.0, h) == pytest.approx(SIGMA_2D / h**2)


def test_kernel_derivative_matches_finite_difference():
    h = 1.7
    for r in np.linspace(0.05, 3.3, 40):
        e = 1e-6
        fd = (w_cubic(r + e, h) - w_cubic(r - e, h)) / (2 * e)
        assert dwdr_cubic(r, h) == pytest.approx(fd, rel=1e-6, abs=1e-9)


def _reference_pairs(x, y, h):
    tree = cKDTree(np.c_[x, y])
    pairs = tree.query_pairs(2 * h.max(), output_type="ndarray")
    r = np.hypot(*(np.c_[x, y][pairs[:, 0]] - np.c_[x, y][pairs[:, 1]]).T)
    keep = pairs[r < 2 * np.maximum(h[pairs[:, 0]], h[pairs[:, 1]])]
    return set(map(tuple, keep)) | set(map(tuple, keep[:, ::-1]))


def _listed_pairs(nl, n):
    return {(i, int(j)) for i in range(n) for j in nl.nbr[nl.start[i]:nl.start[i + 1]]}


@pytest.mark.parametrize("cloud", ["uniform", "clustered"])
def test_neighbour_lists_equal_kdtree_with_mixed_h(cloud):
    rng = np.random.default_rng(7)
    n = 6000
    if cloud == "uniform":
        x, y = rng.uniform(0, 100, n), rng.uniform(0, 60, n)
    else:
        centres = rng.uniform(0, 100, (12, 2))
        pick = rng.integers(0, 12, n)
        x = centres[pick, 0] + rng.normal(0, 3, n)
        y = centres[pick, 1] + rng.normal(0, 3, n)
    h = rng.uniform(0.4, 1.2, n)
    big = rng.random(n) < 0.01  # a few front particles with a much larger support
    h[big] = rng.uniform(5, 15, big.sum())
    nl = NeighbourList(x, y, h, skin=0.0)
    assert _listed_pairs(nl, n) == _reference_pairs(x, y, h)


def test_skin_keeps_list_valid_until_h_grows_past_it():
    rng = np.random.default_rng(3)
    x, y = rng.uniform(0, 50, 2000), rng.uniform(0, 50, 2000)
    h = np.full(2000, 1.0)
    nl = NeighbourList(x, y, h, skin=0.1)
    assert nl.still_valid(h * 1.09)
    assert not nl.still_valid(h * 1.11)
    assert _reference_pairs(x, y, h * 1.1) <= _listed_pairs(nl, 2000)
