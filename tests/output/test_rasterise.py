"""SPH -> grid interpolation: exact for uniform fields, honest extent at the water's edge."""

import numpy as np
import pytest

from floodsph.constants import RHO_WATER
from floodsph.model.terrain import Terrain
from floodsph.output.grid import OutputGrid
from floodsph.output.rasterise import interpolate, rasterise
from floodsph.sph.kernels import w_cubic

KAPPA = 1.3


def lattice(x0, x1, y0, y1, dx, d, u=0.0, v=0.0):
    """Square lattice of particles covering [x0, x1] x [y0, y1] with uniform depth d."""
    gx = np.arange(x0 + dx / 2, x1, dx)
    gy = np.arange(y0 + dx / 2, y1, dx)
    X, Y = np.meshgrid(gx, gy)
    n = X.size
    rho = np.full(n, RHO_WATER * d)
    return dict(x=X.ravel(), y=Y.ravel(), u=np.full(n, u), v=np.full(n, v), m=rho * dx * dx,
                rho=rho, h=np.full(n, KAPPA * dx))


def test_uniform_lattice_gives_its_depth_inside_and_nan_beyond_support():
    terrain = Terrain.from_function(lambda x, y: 0.0 * x, (0, 100), (0, 80), 2.0)
    grid = OutputGrid.from_terrain(terrain)
    p = lattice(20.0, 60.0, 10.0, 50.0, 1.0, 0.7, u=0.3, v=-0.2)
    d, u, v, support = rasterise(grid, **p)
    xc, yc = grid.cell_centres()
    X, Y = np.meshgrid(xc, yc)
    inside = (X > 23) & (X < 57) & (Y > 13) & (Y < 47)
    np.testing.assert_allclose(d[inside], 0.7, atol=1e-6)
    np.testing.assert_allclose(u[inside], 0.3, atol=1e-6)
    np.testing.assert_allclose(v[inside], -0.2, atol=1e-6)
    far = (X < 20 - 2 * KAPPA) | (X > 60 + 2 * KAPPA) | (Y < 10 - 2 * KAPPA) | (Y > 50 + 2 * KAPPA)
    assert np.all(np.isnan(d[far])) and np.all(support[far] == 0.0)


def test_mapped_extent_follows_the_edge_of_the_water():
    """The half-support contour sits on the water's edge: x = 40 for particles up to 39.5."""
    p = lattice(0.0, 40.0, 0.0, 40.0, 1.0, 0.5)
    px = np.array([38.0, 39.5, 39.9, 40.5, 41.0, 42.0])
    d, _, _, support = interpolate(px, np.full(px.size, 20.0), **p)
    np.testing.assert_allclose(d[:3], 0.5, atol=1e-9)
    assert np.all(np.isnan(d[3:]))
    assert support[2] > 0.5 > support[3]


def test_a_few_huge_smoothing_lengths_are_found():
    """Particles with h far above the rest (binned separately) still reach distant cells."""
    p = lattice(0.0, 20.0, 0.0, 20.0, 1.0, 1.0)
    big = {k: np.array([val]) for k, val in
           dict(x=60.0, y=10.0, u=2.0, v=0.0, m=RHO_WATER * 0.2 * 400.0, rho=RHO_WATER * 0.2,
                h=KAPPA * 20.0).items()}
    q = {k: np.concatenate([p[k], big[k]]) for k in p}
    d, u, _, support = interpolate(np.array([60.0, 85.0]), np.array([10.0, 10.0]), **q)
    # Only the big particle reaches these points; at x = 60 its V W(0) alone is 0.19 < 0.5.
    assert support[0] == pytest.approx(400.0 * w_cubic(0.0, KAPPA * 20.0), rel=1e-12)
    assert support[1] == pytest.approx(400.0 * w_cubic(25.0, KAPPA * 20.0), rel=1e-12)
    assert np.isnan(d[0])
    d, u, _, _ = interpolate(np.array([60.0]), np.array([10.0]), **q, min_support=0.1)
    assert d[0] == pytest.approx(0.2) and u[0] == pytest.approx(2.0)


def test_resampled_grid_is_aligned_to_the_dem_origin():
    terrain = Terrain.from_function(lambda x, y: 0.5 * x + 2.0 * y, (100, 130), (200, 221), 1.0)
    grid = OutputGrid.from_terrain(terrain, resolution_m=4.0)
    assert (grid.nx, grid.ny) == (8, 6)
    assert (grid.x0, grid.y0) == (100.0, 200.0)
    xc, yc = grid.cell_centres()
    # A plane is reproduced exactly by bilinear interpolation (inside the node range).
    X, Y = np.meshgrid(xc + 100, yc + 200)
    inner = (X < 129.5) & (Y < 220.5)
    np.testing.assert_allclose(grid.bed[inner], (0.5 * X + 2.0 * Y)[inner])


