"""Map comparison: contingency scores on hand-built maps, alignment of shifted grids, CLI."""

import csv
import json
import math

import numpy as np
import pytest
import rasterio
from click.testing import CliRunner
from rasterio.crs import CRS
from rasterio.transform import from_origin

from floodsph.cli.compare import command
from floodsph.errors import InputError
from floodsph.output.compare import compare, scores, write_outputs

CELL = 10.0
WEST, NORTH = 500000.0, 4200000.0


def write(path, data, west=WEST, north=NORTH, crs="EPSG:32633", desc=None):
    profile = {"driver": "GTiff", "width": data.shape[1], "height": data.shape[0], "count": 1,
               "dtype": str(data.dtype), "crs": crs,
               "transform": from_origin(west, north, CELL, CELL),
               "nodata": 0 if data.dtype == np.uint8 else float("nan")}
    with rasterio.open(path, "w", **profile) as dst:
        dst.write(data, 1)
        if desc:
            dst.set_band_description(1, desc)
    return path


def test_scores_from_counts_by_hand():
    s = scores(hits=6, false_alarms=3, misses=2)
    assert s["hit_rate"] == pytest.approx(6 / 8)
    assert s["false_alarm_ratio"] == pytest.approx(3 / 9)
    assert s["csi"] == pytest.approx(6 / 11)
    assert s["f2"] == pytest.approx(3 / 11)
    assert s["error_bias"] == pytest.approx(1.5)
    assert scores(4, 2, 0)["error_bias"] == math.inf
    assert math.isnan(scores(0, 0, 0)["csi"])


def test_hand_built_maps_counts_and_depth_errors(tmp_path):
    a = np.full((10, 10), np.nan, dtype=np.float32)
    b = np.full((10, 10), np.nan, dtype=np.float32)
    a[0, :6] = 1.0          # 6 cells wet in both ...
    b[0, :6] = 0.5          # ... with model - reference = 0.5 m
    a[1, :3] = 0.2          # 3 false alarms
    b[2, :2] = 0.3          # 2 misses
    a[3, 0] = 0.05          # below the 0.1 m threshold: dry, not a false alarm
    r = compare(write(tmp_path / "a.tif", a), write(tmp_path / "b.tif", b), threshold=0.1)
    s = r.summary
    assert (s["hits"], s["false_alarms"], s["misses"], s["correct_negatives"]) == (6, 3, 2, 89)
    assert s["csi"] == pytest.approx(6 / 11) and s["f2"] == pytest.approx(3 / 11)
    assert s["depth"] == {"n": 6, "rmse": pytest.approx(0.5), "bias": pytest.approx(0.5),
                          "mae": pytest.approx(0.5)}
    assert r.difference[2, 0] == pytest.approx(-0.3) and np.isnan(r.difference[5, 5])


@pytest.mark.parametrize("k", [1, 5])
def test_reference_shifted_by_k_cells_gives_hand_computed_csi(tmp_path, k):
    """A 20 x 10 wet block against itself moved k cells east: hits 10 (20 - k), etc."""
    depth = np.zeros((40, 60), dtype=np.float32)
    depth[10:20, 10:30] = 1.0
    model = write(tmp_path / "model.tif", depth)
    ref = write(tmp_path / "ref.tif", depth, west=WEST + k * CELL)
    s = compare(model, ref, threshold=0.1).summary
    assert (s["hits"], s["false_alarms"], s["misses"]) == (10 * (20 - k), 10 * k, 10 * k)
    assert s["cells_compared"] == 40 * (60 - k)      # the reference covers columns k..59
    assert s["csi"] == pytest.approx((20 - k) / (20 + k))
    assert s["depth"]["rmse"] == pytest.approx(0.0, abs=1e-6)


