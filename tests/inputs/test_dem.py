"""DEM ingestion: formats, CRS handling, transform/orientation, nodata, cropping."""

import logging
import os
from pathlib import Path

import numpy as np
import pytest
import rasterio
from rasterio.crs import CRS
from rasterio.transform import Affine, from_origin
from rasterio.warp import transform as warp_transform

from floodsph.errors import InputError
from floodsph.inputs.dem import load_terrain

UTM32 = "EPSG:32632"


def write_tif(path, z, transform, crs=UTM32, nodata=-9999.0):
    z = np.asarray(z, dtype=np.float32)
    with rasterio.open(
        path,
        "w",
        driver="GTiff",
        width=z.shape[1],
        height=z.shape[0],
        count=1,
        dtype="float32",
        crs=crs,
        transform=transform,
        nodata=nodata,
    ) as dst:
        dst.write(z, 1)
    return path


def write_asc(path, z, xll, yll, cell, nodata=-9999):
    rows = "\n".join(" ".join(f"{v:.3f}" for v in row) for row in z)
    Path(path).write_text(
        f"ncols {z.shape[1]}\nnrows {z.shape[0]}\nxllcorner {xll}\nyllcorner {yll}\n"
        f"cellsize {cell}\nNODATA_value {nodata}\n{rows}\n"
    )
    return path


def ramp(rows=8, cols=12):
    """North-up grid with a distinct value in every cell: 100 + col + 0.01 row."""
    r, c = np.mgrid[0:rows, 0:cols]
    return 100.0 + c + 0.01 * r


def test_geotiff_crs_transform_and_orientation(tmp_path):
    z = ramp()
    t = from_origin(500_000.0, 5_000_080.0, 10.0, 5.0)  # non-square: dx=10, dy=5
    ter = load_terrain(write_tif(tmp_path / "dem.tif", z, t))
    assert CRS.from_wkt(ter.crs_wkt) == CRS.from_string(UTM32)
    assert (ter.dx, ter.dy) == (10.0, 5.0)
    assert (ter.x0, ter.y0) == (500_000.0, 5_000_040.0)  # lower-left corner
    # North-up cell (row 2, col 7): world centre -> local coordinates -> same elevation.
    X, Y = t @ (7 + 0.5, 2 + 0.5)
    x, y = ter.to_local(X, Y)
    i, j = int(y / ter.dy - 0.5), int(x / ter.dx - 0.5)
    assert (i, j) == (z.shape[0] - 1 - 2, 7)  # row 0 = south
    assert ter.elevation[i, j] == pytest.approx(z[2, 7], abs=1e-4)
    assert ter.valid.all()
    assert np.all(ter.manning == 0.035)


def test_south_up_raster_is_flipped(tmp_path):
    z = ramp()
    t = Affine(10.0, 0.0, 500_000.0, 0.0, 10.0, 5_000_000.0)  # row 0 = south
    ter = load_terrain(write_tif(tmp_path / "dem.tif", z, t))
    assert (ter.x0, ter.y0) == (500_000.0, 5_000_000.0)
    np.testing.assert_allclose(ter.elevation, z, atol=1e-4)


def test_asc_with_prj(tmp_path):
    z = ramp()
    path = write_asc(tmp_path / "dem.asc", z, 957_000.0, 1_844_000.0, 20.0)  # Malpasset
    (tmp_path / "dem.prj").write_text(CRS.from_epsg(27572).to_wkt())
    ter = load_terrain(path)
    assert CRS.from_wkt(ter.crs_wkt).to_epsg() == 27572
    assert (ter.x0, ter.y0, ter.dx) == (957_000.0, 1_844_000.0, 20.0)
    np.testing.assert_allclose(ter.elevation, z[::-1], atol=1e-3)


def test_asc_with_crs_argument_and_without_crs(tmp_path):
    path = write_asc(tmp_path / "bare.asc", ramp(), 957_000.0, 1_844_000.0, 5.0)
    ter = load_terrain(path, crs="EPSG:27572")
    assert CRS.from_wkt(ter.crs_wkt).to_epsg() == 27572
    with pytest.raises(InputError, match="bare.asc has no coordinate reference system"):
        load_terrain(path)


