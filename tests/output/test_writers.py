"""GeoTIFF, NetCDF and gauge files read back with the same values, CRS and transform."""

import csv
import json

import numpy as np
import pytest
import rasterio
import xarray as xr
from rasterio.crs import CRS
from rasterio.transform import from_origin

import floodsph
from floodsph.constants import RHO_WATER
from floodsph.errors import InputError
from floodsph.io.run_names import PICTURE_NAMES
from floodsph.model.terrain import Terrain
from floodsph.output import write_maps
from floodsph.output.envelopes import MAPS, Envelopes
from floodsph.output.gauges import Gauges, read_gauge_file
from floodsph.output.geotiff import write_geotiff
from floodsph.output.grid import OutputGrid
from floodsph.output.netcdf import SnapshotWriter, write_flood_maps

X0, Y0, CELL = 431000.0, 5012000.0, 5.0
CRS_UTM = CRS.from_epsg(32632)


@pytest.fixture(scope="module")
def terrain():
    t = Terrain.from_function(lambda x, y: 0.01 * (x - X0) + 0.02 * (y - Y0),
                              (X0, X0 + 300.0), (Y0, Y0 + 200.0), CELL)
    t.crs_wkt = CRS_UTM.to_wkt()
    return t


def particles(x0, x1, y0, y1, d, u):
    g = np.arange(x0, x1, 2.0) + 1.0
    X, Y = np.meshgrid(g, np.arange(y0, y1, 2.0) + 1.0)
    n = X.size
    rho = np.full(n, RHO_WATER * d)
    return (X.ravel(), Y.ravel(), np.full(n, u), np.zeros(n), rho * 4.0, rho, np.full(n, 2.6))


@pytest.fixture(scope="module")
def envelopes(terrain):
    env = Envelopes(OutputGrid.from_terrain(terrain), wet_threshold=0.05)
    env.update(0.0, 0.0, *particles(0.0, 120.0, 0.0, 200.0, 1.5, 0.5))
    env.update(1.0, 1.0, *particles(0.0, 180.0, 0.0, 100.0, 0.8, 2.5))
    return env