def test_arrival_maps_and_points(tmp_path):
    a = np.full((5, 5), np.nan, dtype=np.float32)
    a[:, :3] = 60.0
    b = a.copy()
    b[:, :2] = 90.0
    pa = write(tmp_path / "a.tif", a, desc="arrival_time")
    pb = write(tmp_path / "b.tif", b, desc="arrival_time")
    s = compare(pa, pb).summary
    assert s["kind"] == "arrival" and s["arrival"]["n"] == 15
    assert s["arrival"]["bias"] == pytest.approx(-30.0 * 10 / 15)
    depth = np.zeros((5, 5), dtype=np.float32)
    depth[:, 0] = 2.0
    obs = tmp_path / "hwm.csv"
    obs.write_text(f"id,x,y,observed\nP1,{WEST + 5},{NORTH - 15},1.5\n"
                   f"P2,{WEST + 25},{NORTH - 15},0.5\n")
    pd = write(tmp_path / "d.tif", depth)
    s = compare(pd, pd, points=obs).summary
    # P1: 2.0 - 1.5 = 0.5; P2 is on a dry cell (depth 0): 0 - 0.5 = -0.5.
    assert s["points"]["n"] == 2 and s["points"]["bias"] == pytest.approx(0.0)
    assert s["points"]["rmse"] == pytest.approx(0.5)


def test_rasters_without_crs_or_overlap_are_refused(tmp_path):
    d = np.ones((4, 4), dtype=np.float32)
    good = write(tmp_path / "good.tif", d)
    bare = write(tmp_path / "bare.tif", d, crs=None)
    with pytest.raises(InputError, match=r"bare\.tif: the raster has no CRS"):
        compare(good, bare)
    far = write(tmp_path / "far.tif", d, west=WEST + 1e5)
    with pytest.raises(InputError, match=r"good\.tif and .*far\.tif do not overlap"):
        compare(good, far)