def test_kernel_sums_equal_a_brute_force_sum_with_h_spread_over_many_levels():
    """A fifth of the particles thin out to h up to ten times the rest (the share at which a
    split into two groups used to fall back to one grid of the largest h): every point gets
    the sum over all particles whose support reaches it."""
    rng = np.random.default_rng(11)
    n = 2000
    x, y = rng.uniform(0.0, 500.0, n), rng.uniform(0.0, 300.0, n)
    h = np.full(n, 6.5)
    thin = rng.random(n) < 0.2
    h[thin] *= rng.uniform(1.0, 10.0, thin.sum())
    rho = RHO_WATER * rng.uniform(0.05, 2.0, n)
    m = rho * 25.0
    u, v = rng.normal(0.0, 1.0, n), rng.normal(0.0, 1.0, n)
    px, py = rng.uniform(-50.0, 550.0, 3000), rng.uniform(-50.0, 350.0, 3000)
    d, uu, _, support = interpolate(px, py, x, y, u, v, m, rho, h, min_support=0.0)
    r = np.hypot(px[:, None] - x, py[:, None] - y)
    w = np.where(r < 2.0 * h, m / rho * np.vectorize(w_cubic)(r, h), 0.0)
    np.testing.assert_allclose(support, w.sum(axis=1), rtol=1e-12, atol=1e-15)
    reached = support > 0.0
    assert reached.mean() > 0.9
    np.testing.assert_allclose(d[reached], (w @ (rho / RHO_WATER))[reached] / support[reached],
                               rtol=1e-10)
    np.testing.assert_allclose(uu[reached], (w @ u)[reached] / support[reached], rtol=1e-9,
                               atol=1e-12)


def test_map_grid_sums_equal_a_brute_force_sum_over_every_cell():
    """The gather by row bands (``rasterise``) gives every cell the sum over all particles
    whose support reaches its centre, and the cells no particle reaches are NaN: particles
    with h from one to ten times the rest, some beyond the grid's edges and some whose
    support spans many bands."""
    terrain = Terrain.from_function(lambda x, y: 0.0 * x, (0, 600), (0, 450), 10.0)
    grid = OutputGrid.from_terrain(terrain)
    rng = np.random.default_rng(5)
    n = 1500
    x, y = rng.uniform(-80.0, 380.0, n), rng.uniform(-80.0, 530.0, n)
    h = 6.5 * np.where(rng.random(n) < 0.2, rng.uniform(1.0, 10.0, n), 1.0)
    rho = RHO_WATER * rng.uniform(0.05, 2.0, n)
    u, v = rng.normal(0.0, 1.0, n), rng.normal(0.0, 1.0, n)
    d, uu, vv, support = rasterise(grid, x, y, u, v, rho * 25.0, rho, h, min_support=0.0)
    assert d.shape == support.shape == grid.shape
    xc, yc = grid.cell_centres()
    px, py = (a.ravel() for a in np.meshgrid(xc, yc))
    r = np.hypot(px[:, None] - x, py[:, None] - y)
    w = np.where(r < 2.0 * h, 25.0 * np.vectorize(w_cubic)(r, h), 0.0)
    s = w.sum(axis=1)
    np.testing.assert_allclose(support.ravel(), s, rtol=1e-12, atol=1e-15)
    reached = s > 0.0
    assert 0.5 < reached.mean() < 1.0
    np.testing.assert_allclose(d.ravel()[reached], (w @ (rho / RHO_WATER))[reached] / s[reached],
                               rtol=1e-10)
    np.testing.assert_allclose(vv.ravel()[reached], (w @ v)[reached] / s[reached], rtol=1e-9,
                               atol=1e-12)
    assert np.all(np.isnan(d.ravel()[~reached]))


def test_a_wall_hides_the_water_behind_it_from_the_maps_and_gauges():
    """Water up to a wall at x = 40 m, mapped down to a kernel sum of 0.2: with the wall's
    segments no cell or gauge beyond it is wet, and the depth in front of it is the water's;
    without them the kernel reaches past the wall."""
    from floodsph.walls.index import MapWalls

    terrain = Terrain.from_function(lambda x, y: 0.0 * x, (0, 100), (0, 80), 2.0)
    grid = OutputGrid.from_terrain(terrain)
    p = lattice(10.0, 40.0, 10.0, 70.0, 2.0, 1.5)
    seg = np.array([[40.0, 0.0, 40.0, 80.0]])
    n = p["x"].size
    walls = MapWalls(seg, np.arange(n + 1, dtype=np.int64), np.zeros(n, dtype=np.int64))
    X, Y = np.meshgrid(*grid.cell_centres())
    beyond = (X > 40.0) & (Y > 20.0) & (Y < 60.0)
    front = (X > 30.0) & (X < 40.0) & (Y > 20.0) & (Y < 60.0)
    d_open = rasterise(grid, **p, min_support=0.2)[0]
    d_walled = rasterise(grid, **p, min_support=0.2, walls=walls)[0]
    assert np.isfinite(d_open[beyond]).sum() >= 20
    assert not np.isfinite(d_walled[beyond]).any()
    np.testing.assert_allclose(d_walled[front], d_open[front])
    gx, gy = np.array([35.0, 42.0]), np.array([40.0, 40.0])
    d_gauge = interpolate(gx, gy, **p, min_support=0.2, walls=walls)[0]
    assert d_gauge[0] == pytest.approx(1.5, rel=1e-6) and np.isnan(d_gauge[1])


def test_maps_hold_no_water_over_nodata():
    """A DEM with a nodata block: the lattice reaching its edge maps no depth in its cells."""
    terrain = Terrain.from_function(lambda x, y: 0.0 * x, (0, 100), (0, 80), 2.0)
    valid = np.ones(terrain.shape, dtype=bool)
    valid[:, 25:] = False  # x >= 50 m
    terrain = Terrain(terrain.elevation, terrain.dx, terrain.dy, valid=valid)
    grid = OutputGrid.from_terrain(terrain)
    d = rasterise(grid, **lattice(10.0, 52.0, 10.0, 70.0, 2.0, 1.5))[0]
    assert np.isfinite(d[:, 24]).any() and not np.isfinite(d[:, 25:]).any()
    coarse = OutputGrid.from_terrain(terrain, 5.0)
    d = rasterise(coarse, **lattice(10.0, 52.0, 10.0, 70.0, 2.0, 1.5))[0]
    assert not np.isfinite(d[:, 10:]).any()
