"""``floodsph ensemble`` on a real LocalCluster of 2 worker processes, then ``--resume``.

Six members of the tiny dam break (``ensemble_cases``): the basin level is uniform in
101.5-103.5 m, and Manning's n is a choice of 0.03 (weight 2) or a file that is not a raster
(weight 1). Latin-hypercube strata put exactly two members on the broken file: they fail
when the run reads it, and the other four complete. The maps must equal what numpy computes
from the four completed members' own map files.
"""

from __future__ import annotations

import csv
import json
import tomllib

import numpy as np
import pytest
from click.testing import CliRunner
from ensemble_cases import LEVEL, ensemble_text, write_case

from floodsph.cli.main import cli

MANNING = """
[[ensemble.parameters]]
key = "terrain.manning"
distribution = "choice"
values = [0.03, "broken.tif"]
weights = [2.0, 1.0]
"""
QUANTILES = (0.05, 0.5, 0.95)


def invoke(*args):
    return CliRunner().invoke(cli, ["-q", *(str(a) for a in args)])


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ensemble")
    (folder / "broken.tif").write_text("not a raster")
    path = write_case(folder, ensemble_text(LEVEL + MANNING, members=6))
    result = invoke("ensemble", path, "--workers", 2, "--threads-per-worker", 1)
    return result, folder / "out" / "tiny"


@pytest.fixture(scope="module")
def samples(case):
    _, out = case
    with open(out / "samples.csv", newline="") as f:
        return list(csv.DictReader(f))


@pytest.fixture(scope="module")
def completed(case, samples):
    _, out = case
    return [out / "members" / row["member"] for row in samples if row["status"] == "completed"]


def read(path):
    import rasterio

    with rasterio.open(path) as src:
        return src.read(1).astype(np.float64)


def stack(folders, name):
    return np.array([read(folder / f"{name}.tif") for folder in folders])


def test_failed_members_are_counted_and_the_rest_complete(case, samples):
    result, out = case
    assert result.exit_code == 0, result.output
    manifest = json.loads((out / "ensemble.json").read_text())
    assert (manifest["status"], manifest["members"], manifest["members_completed"],
            manifest["members_failed"]) == ("completed_with_failures", 6, 4, 2)
    assert (manifest["scheduler"], manifest["workers"], manifest["threads_per_worker"]) == (
        "local", 2, 1)
    for row in samples:
        broken = row["terrain.manning"] == "broken.tif"
        assert row["status"] == ("failed" if broken else "completed"), row
        assert ("broken.tif" in row["error"]) == broken


def test_members_are_run_folders_of_their_sampled_scenario(completed, samples):
    levels = {row["member"]: float(row["initial_water[0].level_m"]) for row in samples}
    for folder in completed:
        run = json.loads((folder / "run.json").read_text())
        scenario = tomllib.loads((folder / "scenario.toml").read_text())
        assert run["status"] == "completed"
        assert run["threads"] == 1
        assert scenario["initial_water"][0]["level_m"] == levels[folder.name]
        assert run["scenario"]["initial_water"][0]["level_m"] == levels[folder.name]
        assert scenario["output"]["directory"] == str(folder)


def test_probability_maps_are_the_fractions_of_completed_members(case, completed):
    _, out = case
    depth = np.nan_to_num(stack(completed, "max_depth"))
    hazard = stack(completed, "hazard_uk")
    outside = np.isnan(read(out / "p_depth_gt_0.1m.tif"))
    assert not outside.any()  # the whole DEM has data
    for t, label in ((0.1, "0.1"), (0.5, "0.5"), (1.0, "1"), (2.0, "2")):
        p = read(out / f"p_depth_gt_{label}m.tif")
        np.testing.assert_allclose(p, (depth > t).sum(axis=0) / 4.0)
    p01 = read(out / "p_depth_gt_0.1m.tif")
    assert ((p01 > 0) & (p01 < 1)).any()  # members differ in extent
    for k in (1, 2, 3, 4):
        np.testing.assert_allclose(read(out / f"p_hazard_uk_ge_{k}.tif"),
                                   (hazard >= k).sum(axis=0) / 4.0)


