"""A small run's flood_maps.nc and snapshots.nc against the CF-1.8 conventions.

The run: the conftest valley with water at level 101 m held in its western 200 m (3 m deep
in the basin, 1 m on the floor), released at t = 0 onto the dry eastern floor (a dam break),
6 s, snapshots every 2 s, one gauge, a calendar start at 07:00 on 15 January 2024 in UTC+1.
The attributes are checked
against the CF rules themselves (coordinate variables without _FillValue, flag values that
are the class values, time units that a CF time library decodes, standard names of the CF
table), then, where installed (``pip install floodsph[cf]``), by the CF checker (cfchecks:
no error, no warning) and the IOOS compliance checker (no high-priority failure).
"""

from __future__ import annotations

import csv
import importlib.util
import json
from datetime import UTC, datetime, timedelta
from pathlib import Path

import netCDF4
import numpy as np
import pytest
from conftest import CELL, NY, X0, Y0, valley_elevation, write_geotiff
from rasterio.crs import CRS

from floodsph.output.envelopes import MAPS
from floodsph.run.pipeline import run_scenario
from floodsph.scenario.reader import load_scenario

END_S, SNAPSHOT_S, WET_M, DAM_M = 6.0, 2.0, 0.02, 200.0
START = "2024-01-15T07:00:00+01:00"
START_UTC = datetime(2024, 1, 15, 6, tzinfo=UTC)
DAM_BREAK = f"""
[scenario]
name = "cf"
end_time_s = {END_S}
start = {START}

[terrain]
dem = "dem.tif"
manning = 0.03
edges = "closed"

[[initial_water]]
level_m = 101.0
polygon = [[{X0}, {Y0}], [{X0 + DAM_M}, {Y0}], [{X0 + DAM_M}, {Y0 + NY * CELL}],
           [{X0}, {Y0 + NY * CELL}]]

[numerics]
particle_spacing_m = 10.0
refinement = "none"

[output]
resolution_m = 10.0
wet_threshold_m = {WET_M}
snapshot_interval_s = {SNAPSHOT_S}

[gauges]
file = "gauges.csv"
interval_s = 2.0
"""
NETCDF_FILES = ("flood_maps.nc", "snapshots.nc")


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("cf")
    write_geotiff(folder / "dem.tif", valley_elevation())
    (folder / "scenario.toml").write_text(DAM_BREAK)
    (folder / "gauges.csv").write_text(f"id,x,y\nfloor,{X0 + 250},{Y0 + 100}\n")
    manifest = run_scenario(load_scenario(folder / "scenario.toml"), folder / "out",
                            progress=False)
    assert manifest["status"] == "completed"
    return folder / "out"


def standard_names() -> dict[str, str]:
    """CF standard name -> canonical units, from the table the compliance checker ships."""
    import xml.etree.ElementTree as ET

    spec = importlib.util.find_spec("compliance_checker")
    if spec is None:
        pytest.skip("compliance-checker (floodsph[cf]) not installed: no CF standard name table")
    table = Path(spec.origin).parent / "data" / "cf-standard-name-table.xml"
    root = ET.parse(table).getroot()
    return {e.get("id"): e.findtext("canonical_units") for e in root.iter("entry")}


def test_the_dam_break_reached_the_floor(run_dir):
    """The files describe a real flood: water east of the dam, in the maps and snapshots."""
    with netCDF4.Dataset(run_dir / "flood_maps.nc") as ds:
        depth = ds["max_depth"][:].filled(np.nan)
        x = ds["x"][:]
    assert np.nanmax(depth[:, x > X0 + DAM_M]) > 0.1
    with netCDF4.Dataset(run_dir / "snapshots.nc") as ds:
        assert ds["depth"].shape[0] == len(np.arange(0.0, END_S + 1e-9, SNAPSHOT_S))


