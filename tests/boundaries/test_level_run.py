"""``[[level_boundaries]]`` in a run: the keys refused with the key named, the volumes that
crossed the boundary in run.json adding up to the balance, and a run stopped and resumed
equal to the run that never stopped (the boundary's buffer and counters are checkpointed
with the model)."""

from __future__ import annotations

import os
import signal

import pytest
from conftest import BASE_SCENARIO, CELL, NY, X0, Y0

from floodsph.errors import InputError
from floodsph.inputs.prepare import prepare_inputs
from floodsph.run.pipeline import run_scenario
from floodsph.scenario.reader import load_scenario
from floodsph.simulation.schedules import IterationInterval

SEA = """
[[level_boundaries]]
name = "sea"
side = "west"
file = "tide.csv"
"""

TIDE = "time_s,level_m\n0,100.0\n20,100.6\n40,99.2\n"
"""At the reservoir's west side (bed 98 m, water at 100 m): the sea rises 0.6 m, spilling
onto the valley floor (100 m), then falls 0.8 m below the reservoir's level."""


def _scenario(write_scenario, tmp_path, extra: str = SEA, head: str = BASE_SCENARIO):
    (tmp_path / "tide.csv").write_text(TIDE)
    text = head.replace("end_time_s = 20.0", "end_time_s = 60.0").replace(
        "mass_balance_interval_s = 5.0", "mass_balance_interval_s = 5.0\n"
                                         "checkpoint_interval_s = 10.0")
    return write_scenario(text + extra)


@pytest.mark.parametrize("extra, match", [
    ('side = "up"\nlevel_m = 1.0', r"level_boundaries\[0\]\.side: unknown side 'up'"),
    ('side = "east"', r"level_boundaries\[0\]: expected exactly one of level_m .* or file"),
    ('side = "east"\nline = [[0, 0], [0, 10]]\nlevel_m = 1.0',
     r"level_boundaries\[0\]: expected exactly one of side .* or line"),
    ('side = "east"\nlevel_m = 1.0\ndirection = [1, 0]',
     r"level_boundaries\[0\]\.direction: only applies with line"),
])
def test_level_boundary_keys_are_refused_with_the_key_named(write_scenario, tmp_path, extra,
                                                            match):
    path = write_scenario(BASE_SCENARIO + f'\n[[level_boundaries]]\nname = "sea"\n{extra}\n')
    with pytest.raises(InputError, match=match):
        load_scenario(path)


def test_the_resolved_scenario_keeps_the_level_boundaries(write_scenario, tmp_path):
    from floodsph.scenario.writer import write_resolved

    line = (f'\n[[level_boundaries]]\nname = "river"\nline = [[{X0 + 300}, {Y0}], '
            f'[{X0 + 300}, {Y0 + 50}]]\ndirection = [-1.0, 0.0]\nlevel_m = 100.2\n')
    scenario = load_scenario(_scenario(write_scenario, tmp_path, SEA + line))
    (tmp_path / "copy").mkdir()
    write_resolved(scenario, tmp_path / "copy" / "resolved.toml")
    again = load_scenario(tmp_path / "copy" / "resolved.toml")
    assert again.level_boundaries == scenario.level_boundaries
    assert again.level_boundaries[1].line == ((X0 + 300, Y0), (X0 + 300, Y0 + 50))
    assert scenario.level_boundaries[0].file == tmp_path / "tide.csv"


def test_a_side_both_closed_and_a_level_boundary_is_refused(write_scenario):
    head = BASE_SCENARIO.replace('edges = "closed"', 'edges = "open"\nclosed_sides = ["east"]')
    path = write_scenario(head + '\n[[level_boundaries]]\nname = "sea"\nside = "east"\n'
                                 'level_m = 100.0\n')
    with pytest.raises(InputError, match=r"level_boundaries\[0\]\.side: 'east' is listed in "
                                         r"terrain\.closed_sides too"):
        load_scenario(path)


def test_a_bad_level_file_and_a_line_off_the_dem_are_refused_before_the_run(write_scenario,
                                                                           tmp_path):
    path = _scenario(write_scenario, tmp_path)
    (tmp_path / "tide.csv").write_text("time_s,level_m\n0,100\n20,100.5\n15,100.2\n")
    with pytest.raises(InputError, match=r"level_boundaries\[0\]\.file: .*tide\.csv, line 4: "
                                         r"time_s = 15 does not follow 20"):
        prepare_inputs(load_scenario(path))
    off = (f'\n[[level_boundaries]]\nname = "river"\nline = [[{X0 + 300}, {Y0 + 100}], '
           f'[{X0 + 300}, {Y0 + NY * CELL + 50}]]\nlevel_m = 100.2\n')
    with pytest.raises(InputError, match=r"level_boundaries\[0\]\.line: the point .* lies off "
                                         r"the DEM"):
        prepare_inputs(load_scenario(write_scenario(BASE_SCENARIO + off)))


def _sigterm_at(step: int | None):
    """A callback sending SIGTERM to this process once, at the first step >= ``step``."""
    sent = []

    def callback(sim):
        if step is not None and sim.model.steps >= step and not sent:
            sent.append(step)
            os.kill(os.getpid(), signal.SIGTERM)

    return callback, IterationInterval(1)


def _run(path, out, stop_at=None, resume=False):
    return run_scenario(load_scenario(path), out, progress=False,
                        callbacks=[_sigterm_at(stop_at)], resume=resume)


def test_run_json_counts_the_sea_and_a_resumed_run_equals_the_whole(write_scenario, tmp_path):
    """The sea rises and falls at the reservoir's west side: water enters and leaves across
    it; run.json's level volumes close the balance with the initial
    reservoir (40 000 m3), and a run stopped by SIGTERM and resumed ends the same."""
    path = _scenario(write_scenario, tmp_path)
    whole = _run(path, tmp_path / "whole")
    assert whole["status"] == "completed"
    sea = whole["level_boundaries"]["sea"]
    assert sea["volume_in_m3"] > 500.0 and sea["volume_out_m3"] > 100.0
    assert sea["level_m"] == pytest.approx(99.2)
    assert whole["volume_in_m3"] == pytest.approx(sea["volume_in_m3"], rel=1e-12)
    assert whole["volume_out_levels_m3"] == {"sea": sea["volume_out_m3"]}
    out = (sum(whole["volume_out_sinks_m3"]) + sum(whole["volume_out_sides_m3"].values())
           + sum(whole["volume_out_levels_m3"].values()) + whole["volume_out_other_m3"])
    assert out == pytest.approx(whole["volume_out_m3"], rel=1e-12)
    initial = 40_000.0  # the reservoir (conftest)
    assert whole["volume_domain_m3"] == pytest.approx(
        initial + whole["volume_in_m3"] - whole["volume_out_m3"], rel=1e-9)

    first = _run(path, tmp_path / "parts", stop_at=whole["steps"] // 2)
    assert first["status"] == "interrupted"
    last = _run(path, tmp_path / "parts", resume=True)
    assert last["status"] == "completed" and last["resumed_from"]
    for key in ("steps", "volume_in_m3", "volume_out_m3", "volume_domain_m3",
                "level_boundaries"):
        assert last[key] == whole[key], key
