"""Envelopes track maxima, arrival, duration and hazard between map outputs."""

import numpy as np
import pytest

from floodsph.constants import RHO_WATER
from floodsph.model.terrain import Terrain
from floodsph.output.envelopes import MAPS, Envelopes
from floodsph.output.grid import OutputGrid


def uniform_state(d, u):
    """Particles of uniform depth d and velocity (u, 0) on a lattice well beyond the grid."""
    g = np.arange(-10.0, 30.0, 1.0) + 0.5
    X, Y = np.meshgrid(g, g)
    n = X.size
    rho = np.full(n, RHO_WATER * d)
    return (X.ravel(), Y.ravel(), np.full(n, u), np.zeros(n), rho * 1.0, rho, np.full(n, 1.3))


@pytest.fixture()
def grid():
    terrain = Terrain.from_function(lambda x, y: 0.1 * x, (0, 20), (0, 16), 2.0)
    return OutputGrid.from_terrain(terrain)


# (t, d, speed): a film below the wet threshold, a one-update depth peak at t = 3, a speed
# peak at t = 5 with little depth, then a film again.
SEQUENCE = [(0, 0.005, 0.0), (1, 0.005, 0.0), (2, 0.5, 0.1), (3, 1.2, 0.1), (4, 0.5, 0.1),
            (5, 0.2, 1.9), (6, 0.3, 0.2), (7, 0.3, 0.2), (8, 0.3, 0.2), (9, 0.005, 0.0),
            (10, 0.005, 0.0)]


def test_envelope_catches_a_peak_between_snapshots(grid):
    env = Envelopes(grid, wet_threshold=0.01)
    t_prev = 0.0
    for t, d, s in SEQUENCE:
        env.update(t, t - t_prev, *uniform_state(d, s))
        t_prev = t
    m = env.maps()
    # Snapshots every 5 s (t = 0, 5, 10) would report 0.2 m; the envelope has the peak.
    np.testing.assert_allclose(m["max_depth"], 1.2, atol=1e-6)
    np.testing.assert_allclose(m["time_of_max_depth"], 3.0)
    np.testing.assert_allclose(m["max_level"], 1.2 + grid.bed, atol=1e-6)
    np.testing.assert_allclose(m["max_speed"], 1.9, atol=1e-6)
    np.testing.assert_allclose(m["max_unit_discharge"], 0.2 * 1.9, atol=1e-6)
    np.testing.assert_allclose(m["arrival_time"], 2.0)
    np.testing.assert_allclose(m["duration"], 7.0)      # wet at t = 2..8, 1 s each


def test_hazard_is_the_maximum_of_per_update_classes(grid):
    """Classes of (max d, max v) = (1.2, 1.9) would be UK 4 and H5; the true maxima are lower."""
    env = Envelopes(grid, wet_threshold=0.01)
    t_prev = 0.0
    for t, d, s in SEQUENCE:
        env.update(t, t - t_prev, *uniform_state(d, s))
        t_prev = t
    m = env.maps()
    # t = 3: HR = 1.2 (0.1 + 0.5) + 1 = 1.72 -> 3; H3 (d <= 1.2, v <= 2, dv <= 0.6).
    assert np.all(m["hazard_uk"] == 3)
    assert np.all(m["hazard_arr"] == 3)


def test_film_below_threshold_keeps_depth_but_is_dry(grid):
    env = Envelopes(grid, wet_threshold=0.01)
    d = np.full(grid.shape, np.nan)
    d[:, :3] = 0.004
    d[:, 3:6] = 0.4
    zeros = np.zeros(grid.shape)
    env.fold(0.0, 0.0, d, zeros + 0.5, zeros)
    env.fold(2.0, 2.0, d, zeros + 0.5, zeros)
    m = env.maps()
    film, wet, never = (slice(None), slice(0, 3)), (slice(None), slice(3, 6)), (slice(None),
                                                                                  slice(6, None))
    np.testing.assert_allclose(m["max_depth"][film], 0.004)
    assert np.all(np.isnan(m["arrival_time"][film])) and np.all(m["hazard_uk"][film] == 0)
    assert np.all(np.isnan(m["max_speed"][film])) and np.all(np.isnan(m["duration"][film]))
    np.testing.assert_allclose(m["duration"][wet], 2.0)
    np.testing.assert_allclose(m["arrival_time"][wet], 0.0)
    for name in MAPS:
        if m[name].dtype == np.uint8:
            assert np.all(m[name][never] == 0)
        else:
            assert np.all(np.isnan(m[name][never])), name


def test_state_round_trip_resumes_identically(grid):
    a = Envelopes(grid)
    a.update(0.0, 0.0, *uniform_state(0.3, 0.5))
    b = Envelopes(grid)
    b.restore(a.state())
    for env in (a, b):
        env.update(1.0, 1.0, *uniform_state(0.6, 0.1))
    for name in MAPS:
        np.testing.assert_array_equal(a.maps()[name], b.maps()[name])
    assert b.t_last == 1.0 and b.updates == 2