def test_cli_prints_table_and_writes_outputs(tmp_path):
    depth = np.zeros((30, 30), dtype=np.float32)
    depth[5:15, 5:15] = 0.8
    a = write(tmp_path / "a.tif", depth)
    b = write(tmp_path / "b.tif", np.roll(depth, 2, axis=1))
    out = tmp_path / "cmp"
    result = CliRunner().invoke(command, [str(a), str(b), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "csi" in result.output and "0.6667" in result.output     # 80 / 120
    summary = json.loads((out / "comparison.json").read_text())
    assert summary["hits"] == 80 and summary["misses"] == 20
    with rasterio.open(out / "difference.tif") as src:
        assert src.crs == CRS.from_epsg(32633)
        assert src.read(1)[5, 5] == pytest.approx(0.8)
    assert (out / "comparison.png").stat().st_size > 0


def netcdf_and_geotiffs(folder, maps):
    """``maps`` (north-up, name -> array) written by the run's writers as ``<name>.tif`` and
    as variables of ``flood_maps.nc`` on the grid of :func:`write` (EPSG:32633)."""
    from floodsph.output.envelopes import MAPS
    from floodsph.output.geotiff import write_geotiff
    from floodsph.output.grid import OutputGrid
    from floodsph.output.netcdf import write_flood_maps

    ny, nx = next(iter(maps.values())).shape
    grid = OutputGrid(nx, ny, CELL, CELL, WEST, NORTH - ny * CELL,
                      CRS.from_epsg(32633).to_wkt(), np.zeros((ny, nx)))
    south_up = {name: a[::-1] for name, a in maps.items()}
    for name, a in south_up.items():
        write_geotiff(folder / f"{name}.tif", a, grid, name, MAPS[name][1])
    names = {"hazard_uk": ("Dry", "Low", "Some", "Most", "All")}
    return write_flood_maps(folder / "flood_maps.nc", south_up, MAPS, grid, class_names=names)


def shifted_maps():
    """A depth block with arrival times and UK classes, and the same block 2 cells east."""
    depth = np.full((20, 30), np.nan, dtype=np.float32)
    depth[4:12, 5:15] = np.linspace(0.05, 1.5, 80, dtype=np.float32).reshape(8, 10)
    arrival = np.where(np.isfinite(depth), 30.0 + np.arange(30, dtype=np.float32), np.nan)
    hazard = np.where(np.nan_to_num(depth) > 0.1, 1 + (np.nan_to_num(depth) > 0.8), 0)
    model = {"max_depth": depth, "arrival_time": arrival.astype(np.float32),
             "hazard_uk": hazard.astype(np.uint8)}
    return model, {name: np.roll(a, 2, axis=1) for name, a in model.items()}


@pytest.mark.parametrize("name", ["max_depth", "arrival_time", "hazard_uk"])
def test_a_netcdf_variable_gives_the_numbers_of_its_geotiff(tmp_path, name):
    model, ref = shifted_maps()
    nc = netcdf_and_geotiffs(tmp_path, model)
    (tmp_path / "ref").mkdir()
    netcdf_and_geotiffs(tmp_path / "ref", ref)
    reference = tmp_path / "ref" / f"{name}.tif"
    from_tif = compare(tmp_path / f"{name}.tif", reference)
    from_nc = compare(f"{nc}:{name}", reference)
    from_both = compare(f"{nc}:{name}", f"{tmp_path / 'ref' / 'flood_maps.nc'}:{name}")
    expected_kind = {"max_depth": "depth", "arrival_time": "arrival",
                     "hazard_uk": "hazard_uk"}
    assert from_tif.summary["kind"] == expected_kind[name]
    assert from_tif.summary["hits"] > 0 and from_tif.summary["misses"] > 0
    for other in (from_nc, from_both):
        assert {k: v for k, v in other.summary.items() if k not in ("model", "reference")} == \
            {k: v for k, v in from_tif.summary.items() if k not in ("model", "reference")}
        np.testing.assert_array_equal(other.difference, from_tif.difference)
    assert from_nc.summary["model"] == f"{nc}:{name}"


def compare_cli(*args):
    from floodsph.cli.main import cli

    return CliRunner().invoke(cli, ["compare", *[str(a) for a in args]])


def assert_one_message(result, *parts):
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and result.output.count("Error:") == 1
    for part in parts:
        assert part in result.output, result.output


def test_compare_errors_name_the_map_at_fault(tmp_path):
    model, _ = shifted_maps()
    nc = netcdf_and_geotiffs(tmp_path, model)
    tif = tmp_path / "max_depth.tif"
    assert_one_message(compare_cli(tif, nc), f"{nc} holds several maps (max_depth, ",
                       f"{nc}:max_depth")
    assert_one_message(compare_cli(tif, f"{nc}:max_deep"),
                       f"{nc}:max_deep: {nc} has no map variable 'max_deep'", "max_depth")
    assert_one_message(compare_cli(f"{tif}:max_depth", tif), f"{tif} is not a NetCDF file")
    assert_one_message(compare_cli(tif, tmp_path / "missing.tif"), "missing.tif: no such file")
    text = tmp_path / "notes.tif"
    text.write_text("not a raster\n")
    assert_one_message(compare_cli(tif, text), f"{text}: cannot read it as a raster")
    two = tmp_path / "two.tif"
    profile = {"driver": "GTiff", "width": 4, "height": 4, "count": 2, "dtype": "float32",
               "crs": "EPSG:32633", "transform": from_origin(WEST, NORTH, CELL, CELL)}
    with rasterio.open(two, "w", **profile) as dst:
        dst.write(np.ones((2, 4, 4), dtype=np.float32))
    assert_one_message(compare_cli(tif, two), f"{two} has 2 bands")


def test_maps_of_different_quantities_are_refused_naming_both(tmp_path):
    model, _ = shifted_maps()
    model["max_speed"] = model["max_depth"] * 2
    model["duration"] = np.where(np.isfinite(model["max_depth"]), 600.0, np.nan).astype(
        np.float32)
    nc = netcdf_and_geotiffs(tmp_path, model)
    depth = tmp_path / "max_depth.tif"
    assert_one_message(compare_cli(depth, f"{nc}:max_speed"),
                       f"{depth} is a depth map (band description 'max_depth')",
                       f"{nc}:max_speed is a speed map (standard_name 'flood_water_speed')",
                       "same quantity")
    assert_one_message(compare_cli(depth, tmp_path / "duration.tif"),
                       f"{tmp_path / 'duration.tif'} is a wet-duration map")
    assert_one_message(compare_cli(tmp_path / "arrival_time.tif", depth),
                       "arrival_time.tif is an arrival-time map (band description")
    assert_one_message(compare_cli(depth, tmp_path / "hazard_uk.tif"), "a UK-hazard-class map")
    assert_one_message(compare_cli(depth, depth, "--arrival"),
                       f"{depth} is a depth map", "--arrival asks for arrival times")


def test_a_map_without_metadata_takes_the_quantity_of_the_other(tmp_path):
    """A benchmark raster without description or units is compared as what the model map
    holds: a speed map's wet cells are those with a value, not those above 0.1 m."""
    model, _ = shifted_maps()
    speed = np.where(np.isfinite(model["max_depth"]), 0.05, np.nan).astype(np.float32)
    model["max_speed"] = speed
    netcdf_and_geotiffs(tmp_path, model)
    bare = write(tmp_path / "bare.tif", speed)
    s = compare(tmp_path / "max_speed.tif", bare).summary
    assert s["kind"] == "speed" and s["threshold_m"] is None
    assert s["hits"] == 80 and s["speed"]["rmse"] == pytest.approx(0.0, abs=1e-7)


def test_points_off_the_map_are_rows_marked_outside(tmp_path):
    depth = np.zeros((5, 5), dtype=np.float32)
    depth[:, 0] = 2.0
    d = write(tmp_path / "d.tif", depth)
    obs = tmp_path / "hwm.csv"
    obs.write_text(f"id,x,y,observed\nP1,{WEST + 5},{NORTH - 15},1.5\n"
                   f"FAR,{WEST + 5000},{NORTH - 15},1.0\n"
                   f"P2,{WEST + 25},{NORTH - 15},0.5\n")
    out = tmp_path / "cmp"
    result = compare_cli(d, d, "--points", obs, "--out", out)
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "comparison.json").read_text())
    assert summary["points"]["n"] == 2 and summary["points"]["outside"] == ["FAR"]
    assert summary["points"]["rmse"] == pytest.approx(0.5)
    with open(out / "points.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["id"] for r in rows] == ["P1", "FAR", "P2"]
    assert list(rows[0]) == ["id", "x", "y", "observed", "modelled", "error", "status"]
    assert float(rows[0]["modelled"]) == 2.0 and float(rows[0]["error"]) == pytest.approx(0.5)
    assert rows[1]["status"] == "outside" and rows[1]["modelled"] == "nan"
    assert rows[2]["status"] == "compared" and float(rows[2]["error"]) == pytest.approx(-0.5)


def test_difference_map_is_a_valid_cloud_optimized_geotiff(tmp_path):
    """On a map larger than one 512-cell tile: tiled, with internal overviews, in the COG
    layout (rio-cogeo's validator, strict: warnings count as failures)."""
    cog = pytest.importorskip("rio_cogeo.cogeo")
    depth = np.zeros((700, 900), dtype=np.float32)
    depth[100:600, 100:800] = 1.5
    a = write(tmp_path / "a.tif", depth)
    b = write(tmp_path / "b.tif", np.roll(depth, 7, axis=1))
    diff = write_outputs(compare(a, b), tmp_path / "cmp")[0]
    valid, problems, warns = cog.cog_validate(diff, strict=True)
    assert valid, (problems, warns)
    with rasterio.open(diff) as src:
        assert src.overviews(1) and src.profile["tiled"]
        assert src.units[0] == "m" and src.crs == CRS.from_epsg(32633)
        assert src.read(1)[300, 103] == pytest.approx(1.5)


def test_every_map_of_a_run_has_its_own_quantity_with_its_units():
    from floodsph.output.envelopes import CLASS_MAPS, MAPS
    from floodsph.output.quantities import MapMetadata, identify

    found = {}
    for name, (long_name, units, _) in MAPS.items():
        meta = MapMetadata(description=name, long_name=long_name, units=units,
                           integer=name in CLASS_MAPS)
        quantity, evidence = identify(meta)
        assert quantity.units == units and evidence == f"band description {name!r}"
        found[name] = quantity.name
    assert len(set(found.values())) == len(MAPS), found
