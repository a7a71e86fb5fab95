"""Member folders before any run: the sampled scenario, a raster scaled by a factor, the
GeoTIFF maps the aggregation needs, and which folders count as completed."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest
from conftest import NX, NY, write_geotiff
from ensemble_cases import DAM_BREAK, ensemble_text, write_case

from floodsph.ensemble.members import build_members, completed_manifest, write_member
from floodsph.ensemble.sampling import draw_samples
from floodsph.ensemble.spec import load_ensemble
from floodsph.errors import InputError
from floodsph.scenario.reader import load_scenario

RASTER_FACTOR = """
[[ensemble.parameters]]
key = "terrain.manning"
distribution = "uniform"
low = 0.5
high = 2.0
mode = "factor"
"""


def members_of(path, out):
    spec = load_ensemble(path)
    base = load_scenario(spec.base)
    return build_members(spec, base, draw_samples(spec), out), draw_samples(spec)


@pytest.fixture
def raster_case(tmp_path):
    n = np.full((NY, NX), 0.04)
    n[0, :3] = -9999.0  # nodata
    write_geotiff(tmp_path / "n.tif", n)
    scenario = DAM_BREAK.replace("manning = 0.03", 'manning = "n.tif"')
    return write_case(tmp_path, ensemble_text(RASTER_FACTOR, members=3), scenario)


def test_a_factor_scales_the_raster_into_the_member_folder(raster_case, tmp_path):
    import rasterio

    members, samples = members_of(raster_case, tmp_path / "out")
    for member, (factor,) in zip(members, samples.rows, strict=True):
        write_member(member)
        scenario = tomllib.loads(member.scenario_path.read_text())
        target = member.folder / "terrain.manning.tif"
        assert scenario["terrain"]["manning"] == str(target)
        with rasterio.open(target) as src:
            scaled = src.read(1, masked=True)
        assert scaled.mask[0, :3].all() and not scaled.mask[1:].any()
        np.testing.assert_allclose(scaled[1:], 0.04 * factor, rtol=1e-6)
        assert load_scenario(member.scenario_path).terrain.manning == target


def test_a_raster_factor_must_be_positive(tmp_path):
    n = np.full((NY, NX), 0.04)
    write_geotiff(tmp_path / "n.tif", n)
    scenario = DAM_BREAK.replace("manning = 0.03", 'manning = "n.tif"')
    text = ensemble_text(RASTER_FACTOR.replace("low = 0.5", "low = -1.0"), members=8)
    with pytest.raises(InputError, match=r"terrain.manning = .*n.tif x -0\.\d+ \(member m000\d\)"
                                         r": a raster factor must be > 0"):
        members_of(write_case(tmp_path, text, scenario), tmp_path / "out")


def test_member_scenario_has_its_values_name_and_folder(tmp_path):
    path = write_case(tmp_path, ensemble_text(members=3))
    members, samples = members_of(path, tmp_path / "out")
    assert [m.id for m in members] == ["m0000", "m0001", "m0002"]
    for member, (level,) in zip(members, samples.rows, strict=True):
        scenario = tomllib.loads(member.scenario_text)
        assert scenario["initial_water"][0]["level_m"] == level
        assert scenario["scenario"]["name"] == f"dam-break-{member.id}"
        assert scenario["output"]["directory"] == str((tmp_path / "out").resolve() / "members"
                                                      / member.id)
        assert f"#   initial_water[0].level_m = {level!r}" in member.scenario_text


def test_members_always_write_geotiff_maps(tmp_path):
    scenario = DAM_BREAK + 'formats = ["netcdf"]\n'
    members, _ = members_of(write_case(tmp_path, ensemble_text(members=1), scenario),
                            tmp_path / "out")
    assert tomllib.loads(members[0].scenario_text)["output"]["formats"] == ["netcdf", "geotiff"]


def test_completed_means_a_completed_run_of_this_scenario(tmp_path):
    path = write_case(tmp_path, ensemble_text(members=2))
    members, _ = members_of(path, tmp_path / "out")
    member = members[0]
    write_member(member)
    run = {"status": "completed", "scenario": load_scenario(member.scenario_path).to_dict()}
    (member.folder / "run.json").write_text(json.dumps(run))
    assert completed_manifest(member) == run
    other = members[1]  # the same run.json beside another member's scenario
    write_member(other)
    (other.folder / "run.json").write_text(json.dumps(run))
    assert completed_manifest(other) is None
    (member.folder / "run.json").write_text(json.dumps({**run, "status": "failed"}))
    assert completed_manifest(member) is None


def test_the_sample_ensemble_builds_its_members(tmp_path):
    """data_samples/valley_breach/ensemble.toml: 32 valid members, the breach width a factor on
    the Froehlich (2008) width of the base's 2.3 Mm3 reservoir and 9 m breach."""
    from pathlib import Path

    from floodsph.breach.formulas import froehlich2008_average_width

    sample = Path(__file__).resolve().parents[2] / "data_samples" / "valley_breach"
    members, samples = members_of(sample / "ensemble.toml", tmp_path)
    assert len(members) == 32
    width = froehlich2008_average_width(2.3e6, 9.0, "overtopping")
    for member, (factor, time_factor, n) in zip(members, samples.rows, strict=True):
        scenario = tomllib.loads(member.scenario_text)
        breach = scenario["inflows"][0]["breach"]
        assert breach["average_width_m"] == pytest.approx(width * factor, rel=1e-12)
        assert breach["formation_time_s"] == pytest.approx(600.0 * time_factor, rel=1e-12)
        assert scenario["terrain"]["manning"] == n