def test_quantile_maps_are_numpy_quantiles_of_completed_members(case, completed):
    _, out = case
    for name in ("max_depth", "max_speed"):
        values = np.nan_to_num(stack(completed, name))
        for q, label in zip(QUANTILES, ("q05", "q50", "q95"), strict=True):
            np.testing.assert_allclose(read(out / f"{name}_{label}.tif"),
                                       np.quantile(values, q, axis=0), rtol=1e-6, atol=1e-7)
    arrival = stack(completed, "arrival_time")
    wet = np.isfinite(arrival).sum(axis=0)
    median = read(out / "arrival_time_q50.tif")
    assert np.array_equal(np.isnan(median), wet < 2)
    some = wet >= 2
    np.testing.assert_allclose(median[some], np.nanquantile(arrival[:, some], 0.5, axis=0),
                               rtol=1e-6)


def test_netcdf_holds_the_same_maps_with_threshold_and_quantile_dimensions(case):
    import xarray as xr

    _, out = case
    with xr.open_dataset(out / "ensemble_maps.nc") as ds:
        assert ds.attrs["Conventions"] == "CF-1.8"
        assert ds["p_depth_gt"].dims == ("threshold", "y", "x")
        assert list(ds["threshold"].values) == [0.1, 0.5, 1.0, 2.0]
        assert list(ds["quantile"].values) == list(QUANTILES)
        assert ds["max_depth_q"].attrs["grid_mapping"] == "crs"
        np.testing.assert_array_equal(ds["p_depth_gt"].sel(threshold=0.5).values,
                                      read(out / "p_depth_gt_0.5m.tif"))
        np.testing.assert_array_equal(ds["arrival_time_q"].sel(quantile=0.95).values,
                                      read(out / "arrival_time_q95.tif"))
        np.testing.assert_array_equal(ds["p_hazard_uk_ge"].sel(hazard_uk_class=2).values,
                                      read(out / "p_hazard_uk_ge_2.tif"))
        assert ds.attrs["members_completed"] == 4


def test_maps_are_cloud_optimized_geotiffs(case):
    import rasterio

    _, out = case
    with rasterio.open(out / "max_depth_q50.tif") as src:
        assert src.tags(ns="IMAGE_STRUCTURE").get("LAYOUT") == "COG"
        assert src.crs.to_epsg() == 32632
    assert (out / "ensemble.png").stat().st_size > 0


@pytest.fixture(scope="module")
def resumed(case, completed):
    _, out = case
    started = {f.name: json.loads((f / "run.json").read_text())["started"] for f in completed}
    result = invoke("ensemble", out.parents[1] / "ensemble.toml", "--resume")
    return result, started


def test_resume_reruns_nothing_that_completed(case, completed, resumed):
    _, out = case
    result, started = resumed
    assert result.exit_code == 0, result.output
    for folder in completed:
        assert json.loads((folder / "run.json").read_text())["started"] == started[folder.name]
    manifest = json.loads((out / "ensemble.json").read_text())
    assert (manifest["members_kept"], manifest["members_completed"],
            manifest["members_failed"]) == (4, 4, 2)


def test_resume_runs_the_failed_members_again(case, samples, resumed):
    _, out = case
    with open(out / "samples.csv", newline="") as f:
        again = {row["member"]: row for row in csv.DictReader(f)}
    for row in samples:
        if row["status"] == "failed":
            assert again[row["member"]]["status"] == "failed"
            assert again[row["member"]]["wall_time_s"] != row["wall_time_s"]


def test_local_workers_get_their_threads_no_malloc_trim_and_no_profiler():
    """Workers start with NUMBA_NUM_THREADS = the threads per worker, without dask's
    MALLOC_TRIM_THRESHOLD_ and with the profiler off (floodsph.ensemble.engine.CLUSTER_CONFIG)."""
    import os

    import dask

    from floodsph.ensemble.engine import WorkerPlan, open_client

    names = ("NUMBA_NUM_THREADS", "MALLOC_TRIM_THRESHOLD_")
    with open_client(WorkerPlan(1, 2), None) as client:
        env = client.submit(lambda: {k: os.environ.get(k) for k in names}, pure=False).result()
        profile = client.run(lambda: dask.config.get("distributed.worker.profile.enabled"))
    assert env == {"NUMBA_NUM_THREADS": "2", "MALLOC_TRIM_THRESHOLD_": None}
    assert list(profile.values()) == [False]