@pytest.mark.parametrize("name", NETCDF_FILES)
def test_coordinates_have_no_fill_value_and_crs_comes_from_pyproj(run_dir, name):
    with netCDF4.Dataset(run_dir / name) as ds:
        assert ds.Conventions == "CF-1.8"
        for var in ds.variables.values():
            if var.dimensions == (var.name,) or var.name in ("wet_threshold", "time"):
                assert "_FillValue" not in var.ncattrs(), var.name
        crs = ds["crs"]
        assert CRS.from_wkt(crs.crs_wkt) == CRS.from_epsg(32632)
        assert crs.grid_mapping_name == "transverse_mercator"
        assert crs.longitude_of_central_meridian == 9.0     # UTM zone 32: 6 * 32 - 183
        assert crs.scale_factor_at_central_meridian == pytest.approx(0.9996)


@pytest.mark.parametrize("name", NETCDF_FILES)
def test_standard_names_are_in_the_cf_table_with_the_units_written(run_dir, name):
    table = standard_names()
    import cf_units

    with netCDF4.Dataset(run_dir / name) as ds:
        named = {v.name: v for v in ds.variables.values() if "standard_name" in v.ncattrs()}
        for var in named.values():
            assert var.standard_name in table, (var.name, var.standard_name)
            if var.standard_name != "time":
                assert cf_units.Unit(var.units).is_convertible(
                    cf_units.Unit(table[var.standard_name])), var.name
    expected = ({"max_depth", "max_speed", "max_level", "arrival_time", "time_of_max_depth"}
                if name == "flood_maps.nc" else {"depth"})
    assert expected <= set(named)
    # No standard name where none is exact: total wet time is not the first-to-last
    # duration of flood_water_duration_above_threshold; grid x/y velocity is not eastward.
    assert not {"duration", "max_unit_discharge", "hazard_uk", "hazard_arr", "u", "v"} & set(
        named)


def test_hazard_flags_are_the_class_values_written(run_dir):
    with netCDF4.Dataset(run_dir / "flood_maps.nc") as ds:
        for name, k in (("hazard_uk", 5), ("hazard_arr", 7)):
            var = ds[name]
            values, meanings = list(var.flag_values), var.flag_meanings.split()
            assert values == list(range(k)) and len(meanings) == k and meanings[0] == "dry"
            assert var.dtype == var.flag_values.dtype == np.int8     # CF-1.8 has no ubyte
            assert set(np.unique(var[:])) <= set(values)
            assert np.unique(var[:]).size > 1                         # some wet classes


def test_threshold_and_period_coordinates(run_dir):
    """arrival_time names its threshold (the scenario's wet threshold); the maxima's
    ``time: maximum`` refers to a scalar time whose bounds are the whole run."""
    with netCDF4.Dataset(run_dir / "flood_maps.nc") as ds:
        assert ds["arrival_time"].coordinates.split() == ["wet_threshold"]
        assert ds["wet_threshold"].standard_name == "flood_water_thickness"
        assert float(ds["wet_threshold"][...]) == WET_M
        assert ds["max_depth"].cell_methods == "time: maximum"
        assert "time" in ds["max_depth"].coordinates.split()
        assert ds["time"].bounds == "time_bounds"
        assert list(ds["time_bounds"][:]) == [0.0, pytest.approx(END_S, abs=1.0)]
        assert json.loads(ds.scenario)["output"]["wet_threshold_m"] == WET_M