def test_netcdf_variable(tmp_path):
    xr = pytest.importorskip("xarray")
    x = 600_000.0 + 10.0 * (np.arange(12) + 0.5)
    y = 4_000_000.0 + 10.0 * (np.arange(8) + 0.5)  # increasing: stored south-up
    elev = 50.0 + 0.5 * (x[None, :] - x[0]) / 10.0 - 0.2 * (y[:, None] - y[0]) / 10.0
    crs = xr.DataArray(
        0,
        attrs={
            "crs_wkt": CRS.from_string(UTM32).to_wkt(),
            "spatial_ref": CRS.from_string(UTM32).to_wkt(),
        },
    )
    ds = xr.Dataset(
        {
            "bed": (("y", "x"), elev, {"grid_mapping": "crs", "units": "m"}),
            "other": (("y", "x"), np.zeros_like(elev), {"grid_mapping": "crs"}),
            "crs": crs,
        },
        coords={
            "x": ("x", x, {"units": "m", "standard_name": "projection_x_coordinate"}),
            "y": ("y", y, {"units": "m", "standard_name": "projection_y_coordinate"}),
        },
    )
    path = tmp_path / "dem.nc"
    ds.to_netcdf(path)
    ter = load_terrain(path, dem_variable="bed")
    assert CRS.from_wkt(ter.crs_wkt) == CRS.from_string(UTM32)
    assert (ter.x0, ter.y0, ter.dx, ter.dy) == (600_000.0, 4_000_000.0, 10.0, 10.0)
    np.testing.assert_allclose(ter.elevation, elev, atol=1e-9)
    with pytest.raises(InputError, match="several variables"):
        load_terrain(path)
    with pytest.raises(InputError, match=r"dem\.nc.*'nosuch'"):
        load_terrain(path, dem_variable="nosuch")


def test_netcdf_without_cf_coordinates_refused(tmp_path):
    # x and y hold the coordinates but carry no units / standard_name: GDAL reads the pixel
    # grid (the identity transform), with the grid mapping's CRS.
    xr = pytest.importorskip("xarray")
    x = 600_000.0 + 10.0 * (np.arange(12) + 0.5)
    y = 4_000_000.0 + 10.0 * (np.arange(8) + 0.5)
    ds = xr.Dataset(
        {"bed": (("y", "x"), np.full((8, 12), 50.0), {"grid_mapping": "crs"}),
         "crs": xr.DataArray(0, attrs={"crs_wkt": CRS.from_string(UTM32).to_wkt()})},
        coords={"x": ("x", x), "y": ("y", y)},
    )
    ds.to_netcdf(tmp_path / "bare.nc")
    with pytest.raises(InputError, match=r"bare.nc: the raster is not georeferenced.*units.*"
                                         r"standard_name.*GeoTIFF"):
        load_terrain(tmp_path / "bare.nc", dem_variable="bed")


def test_geotiff_without_transform_refused(tmp_path):
    path = tmp_path / "pixels.tif"
    with rasterio.open(path, "w", driver="GTiff", width=5, height=5, count=1,
                       dtype="float32", crs=UTM32) as dst:
        dst.write(np.full((5, 5), 10.0, dtype=np.float32), 1)
    with pytest.raises(InputError, match="pixels.tif: the raster is not georeferenced"):
        load_terrain(path)
    from floodsph.io.raster import read_header

    with pytest.raises(InputError, match="pixels.tif: the raster is not georeferenced"):
        read_header(path, what="DEM")


def test_geographic_dem_reprojected_to_utm(tmp_path, caplog):
    # 0.0002 deg cells near 9.01 E, 45.005 N: ~15.7 m x 22.2 m; z linear in lon/lat.
    lon0, lat1, res = 9.0, 45.01, 0.0002
    rows, cols = 50, 100
    r, c = np.mgrid[0:rows, 0:cols]
    lon = lon0 + (c + 0.5) * res
    lat = lat1 - (r + 0.5) * res
    z = 100.0 + 2000.0 * (lon - lon0) + 1000.0 * (lat - 45.0)
    path = write_tif(tmp_path / "geo.tif", z, from_origin(lon0, lat1, res, res), "EPSG:4326")
    with caplog.at_level(logging.WARNING, logger="floodsph.inputs.dem"):
        ter = load_terrain(path)
    assert CRS.from_wkt(ter.crs_wkt).to_epsg() == 32632
    assert "EPSG:32632" in caplog.text
    assert ter.dx == ter.dy and 17.0 < ter.dx < 20.0  # sqrt(15.7 * 22.2) = 18.7
    # Every valid cell keeps the elevation of its own lon/lat, to a quarter of the 0.4 m
    # change per source cell (GDAL's bilinear kernel widens when a direction is coarsened).
    xc, yc = ter.cell_centres()
    X, Y = np.meshgrid(xc + ter.x0, yc + ter.y0)
    v = ter.valid
    lons, lats = warp_transform(CRS.from_epsg(32632), CRS.from_epsg(4326), X[v], Y[v])
    expected = 100.0 + 2000.0 * (np.array(lons) - lon0) + 1000.0 * (np.array(lats) - 45.0)
    area_m2 = (rows * res * 111_200.0) * (cols * res * 111_200.0 * np.cos(np.radians(45.005)))
    assert v.sum() == pytest.approx(area_m2 / ter.dx**2, rel=0.05)  # the footprint is kept
    np.testing.assert_allclose(ter.elevation[v], expected, atol=0.1)


