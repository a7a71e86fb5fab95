"""Inflows, sinks and open edges through ``run_scenario``: the run folder accounts for every
cubic metre (run.json volumes, mass_balance.csv) and keeps the breach hydrograph it used."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from conftest import CELL, NX, NY, X0, Y0

from floodsph.io.hydrograph import read_hydrograph
from floodsph.run.pipeline import run_scenario
from floodsph.scenario.reader import load_scenario

HEAD = f"""\
[scenario]
name = "inflow"
end_time_s = 60.0

[terrain]
dem = "dem.tif"
manning = 0.03
edges = "{{edges}}"

[[inflows]]
line = [[{X0 + 150}, {Y0 + 80}], [{X0 + 150}, {Y0 + 120}]]
direction = [1.0, 0.0]
{{source}}

[numerics]
particle_spacing_m = 5.0
refinement = "none"

[output]
resolution_m = 10.0
mass_balance_interval_s = 5.0
"""


def _run(write_scenario, tmp_path, source, edges="closed", extra=""):
    path = write_scenario(HEAD.format(edges=edges, source=source) + extra)
    manifest = run_scenario(load_scenario(path), tmp_path / "out", progress=False)
    return manifest, tmp_path / "out"


def test_hydrograph_inflow_volume_is_accounted_in_the_run_folder(write_scenario, tmp_path):
    (tmp_path / "q.csv").write_text("time_s,discharge_m3s\n0,0\n10,10\n30,10\n40,0\n")
    manifest, out = _run(write_scenario, tmp_path, 'hydrograph = "q.csv"')
    total = 0.5 * 10 * 10 + 20 * 10 + 0.5 * 10 * 10  # 300 m3
    assert manifest["status"] == "completed"
    assert manifest["volume_in_m3"] == pytest.approx(total, rel=1e-9)
    assert manifest["volume_domain_m3"] == pytest.approx(total, rel=1e-9)
    assert manifest["mass_error_rel"] < 1e-9
    (inflow,) = manifest["inflows"]
    assert inflow["volume_injected_m3"] == pytest.approx(inflow["volume_hydrograph_m3"])
    assert "inflows[0]" in inflow["name"]
    with open(out / "mass_balance.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    v_in = np.array([float(r["volume_in_m3"]) for r in rows])
    assert np.all(np.diff(v_in) >= 0.0) and v_in[-1] == pytest.approx(total)
    assert max(float(r["error_rel"]) for r in rows) < 1e-9
    assert json.loads((out / "run.json").read_text())["volume_in_m3"] == pytest.approx(total)


def test_parametric_breach_writes_the_hydrograph_it_used(write_scenario, tmp_path):
    from floodsph.breach import BreachParams, breach_hydrograph

    table = {"method": "froehlich2008", "reservoir_volume_m3": 2.0e4, "breach_height_m": 2.0,
             "breach_invert_m": 98.0}
    breach = "[inflows.breach]\n" + "".join(
        f"{key} = {value!r}\n".replace("'", '"') for key, value in table.items())
    manifest, out = _run(write_scenario, tmp_path, breach)
    assert manifest["breach_hydrographs"] == ["breach_hydrograph_0.csv"]
    written = read_hydrograph(out / "breach_hydrograph_0.csv")
    t, q, _ = breach_hydrograph(BreachParams.from_mapping(table, "inflows[0].breach"))
    np.testing.assert_allclose(written.t, t, rtol=1e-12)
    np.testing.assert_allclose(written.Q, q, rtol=1e-12, atol=1e-12)
    expected = float(written.volume(0.0, manifest["sim_time_s"]))
    assert manifest["inflows"][0]["volume_hydrograph_m3"] == pytest.approx(expected, rel=1e-9)
    # the injected volume follows the hydrograph within one buffer row (< 1 m3 here)
    assert abs(manifest["volume_in_m3"] - expected) < 1.0
    assert manifest["mass_error_rel"] < 1e-9


def test_sink_and_open_edges_count_what_leaves(write_scenario, tmp_path):
    (tmp_path / "q.csv").write_text("time_s,discharge_m3s\n0,80\n60,80\n")
    sink = f"""
[[sinks]]
polygon = [[{X0 + 220}, {Y0}], [{X0 + NX * CELL}, {Y0}], [{X0 + NX * CELL}, {Y0 + NY * CELL}],
           [{X0 + 220}, {Y0 + NY * CELL}]]
"""
    manifest, _ = _run(write_scenario, tmp_path, 'hydrograph = "q.csv"', edges="open",
                       extra=sink)
    assert manifest["volume_out_m3"] > 0.1 * manifest["volume_in_m3"]
    balance = manifest["volume_domain_m3"] + manifest["volume_out_m3"]
    assert balance == pytest.approx(manifest["volume_in_m3"], rel=1e-9)
    assert manifest["mass_error_rel"] < 1e-9


def test_crest_wall_passes_water_and_run_json_counts_it(write_scenario, tmp_path):
    """A crest wall flush with the floor (crest 100 m) across the valley 50 m east of the
    inflow: the water reaching it passes over, run.json counts the volume passed, and the mass
    balance still closes."""
    (tmp_path / "q.csv").write_text("time_s,discharge_m3s\n0,20\n60,20\n")
    wall = (f"\n[[walls]]\npolyline = [[{X0 + 200}, {Y0}], [{X0 + 200}, {Y0 + NY * CELL}]]\n"
            "crest_m = 100.0\n")
    manifest, _ = _run(write_scenario, tmp_path, 'hydrograph = "q.csv"', extra=wall)
    assert manifest["status"] == "completed"
    passed = manifest["walls_overtopped_m3"]
    assert list(passed) == ["walls[0]"]
    # the wall runs south to north: its right is the east, where the water goes
    assert passed["walls[0]"]["left_to_right_m3"] > 0.0
    assert manifest["volume_domain_m3"] == pytest.approx(manifest["volume_in_m3"], rel=1e-9)
    assert manifest["mass_error_rel"] < 1e-9


def test_check_refuses_a_breach_beyond_its_wall(write_scenario, tmp_path):
    """``floodsph check`` (the preflight) builds the crests as the run will: a breach centred
    beyond the end of its 200 m wall is refused before anything runs, naming the key."""
    from floodsph.errors import InputError
    from floodsph.run.preflight import preflight

    (tmp_path / "q.csv").write_text("time_s,discharge_m3s\n0,20\n60,20\n")
    wall = (f"\n[[walls]]\npolyline = [[{X0 + 200}, {Y0}], [{X0 + 200}, {Y0 + NY * CELL}]]\n"
            "crest_m = 101.0\n\n[walls.breach]\ncentre_m = 250.0\ninvert_m = 100.0\n"
            "bottom_width_m = 20.0\nformation_s = 60.0\n")
    path = write_scenario(HEAD.format(edges="closed", source='hydrograph = "q.csv"') + wall)
    with pytest.raises(InputError, match=r"walls\[0\]\.breach\.centre_m: 250 m is beyond the "
                                         r"end of the wall, which is 200 m long"):
        preflight(load_scenario(path), tmp_path / "out")
