"""Hazard classes exactly at and around the published class boundaries."""

import numpy as np
import pytest

from floodsph.errors import InputError
from floodsph.output.hazard import HazardTables, classify, hazard_rating_uk

EPS = 1e-9


@pytest.fixture(scope="module")
def tables():
    return HazardTables.load("conservative")


def test_uk_rating_formula_and_debris_bands(tables):
    # HR = d (v + 0.5) + DF with the conservative DF = 0 (d <= 0.25) else 1.
    d = np.array([0.25, 0.25 + EPS, 0.5, 1.0])
    v = np.array([1.0, 1.0, 0.5, 3.0])
    np.testing.assert_allclose(hazard_rating_uk(d, v, tables),
                               [0.375, (0.25 + EPS) * 1.5 + 1.0, 1.5, 4.5])
    wood = HazardTables.load("woodland")
    # woodland: 0.5 for 0.25 < d <= 0.75 and v <= 2; 1.0 for d > 0.75 or v > 2.
    np.testing.assert_allclose(hazard_rating_uk([0.5, 0.5, 0.8], [2.0, 2.0 + EPS, 0.0], wood),
                               [0.5 * 2.5 + 0.5, 0.5 * (2.5 + EPS) + 1.0, 0.4 + 1.0])


@pytest.mark.parametrize(("hr_speed", "expected"), [
    # d = 0.25 (DF = 0): HR = 0.25 (v + 0.5); the bounds 0.75, 1.25, 2.0 are exact in binary.
    (2.5 - 4 * EPS, 1), (2.5, 2), (4.5, 2), (4.5 + 4 * EPS, 3), (7.5, 3), (7.5 + 4 * EPS, 4),
])
def test_uk_class_boundaries(tables, hr_speed, expected):
    uk, _ = classify(np.array([0.25]), np.array([hr_speed]), tables)
    assert uk[0] == expected


@pytest.mark.parametrize(("d", "v", "expected"), [
    (0.3, 1.0, 1), (0.3 + EPS, 0.0, 2),                 # depth limit of H1
    (0.15, 2.0, 1), (0.15, 2.0 + EPS, 5),               # speed limit 2 m/s of H1-H4
    (0.2, 1.49, 1), (0.2, 1.51, 2),                     # d v = 0.3 limit of H1
    (0.5, 1.2, 2), (0.5 + EPS, 0.0, 3),                 # H2 bounds
    (1.2, 0.5, 3), (1.2, 0.5 + EPS, 4), (1.2 + EPS, 0.1, 4),
    (2.0, 0.5, 4), (2.0 + EPS, 0.0, 5), (0.8, 1.25 + EPS, 5),
    (4.0, 1.0, 5), (4.0 + EPS, 0.0, 6), (1.0, 4.0, 5), (1.0, 4.0 + EPS, 6), (2.5, 1.7, 6),
])
def test_australian_class_boundaries(tables, d, v, expected):
    _, arr = classify(np.array([d]), np.array([v]), tables)
    assert arr[0] == expected


def test_dry_cells_are_class_zero(tables):
    uk, arr = classify(np.array([0.01, 0.0100001, np.nan]), np.array([5.0, 0.0, 1.0]), tables,
                       wet_threshold=0.01)
    assert uk.tolist() == [0, 1, 0] and arr.tolist() == [0, 1, 0]


def test_unknown_land_use_names_the_choices():
    with pytest.raises(InputError, match="pasture, woodland, urban, conservative.*'forest'"):
        HazardTables.load("forest")
