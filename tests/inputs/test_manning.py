"""Manning n on the DEM grid: constant, n raster, land cover + class table."""

import numpy as np
import pytest
import rasterio
from rasterio.transform import from_origin

from floodsph.errors import InputError
from floodsph.inputs.dem import load_terrain
from floodsph.io.manning import read_manning_table, worldcover_table_path

UTM32 = "EPSG:32632"
X0, Y_TOP = 500_000.0, 5_000_200.0  # DEM: 20 x 20 cells of 10 m


def write(path, z, transform, crs=UTM32, dtype="float32", nodata=-9999.0):
    z = np.asarray(z)
    with rasterio.open(
        path,
        "w",
        driver="GTiff",
        width=z.shape[1],
        height=z.shape[0],
        count=1,
        dtype=dtype,
        crs=crs,
        transform=transform,
        nodata=nodata,
    ) as dst:
        dst.write(z.astype(dtype), 1)
    return path


@pytest.fixture
def dem(tmp_path):
    return write(tmp_path / "dem.tif", np.full((20, 20), 100.0), from_origin(X0, Y_TOP, 10, 10))


def test_constant(dem):
    assert np.all(load_terrain(dem, manning=0.05).manning == 0.05)
    with pytest.raises(InputError, match="terrain.manning must be > 0"):
        load_terrain(dem, manning=0.0)


def test_raster_on_another_grid_and_crs(dem, tmp_path):
    # n raster on a coarser 25 m grid extending beyond the DEM: west half 0.03, east 0.06.
    n = np.where(np.arange(12)[None, :] < 6, 0.03, 0.06) * np.ones((12, 1))
    path = write(tmp_path / "n.tif", n, from_origin(X0 - 50, Y_TOP + 50, 25, 25))
    ter = load_terrain(dem, manning=path)
    # The 0.03/0.06 boundary is at x = X0 - 50 + 150 = X0 + 100 (local x = 100 m).
    xc, _ = ter.cell_centres()
    assert np.all(ter.manning[:, xc < 80] == pytest.approx(0.03))
    assert np.all(ter.manning[:, xc > 120] == pytest.approx(0.06))
    # A uniform raster in geographic coordinates covering the DEM reprojects to the same n.
    geo = write(
        tmp_path / "n_geo.tif",
        np.full((50, 50), 0.045),
        from_origin(8.9, 45.25, 0.004, 0.004),
        crs="EPSG:4326",
    )
    assert np.allclose(load_terrain(dem, manning=geo).manning, 0.045)


def test_raster_not_covering_dem_refused(dem, tmp_path):
    path = write(tmp_path / "small.tif", np.full((5, 5), 0.03), from_origin(X0, Y_TOP, 10, 10))
    with pytest.raises(InputError, match=r"manning raster .*small.tif: \d+ DEM cells"):
        load_terrain(dem, manning=path)


def test_landcover_worldcover(dem, tmp_path):
    # 5 m classes: north half tree cover (10), south half grassland (30).
    cls = np.where(np.arange(40)[:, None] < 20, 10, 30) * np.ones((1, 40))
    lc = write(tmp_path / "lc.tif", cls, from_origin(X0, Y_TOP, 5, 5), dtype="uint8", nodata=0)
    ter = load_terrain(dem, landcover=lc, manning_table="worldcover")
    assert np.all(ter.manning[10:] == 0.12)  # north rows (row 0 = south)
    assert np.all(ter.manning[:10] == 0.035)


def test_landcover_unknown_class_named(dem, tmp_path):
    cls = np.full((20, 20), 30, dtype=np.uint8)
    cls[3, 4] = 77
    lc = write(tmp_path / "lc.tif", cls, from_origin(X0, Y_TOP, 10, 10), dtype="uint8", nodata=0)
    table = tmp_path / "classes.csv"
    table.write_text("class,manning_n\n30,0.035\n")
    with pytest.raises(InputError, match=r"class value\(s\) \[77\] .*classes.csv"):
        load_terrain(dem, landcover=lc, manning_table=table)
    with pytest.raises(InputError, match="needs terrain.manning_table"):
        load_terrain(dem, landcover=lc)


def test_table_errors(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("class,n\n10,0.1\n")
    with pytest.raises(InputError, match="bad.csv: needs columns class,manning_n"):
        read_manning_table(bad)
    bad.write_text("class,manning_n\n10,-0.1\n")
    with pytest.raises(InputError, match="bad.csv, line 2: manning_n must be > 0"):
        read_manning_table(bad)


def test_shipped_worldcover_table():
    table = read_manning_table(worldcover_table_path())
    assert sorted(table) == [10, 20, 30, 40, 50, 60, 70, 80, 90, 95, 100]
    assert table[10] == 0.12 and table[30] == 0.035 and table[60] == 0.025


def holed(tmp_path):
    """A 20 x 20 DEM with a 3 x 3 interior nodata hole (filled by interpolation), and the
    north-up rows/columns of that hole."""
    z = np.full((20, 20), 100.0)
    z[8:11, 5:8] = -9999.0
    return write(tmp_path / "holed.tif", z, from_origin(X0, Y_TOP, 10, 10)), (8, 11, 5, 8)


def test_raster_masked_like_the_dem_follows_its_filled_holes(tmp_path):
    dem, (r0, r1, c0, c1) = holed(tmp_path)
    # n derived from the DEM: the same hole; west of column 6 n = 0.03, east 0.06.
    n = np.where(np.arange(20)[None, :] < 6, 0.03, 0.06) * np.ones((20, 1))
    n[r0:r1, c0:c1] = -9999.0
    warnings = []
    ter = load_terrain(dem, manning=write(tmp_path / "n.tif", n, from_origin(X0, Y_TOP, 10, 10)),
                       warnings=warnings)
    assert [w for w in warnings if "9 cells of the DEM's filled nodata holes" in w]
    hole = ter.manning[::-1][r0:r1, c0:c1]  # north-up again
    # Nearest cell with a value: column 5 -> column 4 (0.03), column 7 -> column 8 (0.06).
    np.testing.assert_allclose(hole[:, 0], 0.03)
    np.testing.assert_allclose(hole[:, 2], 0.06)


def test_raster_missing_over_dem_data_still_refused(tmp_path):
    dem, (r0, r1, c0, c1) = holed(tmp_path)
    n = np.full((20, 20), 0.04)
    n[r0:r1, c0:c1] = -9999.0
    n[2, 2] = -9999.0  # the DEM file holds this cell: refused
    path = write(tmp_path / "n.tif", n, from_origin(X0, Y_TOP, 10, 10))
    with pytest.raises(InputError, match=r"n.tif: 1 DEM cells get no value"):
        load_terrain(dem, manning=path)


def test_landcover_masked_like_the_dem_follows_its_filled_holes(tmp_path):
    dem, (r0, r1, c0, c1) = holed(tmp_path)
    classes = np.full((20, 20), 10)  # WorldCover tree cover
    classes[r0:r1, c0:c1] = 0
    path = write(tmp_path / "lc.tif", classes, from_origin(X0, Y_TOP, 10, 10), dtype="uint8",
                 nodata=0)
    warnings = []
    ter = load_terrain(dem, landcover=path, manning_table="worldcover", warnings=warnings)
    assert [w for w in warnings if "lc.tif: 9 cells" in w]
    tree = ter.manning[0, 0]
    np.testing.assert_allclose(ter.manning[::-1][r0:r1, c0:c1], tree)