def test_rotated_transform_refused(tmp_path):
    t = Affine(10.0, 1.0, 500_000.0, 1.0, -10.0, 5_000_000.0)
    path = write_tif(tmp_path / "rot.tif", ramp(), t)
    with pytest.raises(InputError, match="rot.tif: the raster is rotated or sheared"):
        load_terrain(path)


def test_all_nodata_refused(tmp_path):
    path = write_tif(tmp_path / "empty.tif", np.full((5, 5), -9999.0), from_origin(0, 50, 10, 10))
    with pytest.raises(InputError, match="empty.tif: every cell is nodata"):
        load_terrain(path)


def test_small_hole_filled_large_area_invalid(tmp_path):
    r, c = np.mgrid[0:30, 0:30]
    plane = 50.0 + 0.3 * c - 0.1 * r
    z = plane.copy()
    z[5:7, 5:7] = -9999.0  # 4-cell interior hole: filled
    z[15:25, 12:22] = -9999.0  # 100 cells: outside the model
    z[0:2, 28:30] = -9999.0  # small but on the border: outside the model
    ter = load_terrain(
        write_tif(tmp_path / "holes.tif", z, from_origin(0, 300, 10, 10)), fill_holes_max_cells=50
    )
    valid = ter.valid[::-1]  # back to north-up
    elev = ter.elevation[::-1]
    assert valid[5:7, 5:7].all()
    np.testing.assert_allclose(elev[5:7, 5:7], plane[5:7, 5:7], atol=0.3)
    assert not valid[15:25, 12:22].any() and not valid[0:2, 28:30].any()
    assert valid.sum() == 900 - 100 - 4
    assert np.all(np.isfinite(ter.elevation))
    # Invalid cells carry the nearest valid elevation (a value present in the valid set).
    assert elev[20, 12] == pytest.approx(plane[20, 11], abs=1e-4)


def test_corrupt_file_names_the_file(tmp_path):
    path = tmp_path / "broken.tif"
    path.write_bytes(b"II*\x00 this is not really a tiff" * 10)
    with pytest.raises(InputError, match="broken.tif"):
        load_terrain(path)
    with pytest.raises(InputError, match="missing.tif"):
        load_terrain(tmp_path / "missing.tif")


def test_state_plane_in_feet_becomes_the_same_projection_in_metres(tmp_path):
    # NAD83 / North Carolina (ftUS), 10 ft cells near Raleigh; elevations in metres.
    x_ft, y_ft = 2_100_000.0, 740_000.0
    z = ramp()
    path = write_tif(tmp_path / "feet.tif", z, from_origin(x_ft, y_ft, 10, 10), "EPSG:2264")
    warnings = []
    ter = load_terrain(path, warnings=warnings)
    us_foot = 1200.0 / 3937.0
    crs = CRS.from_wkt(ter.crs_wkt)
    assert crs.linear_units_factor == ("metre", 1.0)
    assert ter.dx == pytest.approx(10.0 * us_foot, rel=1e-12)
    # The grid corner is the same point on the ground in both CRSs.
    x_m, y_m = warp_transform(CRS.from_epsg(2264), crs, [x_ft], [y_ft - 8 * 10.0])
    assert (ter.x0, ter.y0) == pytest.approx((x_m[0], y_m[0]), abs=1e-6)
    assert ter.x0 == pytest.approx(x_ft * us_foot, abs=1e-6)
    np.testing.assert_array_equal(ter.elevation, z[::-1].astype(np.float32))  # not resampled
    assert [w for w in warnings if "feet.tif" in w and "US survey foot" in w
            and "converted to the same projection in metres" in w]
    assert ter.source_scale == pytest.approx((1.0, 1.0), abs=1e-3)