def test_times_are_dated_from_the_scenario_start(run_dir):
    """``start = 2024-01-15T07:00:00+01:00``: every NetCDF time decodes (cftime) to that
    instant, 06:00 UTC, plus the simulated seconds; gauges.csv has the same instants and
    run.json records the start."""
    import cftime

    with netCDF4.Dataset(run_dir / "snapshots.nc") as ds:
        t = ds["time"]
        assert t.units == "seconds since 2024-01-15 06:00:00"
        dates = cftime.num2date(t[:], t.units, t.calendar, only_use_cftime_datetimes=False)
        seconds = t[:]
    assert [(d.replace(tzinfo=UTC) - START_UTC).total_seconds() for d in dates] == \
        pytest.approx(list(seconds), abs=1e-5)
    assert seconds[0] == 0.0 and np.allclose(np.diff(seconds), SNAPSHOT_S, atol=0.5)
    with netCDF4.Dataset(run_dir / "flood_maps.nc") as ds:
        end = cftime.num2date(ds["time"][...], ds["time"].units, ds["time"].calendar,
                              only_use_cftime_datetimes=False)
    assert end.replace(tzinfo=UTC) == pytest.approx(START_UTC + timedelta(seconds=END_S),
                                                    abs=timedelta(seconds=1))
    with open(run_dir / "gauges.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert rows and list(rows[0])[-1] == "time_utc"
    for row in rows:
        instant = datetime.fromisoformat(row["time_utc"])
        assert instant - START_UTC == timedelta(seconds=float(row["time_s"]))
    manifest = json.loads((run_dir / "run.json").read_text())
    assert datetime.fromisoformat(manifest["start"]) == START_UTC


def _cf_tables(folder: Path) -> dict:
    """cfchecks' tables, offline: the standard names of compliance-checker's copy, and empty
    area-type and region tables (no variable uses area types or regions)."""
    table = Path(importlib.util.find_spec("compliance_checker").origin).parent / "data"
    for name, root in (("area.xml", "area_type_table"), ("region.xml",
                                                         "standardized_region_list")):
        (folder / name).write_text(f"<{root}><version_number>0</version_number>"
                                   f"<date>none</date></{root}>")
    return {"cfStandardNamesXML": str(table / "cf-standard-name-table.xml"),
            "cfAreaTypesXML": str(folder / "area.xml"),
            "cfRegionNamesXML": str(folder / "region.xml")}


@pytest.mark.parametrize("name", NETCDF_FILES)
def test_cf_checker_finds_no_error_and_no_warning(run_dir, name, tmp_path):
    try:
        from cfchecker.cfchecks import CFChecker
    except (ImportError, FileNotFoundError, OSError) as e:   # cfunits needs libudunits2
        pytest.skip(f"cfchecker (floodsph[cf], with libudunits2) not usable: {e}")
    if importlib.util.find_spec("compliance_checker") is None:
        pytest.skip("compliance-checker (floodsph[cf]) not installed: no standard name table")
    checker = CFChecker(version="1.8", silent=True, **_cf_tables(tmp_path))
    result = checker.checker(str(run_dir / name))
    found = {"global": result["global"], **result["variables"]}
    problems = {where: r["FATAL"] + r["ERROR"] + r["WARN"] for where, r in found.items()}
    assert not any(problems.values()), problems


KNOWN_CHECKER_WARNINGS = ("Boundary variable time_bounds specified by time should have at "
                          "least two dimensions",)
"""compliance-checker 6 wants 2-D bounds even for a scalar coordinate; CF 7.1 asks for one
dimension more than the coordinate, so the 1-D bounds of the scalar time are right."""


@pytest.mark.parametrize("name", NETCDF_FILES)
def test_compliance_checker_finds_no_failure(run_dir, name, tmp_path):
    pytest.importorskip("compliance_checker", reason="compliance-checker (floodsph[cf]) "
                                                     "not installed")
    from compliance_checker.runner import CheckSuite, ComplianceChecker

    CheckSuite.load_all_available_checkers()
    report = tmp_path / "report.json"
    ComplianceChecker.run_checker(str(run_dir / name), ["cf:1.8"], 0, "normal",
                                  output_filename=str(report), output_format="json")
    result = json.loads(report.read_text())["cf:1.8"]
    failed = {level: [m for r in result[level] if r["value"][0] < r["value"][1]
                      for m in r["msgs"]] for level in ("high_priorities", "medium_priorities")}
    assert failed["high_priorities"] == []
    assert [m for m in failed["medium_priorities"]
            if not m.startswith(KNOWN_CHECKER_WARNINGS)] == []


def test_map_names_and_metadata_match_the_geotiffs(run_dir):
    """Each map variable has the long name and units of its GeoTIFF."""
    import rasterio

    with netCDF4.Dataset(run_dir / "flood_maps.nc") as ds:
        for name in MAPS:
            with rasterio.open(run_dir / f"{name}.tif") as src:
                assert src.units[0] == ds[name].units
                assert src.tags(1)["long_name"] == ds[name].long_name
                np.testing.assert_array_equal(src.read(1).astype(np.float64),
                                              ds[name][:].filled(np.nan).astype(np.float64))