@pytest.fixture(scope="module")
def run_dir(envelopes, tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    write_maps(envelopes, out, scenario={"scenario": {"name": "test"}})
    return out


def test_geotiffs_read_back_north_up_with_crs_and_transform(envelopes, run_dir):
    maps = envelopes.maps()
    for name, (_, units, _) in MAPS.items():
        with rasterio.open(run_dir / f"{name}.tif") as src:
            assert src.crs == CRS_UTM
            assert src.transform == from_origin(X0, Y0 + 200.0, CELL, CELL)
            assert src.descriptions == (name,) and src.tags(1)["units"] == units
            assert src.units == (units,)            # GDAL's band unit type
            assert src.tags()["wet_threshold_m"] == "0.05"
            assert src.profile["tiled"] and src.profile["compress"] == "deflate"
            data = src.read(1)
        expected = maps[name][::-1]
        if name.startswith("hazard"):
            assert data.dtype == np.uint8 and src.nodata == 0
            np.testing.assert_array_equal(data, expected)
        else:
            assert data.dtype == np.float32 and np.isnan(src.nodata)
            np.testing.assert_array_equal(data, expected.astype(np.float32))
    # Something was mapped: the north-west water (row 0 of the file is the north).
    with rasterio.open(run_dir / "max_depth.tif") as src:
        assert src.read(1)[10, 5] == pytest.approx(1.5, abs=1e-6)
        assert np.isnan(src.read(1)[10, 50])


def test_hazard_geotiff_has_colour_table_and_class_names(run_dir):
    with rasterio.open(run_dir / "hazard_arr.tif") as src:
        assert src.colormap(1)[6] == (128, 0, 38, 255)
        assert src.tags(1)["class_1"].startswith("H1")
        assert src.read(1).max() == 5    # d = 0.8, v = 2.5 > 2 m/s, d v = 2 -> H5


def test_geotiff_fallback_layout_matches_cog(terrain, tmp_path):
    grid = OutputGrid.from_terrain(terrain)
    a = np.linspace(0.0, 1.0, grid.nx * grid.ny).reshape(grid.shape)
    for driver in ("COG", "GTiff"):
        path = write_geotiff(tmp_path / f"{driver}.tif", a, grid, "x", "m", driver=driver)
        with rasterio.open(path) as src:
            np.testing.assert_array_equal(src.read(1), a[::-1].astype(np.float32))
            assert src.transform == grid.north_up_transform()


def test_netcdf_is_cf_and_matches_the_maps(envelopes, run_dir):
    maps = envelopes.maps()
    with xr.open_dataset(run_dir / "flood_maps.nc") as ds:
        assert ds.attrs["Conventions"] == "CF-1.8"
        assert ds.attrs["source"].startswith("floodsph ")
        assert json.loads(ds.attrs["scenario"]) == {"scenario": {"name": "test"}}
        assert ds.attrs["wet_threshold_m"] == 0.05
        assert CRS.from_wkt(ds["crs"].attrs["crs_wkt"]) == CRS_UTM
        assert ds["crs"].attrs["grid_mapping_name"] == "transverse_mercator"
        assert ds["x"].attrs["standard_name"] == "projection_x_coordinate"
        np.testing.assert_allclose(ds["x"].values, X0 + (np.arange(60) + 0.5) * CELL)
        np.testing.assert_allclose(ds["y"].values, Y0 + 200.0 - (np.arange(40) + 0.5) * CELL)
        for name, (long_name, units, cell_methods) in MAPS.items():
            var = ds[name]
            assert var.attrs["long_name"] == long_name and var.attrs["units"] == units
            assert var.attrs.get("cell_methods") == cell_methods
            np.testing.assert_array_equal(var.values, maps[name][::-1].astype(var.dtype))
        assert ds["hazard_uk"].attrs["flag_values"].tolist() == [0, 1, 2, 3, 4]
        assert ds["hazard_arr"].values.max() == 5     # H5 as in the GeoTIFF
        assert ds["hazard_uk"].attrs["flag_meanings"].split()[:2] == ["dry",
                                                                      "low_hazard_caution"]
    # GDAL reads the same georeference from the NetCDF.
    with rasterio.open(f"netcdf:{run_dir / 'flood_maps.nc'}:max_depth") as src:
        assert src.crs == CRS_UTM
        assert src.transform.almost_equals(from_origin(X0, Y0 + 200.0, CELL, CELL))


def test_netcdf_without_crs_has_no_grid_mapping(tmp_path):
    """Synthetic terrain (no CRS): no ``crs`` variable for ``grid_mapping`` to point at."""
    t = Terrain.from_function(lambda x, y: 0.0 * x, (0.0, 50.0), (0.0, 30.0), CELL)
    grid = OutputGrid.from_terrain(t)
    path = write_flood_maps(tmp_path / "m.nc", {"max_depth": np.ones(grid.shape)},
                            {"max_depth": MAPS["max_depth"]}, grid, class_names={})
    with xr.open_dataset(path) as ds:
        assert "crs" not in ds.variables and "grid_mapping" not in ds["max_depth"].attrs
        assert ds["max_depth"].attrs["standard_name"] == "flood_water_thickness"


def test_snapshots_append_along_unlimited_time(terrain, tmp_path):
    grid = OutputGrid.from_terrain(terrain)
    d = np.full(grid.shape, np.nan)
    d[:4] = 0.25
    with SnapshotWriter(tmp_path / "snapshots.nc", grid) as w:
        w.append(0.0, d, d * 0, d * 0)
        w.append(5.0, d * 2, d * 0 + 1, d * 0)
    with xr.open_dataset(tmp_path / "snapshots.nc") as ds:
        # no start: seconds since the placeholder 1970-01-01 (floodsph.output.cf.NO_START)
        assert list(ds["time"].values) == [np.datetime64("1970-01-01T00:00:00"),
                                           np.datetime64("1970-01-01T00:00:05")]
        assert ds.encoding["unlimited_dims"] == {"time"}
        np.testing.assert_array_equal(ds["depth"].values[1], (d * 2)[::-1].astype(np.float32))
        assert ds["u"].attrs["units"] == "m s-1"


def test_gauges_sample_depth_level_and_nan_when_dry(terrain, tmp_path):
    gauge_file = tmp_path / "gauges.csv"
    gauge_file.write_text(f"id,x,y\nwet,{X0 + 60},{Y0 + 50}\ndry,{X0 + 250},{Y0 + 150}\n")
    points = read_gauge_file(gauge_file, terrain)
    gauges = Gauges(points, interval_s=1.0, wet_threshold=0.05)
    gauges.sample(2.0, *particles(0.0, 120.0, 0.0, 200.0, 1.5, 0.5))
    out = gauges.write_csv(tmp_path / "out.csv")
    rows = list(csv.DictReader(open(out)))
    assert list(rows[0]) == ["time_s", "id", "depth_m", "level_m", "speed_ms"]
    assert float(rows[0]["depth_m"]) == pytest.approx(1.5)
    assert float(rows[0]["level_m"]) == pytest.approx(1.5 + 0.01 * 60 + 0.02 * 50, abs=1e-4)
    assert float(rows[0]["speed_ms"]) == pytest.approx(0.5)
    assert rows[1]["id"] == "dry" and np.isnan(float(rows[1]["depth_m"]))


def test_gauge_outside_the_dem_is_named(terrain, tmp_path):
    gauge_file = tmp_path / "g.csv"
    gauge_file.write_text("id,x,y\nG7,0,0\n")
    with pytest.raises(InputError, match=r"g\.csv, line 2: gauge 'G7' .* outside the DEM"):
        read_gauge_file(gauge_file, terrain)


def test_pictures_are_written_or_skipped_with_a_message(envelopes, tmp_path, monkeypatch):
    from floodsph.output import write_pictures

    paths = write_pictures(envelopes, tmp_path, title="t")
    assert sorted(p.name for p in paths) == [
        "arrival_time.png", "duration.png", "hazard_arr.png", "hazard_uk.png", "max_depth.png",
        "max_speed.png", "max_unit_discharge.png"]
    # Every picture is a run file, so that a later run may replace the folder.
    assert {p.name for p in paths} == set(PICTURE_NAMES)
    assert all(p.stat().st_size > 10_000 for p in paths)
    monkeypatch.setitem(__import__("sys").modules, "matplotlib", None)
    assert write_pictures(envelopes, tmp_path) == "pictures skipped: matplotlib not installed"


def test_result_tables_format_floats_and_nan(tmp_path):
    from floodsph.output.tables import markdown, write_csv

    rows = [{"case": "a", "wall_s": np.float64(12.3456789), "l1": float("nan"), "n": 3}]
    path = write_csv(tmp_path / "t.csv", rows, spec=".3f")
    assert path.read_text().splitlines() == ["case,wall_s,l1,n", "a,12.346,nan,3"]
    assert markdown(rows, ["case", "wall_s"]).splitlines() == [
        "| case | wall_s |", "|---|---|", "| a | 12.35 |"]


@pytest.mark.parametrize("start", [None, "2024-01-15T07:00:00+01:00"])
def test_maps_are_the_same_dataset_whatever_formats_the_run_wrote(envelopes, tmp_path, start):
    """``open_run(folder).maps()`` from GeoTIFFs only, NetCDF only and both: identical
    variables, values, dtypes (class maps uint8), flags, attributes, coordinates and dated
    time; only ``history`` (when the file read was written) may differ."""
    from datetime import UTC, datetime, timedelta

    from floodsph.run.manifest import write_manifest
    from floodsph.run.results import open_run

    scenario = {"scenario": {"name": "formats", "end_time_s": 2.0}}
    if start is not None:
        scenario["scenario"]["start"] = start
    got = {}
    for formats in (("geotiff",), ("netcdf",), ("geotiff", "netcdf")):
        folder = tmp_path / "+".join(formats)
        write_maps(envelopes, folder, formats, scenario=scenario,
                   start=None if start is None else datetime.fromisoformat(start))
        write_manifest(folder, {"status": "completed", "scenario": scenario, "start": start})
        got[formats] = open_run(folder).maps()
    both = got[("geotiff", "netcdf")]
    assert both["hazard_uk"].dtype == np.uint8 and both["hazard_arr"].dtype == np.uint8
    assert both["hazard_uk"].attrs["flag_values"].dtype == np.uint8
    assert both["hazard_uk"].attrs["flag_meanings"].split()[0] == "dry"
    assert both.attrs["wet_threshold_m"] == 0.05
    assert json.loads(both.attrs["scenario"]) == scenario
    epoch = datetime(2024, 1, 15, 6, tzinfo=UTC) if start else datetime(1970, 1, 1, tzinfo=UTC)
    end = (epoch + timedelta(seconds=envelopes.t_last)).replace(tzinfo=None)
    assert both["time"].values == np.datetime64(end)
    assert int(np.isnan(both["max_depth"]).sum()) > 0      # never-wet cells are NaN
    for formats, ds in got.items():
        assert ds.attrs["history"].endswith(" written by floodsph " + floodsph.__version__)
        ds = ds.assign_attrs(history=both.attrs["history"])
        xr.testing.assert_identical(ds, both)
        for name in ds.variables:
            assert ds[name].dtype == both[name].dtype, (formats, name)


@pytest.mark.parametrize("fail_in", ["geotiff", "netcdf"])
def test_a_writer_that_fails_half_way_leaves_the_old_file_and_no_temporary(
        terrain, tmp_path, monkeypatch, fail_in):
    grid = OutputGrid.from_terrain(terrain)
    target = tmp_path / ("m.tif" if fail_in == "geotiff" else "m.nc")
    target.write_bytes(b"the previous run's map")

    def half_write(*args, **kwargs):
        raise OSError(28, "No space left on device")

    if fail_in == "geotiff":
        monkeypatch.setattr("floodsph.output.geotiff._fill", half_write)
        with pytest.raises(OSError, match="No space"):
            write_geotiff(target, np.ones(grid.shape), grid, "max_depth", "m", driver="COG")
    else:
        monkeypatch.setattr(xr.Dataset, "to_netcdf",
                            lambda self, part, **kw: (open(part, "wb").write(b"half"),
                                                      half_write()))
        with pytest.raises(OSError, match="No space"):
            write_flood_maps(target, {"max_depth": np.ones(grid.shape)},
                             {"max_depth": MAPS["max_depth"]}, grid, class_names={})
    assert target.read_bytes() == b"the previous run's map"
    assert sorted(p.name for p in tmp_path.iterdir()) == [target.name]