def test_extent_crop_to_whole_cells(tmp_path):
    z = ramp(20, 30)
    path = write_tif(tmp_path / "dem.tif", z, from_origin(1000.0, 2200.0, 10.0, 10.0))
    # x 1000..1300, y 2000..2200; the box cuts cells 5..15 in x and rows 4..12 from the top.
    ter = load_terrain(path, extent=[1055.0, 2081.0, 1149.0, 2159.0])
    assert (ter.x0, ter.y0) == (1050.0, 2080.0)
    assert ter.shape == (8, 10)
    np.testing.assert_allclose(ter.elevation[::-1], z[4:12, 5:15], atol=1e-4)
    with pytest.raises(InputError, match="does not overlap the DEM"):
        load_terrain(path, extent=[0.0, 0.0, 10.0, 10.0])


def benchmarks_dir() -> Path:
    env = os.environ.get("FLOODSPH_BENCHMARKS")
    return (
        Path(env) if env else Path(__file__).resolve().parents[2] / ".." / "shared" / "benchmarks"
    )


def test_malpasset_dem():
    path = benchmarks_dir() / "malpasset" / "malpasset_dem_epsg27572_20m.tif"
    if not path.is_file():
        pytest.skip("Malpasset benchmark data not available")
    ter = load_terrain(path)
    assert CRS.from_wkt(ter.crs_wkt).to_epsg() == 27572
    assert (ter.dx, ter.dy) == (20.0, 20.0)
    assert ter.valid.any() and not ter.valid.all()
    assert np.all(np.isfinite(ter.elevation))


def test_utm_zone_choice():
    from floodsph.inputs.dem import utm_crs_for

    assert utm_crs_for(6.76, 43.51).to_epsg() == 32632  # Malpasset, France
    assert utm_crs_for(-70.65, -33.45).to_epsg() == 32719  # Santiago de Chile
    assert utm_crs_for(179.99, 10.0).to_epsg() == 32660
    # Zone borders (multiples of 6 degrees) go to the eastern zone; the edges of the map and
    # the poles stay in zones 1..60.
    assert utm_crs_for(0.0, 10.0).to_epsg() == 32631
    assert utm_crs_for(-180.0, -10.0).to_epsg() == 32701
    assert utm_crs_for(180.0, 10.0).to_epsg() == 32660
    assert utm_crs_for(20.0, 89.0).to_epsg() == 32634
    # Bergen lies in the regular zone 31 (the military grid's zone 32V is not an EPSG area).
    assert utm_crs_for(5.32, 60.39).to_epsg() == 32631


def test_web_mercator_dem_is_reprojected_to_ground_metres(tmp_path):
    # 100 x 100 cells of 20 m in EPSG:3857 at 36.7 N: 1 / cos(36.7 deg) = 1.247, so the
    # cells are 16.0 m on the ground.
    merc = CRS.from_epsg(3857)
    x0, y0 = warp_transform(CRS.from_epsg(4326), merc, [-87.0], [36.7])
    z = np.full((100, 100), 200.0)
    path = write_tif(tmp_path / "merc.tif", z, from_origin(x0[0], y0[0], 20.0, 20.0), "EPSG:3857")
    warnings = []
    ter = load_terrain(path, warnings=warnings)
    assert CRS.from_wkt(ter.crs_wkt).to_epsg() == 32616
    assert ter.dx == ter.dy == 16.0
    lo, hi = ter.source_scale
    assert 1.245 < lo < hi < 1.250
    assert [w for w in warnings if "merc.tif" in w and "EPSG:3857" in w and "1.247" in w
            and "EPSG:32616" in w and "16 m square cells" in w]
    # The area with data is the true ground area: (2000 m / 1.247)^2, within a row of cells.
    area = ter.valid.sum() * ter.dx * ter.dy
    assert area == pytest.approx((2000.0 / 1.2472) ** 2, rel=0.03)


def test_web_mercator_near_the_equator_is_kept(tmp_path):
    # At 2 N the scale factor is 1.0006: within 0.5 %, the DEM is used as it is.
    path = write_tif(tmp_path / "eq.tif", ramp(), from_origin(0.0, 222_000.0, 20.0, 20.0),
                     "EPSG:3857")
    ter = load_terrain(path)
    assert CRS.from_wkt(ter.crs_wkt).to_epsg() == 3857 and ter.dx == 20.0
    assert ter.source_scale[1] == pytest.approx(1.0006, abs=1e-4)
