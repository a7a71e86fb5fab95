"""``workflows/compare_breach_scenarios.py`` on the shipped valley sample (2 s of flow, 20 m
particles): the base compared with itself has CSI 1 and a zero difference map; a Manning
variant starts from the same water; a reservoir 1 m higher starts with more water over a
larger area; no water leaves and the budget closes. Its breach variants (a base with a
parametric breach) scale the Froehlich (2008) width and formation time.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import BASE_SCENARIO, CELL, NX, NY, X0, Y0, load_script, write_geotiff

REPO = Path(__file__).resolve().parents[2]
study = load_script("compare_breach_scenarios",
                    REPO / "workflows" / "compare_breach_scenarios.py")


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))



BREACH_SCENARIO = f"""\
[scenario]
name = "breach-study"
end_time_s = 60.0

[terrain]
dem = "dem.tif"
manning = 0.03

[[initial_water]]
level_m = 99.0
polygon = [[{X0}, {Y0}], [{X0 + 50}, {Y0}], [{X0 + 50}, {Y0 + NY * CELL}], [{X0}, {Y0 + NY * CELL}]]

[[initial_water]]
level_m = 100.0
polygon = [[{X0 + 300}, {Y0}], [{X0 + NX * CELL}, {Y0}], [{X0 + NX * CELL}, {Y0 + NY * CELL}],
           [{X0 + 300}, {Y0 + NY * CELL}]]

[[inflows]]
line = [[{X0 + 150}, {Y0 + 20}], [{X0 + 150}, {Y0 + 180}]]

[inflows.breach]
reservoir_volume_m3 = 2.0e6
breach_height_m = 12.0
mode = "overtopping"
"""


def test_breach_variants_scale_froehlich_width_and_time(tmp_path, write_scenario):
    from floodsph.scenario.reader import load_scenario

    base = study.base_data(write_scenario(BREACH_SCENARIO))
    variants = study.make_variants(base, tmp_path / "inputs", manning_factors=(0.8,),
                                   level_deltas=(1.0,), breach_factors=(0.5, 1.5))
    loaded = {v.name: load_scenario(study.write_variant(v, tmp_path / "sc", tmp_path / "runs",
                                                        "breach-study")) for v in variants}
    assert list(loaded) == ["base", "manning_x0.8", "level_+1m", "breach_width_x0.5",
                            "breach_width_x1.5", "formation_time_x0.5", "formation_time_x1.5"]
    # Froehlich (2008): B_avg = 0.27 k0 V^0.32 h_b^0.04 (k0 = 1.3, overtopping) and
    # t_f = 63.2 sqrt(V / (g h_b^2)).
    width = 0.27 * 1.3 * 2.0e6 ** 0.32 * 12.0 ** 0.04
    t_f = 63.2 * math.sqrt(2.0e6 / (9.81 * 12.0 ** 2))
    for factor in (0.5, 1.5):
        w = loaded[f"breach_width_x{factor:g}"].inflows[0].breach
        t = loaded[f"formation_time_x{factor:g}"].inflows[0].breach
        assert w.average_width_m == pytest.approx(factor * width, rel=1e-12)
        assert w.formation_time_s is None
        assert t.formation_time_s == pytest.approx(factor * t_f, rel=1e-12)
    assert loaded["manning_x0.8"].terrain.manning == pytest.approx(0.024, rel=1e-12)
    # The level variant raises the reservoir (the higher body) only, not the tail water.
    levels = [w.level_m for w in loaded["level_+1m"].initial_water]
    assert levels == [99.0, 101.0]
    assert [w.level_m for w in loaded["base"].initial_water] == [99.0, 100.0]
    assert len({sc.output_directory for sc in loaded.values()}) == len(loaded)


def test_manning_raster_variant_is_the_raster_scaled(tmp_path, write_scenario):
    import rasterio

    from floodsph.scenario.reader import load_scenario

    n = np.full((NY, NX), 0.03)
    n[:, NX // 2:] = 0.06
    write_geotiff(tmp_path / "n.tif", n)
    base = study.base_data(write_scenario(BASE_SCENARIO.replace("manning = 0.03",
                                                                'manning = "n.tif"')))
    variants = study.make_variants(base, tmp_path / "inputs", manning_factors=(1.2,),
                                   level_deltas=())
    assert [v.name for v in variants] == ["base", "manning_x1.2"]
    path = study.write_variant(variants[1], tmp_path / "sc", tmp_path / "runs", "valley")
    with rasterio.open(load_scenario(path).terrain.manning) as src:
        scaled = src.read(1)
    assert scaled == pytest.approx(1.2 * n.astype(np.float32), rel=1e-6)


@pytest.fixture(scope="module")
def valley_study(tmp_path_factory):
    out = tmp_path_factory.mktemp("study")
    rows = study.run_study(study.DEFAULT_BASE, out, end_time=2.0, spacing=20.0,
                           manning_factors=(0.8,), level_deltas=(1.0,))
    return out, {r["variant"]: r for r in rows}


def test_study_base_against_itself_is_perfect(valley_study):
    import rasterio

    out, rows = valley_study
    base = rows["base"]
    assert base["csi"] == 1.0 and base["hit_rate"] == 1.0 and base["false_alarm_ratio"] == 0.0
    assert base["area_change_km2"] == 0.0 and base["depth_rmse_m"] == 0.0
    assert base["flooded_area_km2"] > 0.2  # the 0.29 km2 lake (sample README)
    with rasterio.open(out / "differences" / "base" / "difference.tif") as src:
        assert src.crs.to_epsg() == 32632
        diff = src.read(1)
    finite = diff[np.isfinite(diff)]
    assert finite.size * 1e-4 == pytest.approx(base["flooded_area_km2"], rel=0.05)
    assert np.all(finite == 0.0)
    arrivals = [r for r in _rows(out / "gauge_arrivals.csv") if r["variant"] == "base"]
    assert [r["gauge"] for r in arrivals] == ["G1", "G2", "G3", "G4", "G5"]
    assert all(r["change_s"] in ("0", "nan") for r in arrivals)


def test_study_variants_physically_ordered(valley_study):
    out, rows = valley_study
    base, manning, level = rows["base"], rows["manning_x0.8"], rows["level_+1m"]
    assert manning["value"] == "0.028"
    assert manning["volume_initial_m3"] == base["volume_initial_m3"]
    assert manning["particles_initial"] == base["particles_initial"]
    assert 0.9 < manning["csi"] <= 1.0
    # A lake 1 m higher: at least the base lake area times 1 m more water, over more area.
    extra = level["volume_initial_m3"] - base["volume_initial_m3"]
    assert extra > 0.9 * base["flooded_area_km2"] * 1e6 * 1.0
    assert level["flooded_area_km2"] > base["flooded_area_km2"]
    assert level["area_change_km2"] == pytest.approx(
        level["flooded_area_km2"] - base["flooded_area_km2"], abs=1e-12)
    assert level["depth_bias_m"] == pytest.approx(1.0, abs=0.2)
    for r in rows.values():
        assert r["volume_out_m3"] == 0.0  # the open edge is 2 km away
        assert r["mass_error_rel"] < 1e-9
    table = _rows(out / "summary.csv")
    assert tuple(table[0]) == study.SUMMARY_COLUMNS
    assert [r["variant"] for r in table] == ["base", "manning_x0.8", "level_+1m"]
    md = (out / "summary.md").read_text().splitlines()
    assert sum(line.startswith("| level_+1m |") for line in md) == 1
