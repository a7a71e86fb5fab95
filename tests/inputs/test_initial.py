"""Initial water: depth from a level + polygon or a raster, and lattice seeding."""

import numpy as np
import pytest
import rasterio
from rasterio.transform import from_origin

from floodsph.constants import RHO_WATER
from floodsph.errors import InputError
from floodsph.inputs.initial_water import (
    depth_from_level,
    depth_from_raster,
    lattice_depth,
    lump_thin_cells,
    seed_particles,
)
from floodsph.io.polygons import points_in_polygon
from floodsph.model.terrain import Terrain

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
    """At the DEM spacing each lattice cell is a DEM cell; the seeds carry those depths after
    the thin shore cells are lumped, and the volume."""
    ter = valley()
    d = depth_from_level(ter, LEVEL, RESERVOIR)
    np.testing.assert_allclose(lattice_depth(ter, d, CELL)[2], d, atol=1e-12)
    p = seed_particles(ter, d, CELL, kappa=1.3)
    i = (p.y / CELL - 0.5).round().astype(int)
    j = (p.x / CELL - 0.5).round().astype(int)
    lumped = lump_thin_cells(d)
    np.testing.assert_allclose(p.rho / RHO_WATER, lumped[i, j])
    assert p.n == np.count_nonzero(lumped > 1e-3)
    assert p.volume() == pytest.approx(d.sum() * CELL**2, rel=1e-12)


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


def test_thin_shore_cells_give_their_water_to_the_deepest_neighbour():
    """A steep shore (0.03 and 0.5 m beside 4-6 m) is lumped inwards, the volume kept; a
    uniformly thin sheet and a gentle shore are left alone."""
    from floodsph.inputs.initial_water import LUMP_RATIO

    steep = np.array([[0.0, 0.0, 0.0, 0.0], [0.0, 0.03, 0.5, 5.0], [0.0, 0.02, 4.0, 6.0]])
    lumped = lump_thin_cells(steep)
    assert lumped.sum() == pytest.approx(steep.sum(), rel=1e-15)
    np.testing.assert_allclose(lumped, [[0, 0, 0, 0], [0, 0, 0, 5.0], [0, 0, 4.05, 6.5]])
    rng = np.random.default_rng(1)
    bowl = np.maximum(10.0 - np.hypot(*np.meshgrid(np.arange(40.0), np.arange(40.0))) / 2.0,
                      0.0) + rng.uniform(0.0, 0.2, (40, 40)) * (rng.random((40, 40)) < 0.1)
    out = lump_thin_cells(bowl)
    assert out.sum() == pytest.approx(bowl.sum(), rel=1e-12)
    padded = np.pad(out, 1)
    deepest = np.max([padded[1 + a:41 + a, 1 + b:41 + b] for a in (-1, 0, 1) for b in (-1, 0, 1)
                      if a or b], axis=0)
    assert np.all((out == 0.0) | (out * LUMP_RATIO >= deepest))
    sheet = np.full((5, 5), 0.02)
    np.testing.assert_array_equal(lump_thin_cells(sheet), sheet)
    gentle = np.outer(np.ones(4), [0.5, 1.0, 1.5, 2.0])
    np.testing.assert_array_equal(lump_thin_cells(gentle), gentle)


def test_a_nodata_sliver_belongs_to_the_water_of_its_nearest_valid_cell():
    """Two basins (bed 0) split by a nodata strip two cells wide (columns 10-11). A level of
    5 m over a polygon that covers the west basin and the strip fills the west basin and the
    strip cell next to it, whose nearest valid cell is in the basin. The strip cell next to
    the east basin takes the east basin's bed, and the east basin is outside the polygon: it
    stays dry, else its water would be water nobody put in the east basin."""
    ter = Terrain.from_function(lambda x, y: 0.0 * x, (0.0, 240.0), (0.0, 100.0), CELL)
    ter.valid[:, 10:12] = False
    wet = ter.valid.copy()
    wet[:, 10:12] = True  # both strip cells may hold water (slivers inside walls)
    polygon = [[0.0, 0.0], [118.0, 0.0], [118.0, 100.0], [0.0, 100.0], [0.0, 0.0]]
    d = depth_from_level(ter, 5.0, polygon, wet=wet)
    assert np.all(d[:, :11] == 5.0)
    assert np.all(d[:, 11:] == 0.0)
