"""Initial water: depth from a level + polygon or a raster, and lattice seeding."""

import numpy as np
import pytest
import rasterio
from rasterio.transform import from_origin

from floodsph.constants import RHO_WATER
from floodsph.errors import InputError
from floodsph.initial import depth_from_level, depth_from_raster, seed_particles
from floodsph.io.polygons import points_in_polygon
from floodsph.terrain import Terrain

CELL = 10.0
LEVEL = 20.0


def valley(cell=CELL):
    """Parabolic valley b = (y - 400)^2 / 2000 + x / 200 on 1200 m x 800 m (thalweg 0..6 m)."""
    return Terrain.from_function(
        lambda x, y: (y - 400.0) ** 2 / 2000.0 + x / 200.0, (0.0, 1200.0), (0.0, 800.0), cell
    )


# Reservoir polygon: a skewed pentagon upstream of a dam line at x = 900 m.
RESERVOIR = [[50.0, 100.0], [900.0, 60.0], [900.0, 760.0], [300.0, 700.0], [40.0, 420.0]]


def test_depth_from_level_matches_level_minus_bed():
    ter = valley()
    d = depth_from_level(ter, LEVEL, RESERVOIR)
    xc, yc = ter.cell_centres()
    X, Y = np.meshgrid(xc, yc)
    inside = points_in_polygon(X, Y, np.array(RESERVOIR))
    expected = np.where(inside, np.maximum(LEVEL - ter.elevation, 0.0), 0.0)
    np.testing.assert_allclose(d, expected)
    assert d[np.searchsorted(yc, 400.0), np.searchsorted(xc, 500.0)] > 0
    assert np.all(d[:, xc > 900] == 0.0)  # nothing downstream of the dam line
    assert d.max() == pytest.approx(LEVEL - ter.elevation[inside].min())


def test_invalid_cells_get_no_water():
    ter = valley()
    ter.valid[30:50, 20:40] = False
    d = depth_from_level(ter, LEVEL, RESERVOIR)
    assert np.all(d[30:50, 20:40] == 0.0) and d[40, 50] > 0


@pytest.mark.parametrize("ratio", [1.0, 2.0])
def test_seeded_volume_matches_grid_volume(ratio):
    ter = valley()
    d = depth_from_level(ter, LEVEL, RESERVOIR)
    grid_volume = d.sum() * ter.dx * ter.dy
    dx = ratio * CELL
    p = seed_particles(ter, d, dx, kappa=1.3)
    assert p.volume() == pytest.approx(grid_volume, rel=5e-3)
    # Particle fields: lattice nodes, m = rho_w d dx^2, rho = rho_w d, h = kappa dx.
    np.testing.assert_allclose(np.mod(p.x / dx - 0.5, 1.0), 0.0, atol=1e-9)
    np.testing.assert_allclose(np.mod(p.y / dx - 0.5, 1.0), 0.0, atol=1e-9)
    np.testing.assert_allclose(p.m, p.rho * dx**2)
    assert np.all(p.h == 1.3 * dx) and np.all(p.rho > RHO_WATER * 1e-3)
    assert np.all(p.u == 0.0) and np.all(p.v == 0.0)


def test_lattice_depth_at_dem_spacing_is_the_cell_depth():
    ter = valley()
    d = depth_from_level(ter, LEVEL, RESERVOIR)
    p = seed_particles(ter, d, CELL, kappa=1.3)
    i = (p.y / CELL - 0.5).round().astype(int)
    j = (p.x / CELL - 0.5).round().astype(int)
    np.testing.assert_allclose(p.rho / RHO_WATER, d[i, j])
    assert p.n == np.count_nonzero(d > 1e-3)


def test_degenerate_polygons_named():
    ter = valley()
    with pytest.raises(InputError, match=r"initial_water\[0\]\.polygon: .*3 distinct points"):
        depth_from_level(ter, LEVEL, [[0, 0], [10, 0], [0, 0]], "initial_water[0].polygon")
    with pytest.raises(InputError, match=r"initial_water\[1\]\.polygon: .*zero area"):
        depth_from_level(ter, LEVEL, [[0, 0], [10, 10], [20, 20]], "initial_water[1].polygon")


def test_points_in_polygon_even_odd():
    # A square with a square hole traced as one ring (the hole counts as outside).
    ring = np.array(
        [[0, 0], [10, 0], [10, 10], [0, 10], [0, 0], [3, 3], [3, 7], [7, 7], [7, 3], [3, 3]],
        dtype=float,
    )
    inside = points_in_polygon(
        np.array([1.0, 5.0, 11.0, 8.5]), np.array([1.0, 5.0, 5.0, 5.0]), ring
    )
    assert inside.tolist() == [True, False, False, True]


def write_depth(path, d, transform, crs="EPSG:32632"):
    with rasterio.open(
        path,
        "w",
        driver="GTiff",
        width=d.shape[1],
        height=d.shape[0],
        count=1,
        dtype="float32",
        crs=crs,
        transform=transform,
        nodata=-9999.0,
    ) as dst:
        dst.write(d.astype(np.float32), 1)
    return path


def georeferenced_flat(x0=400_000.0, y0=5_000_000.0):
    from rasterio.crs import CRS

    ter = Terrain(np.zeros((40, 60)), CELL, CELL, 0.035, x0, y0, CRS.from_epsg(32632).to_wkt())
    return ter


def test_depth_from_raster_resampled(tmp_path):
    ter = georeferenced_flat()
    # 2 m deep over the raster's west half at 20 m cells; nodata in one corner.
    d = np.zeros((20, 30))
    d[:, :15] = 2.0
    d[0, 0] = -9999.0
    path = write_depth(tmp_path / "h0.tif", d, from_origin(ter.x0, ter.y0 + 400, 20, 20))
    grid = depth_from_raster(ter, path)
    xc, _ = ter.cell_centres()
    assert np.all(grid[-2:, :2] == 0.0)  # the nodata 20 m cell (north-west corner)
    grid_west = grid[:, xc < 280].copy()
    grid_west[-2:, :2] = 2.0
    assert np.all(grid_west == pytest.approx(2.0))
    assert np.all(grid[:, xc > 320] == 0.0)
    p = seed_particles(ter, grid, CELL, kappa=1.3)
    assert p.volume() == pytest.approx(grid.sum() * CELL**2, rel=1e-12)


def test_negative_depth_raster_refused(tmp_path):
    ter = georeferenced_flat()
    d = np.ones((20, 30))
    d[5, 5] = -0.5
    path = write_depth(tmp_path / "neg.tif", d, from_origin(ter.x0, ter.y0 + 400, 20, 20))
    with pytest.raises(InputError, match=r"initial_water\[2\]\.depth: .*neg.tif has negative"):
        depth_from_raster(ter, path, "initial_water[2].depth")
