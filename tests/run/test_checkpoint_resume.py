"""Checkpoint and resume (docs/run-folder.md, "Checkpoints and `--resume`").

A run stopped by SIGTERM and resumed, any number of times, writes the same maps, gauges and
mass balance as the run that was never stopped: bit for bit, with refinement, inflows, open
edges and either time stepping. The stop is a real signal sent by the process to itself from
a callback at a chosen step, so the handler, the checkpoint and the resume are the ones a
batch scheduler's SIGTERM meets.
"""

from __future__ import annotations

import csv
import json
import os
import signal

import numpy as np
import pytest
import rasterio
import xarray as xr
from run_cases import write_dam_break

from floodsph.output.envelopes import MAPS
from floodsph.run.pipeline import run_scenario
from floodsph.scenario.reader import load_scenario
from floodsph.simulation.schedules import IterationInterval


def sigterm_at(step: int | None):
    """A callback that sends SIGTERM to this process once, at the first step >= ``step``."""
    sent = []

    def callback(sim):
        if step is not None and sim.model.steps >= step and not sent:
            sent.append(sim.model.steps)
            os.kill(os.getpid(), signal.SIGTERM)

    return callback, IterationInterval(1)


@pytest.fixture
def dam_break(valley_dem, tmp_path):
    def make(stepping: str = "global", end_time: float = 40.0, flux: bool = False):
        return load_scenario(write_dam_break(tmp_path, stepping, end_time, flux))

    return make


def run(scenario, out, stop_at=None, resume=False):
    return run_scenario(scenario, out, progress=False, callbacks=[sigterm_at(stop_at)],
                        resume=resume)


def assert_same_outputs(a, b):
    for name in MAPS:
        with rasterio.open(a / f"{name}.tif") as x, rasterio.open(b / f"{name}.tif") as y:
            assert np.array_equal(x.read(1), y.read(1), equal_nan=True), name
    for table in ("gauges.csv", "mass_balance.csv", "flux.csv"):
        assert (a / table).exists() == (b / table).exists(), table
        if (a / table).exists():
            assert (a / table).read_text() == (b / table).read_text(), table
    with xr.open_dataset(a / "flood_maps.nc") as x, xr.open_dataset(b / "flood_maps.nc") as y:
        xr.testing.assert_identical(x.drop_attrs(), y.drop_attrs())
    with xr.open_dataset(a / "snapshots.nc") as x, xr.open_dataset(b / "snapshots.nc") as y:
        xr.testing.assert_identical(x.drop_attrs(), y.drop_attrs())


@pytest.mark.parametrize("stepping", ["global", "local"])
def test_a_run_stopped_twice_and_resumed_equals_the_uninterrupted_run(dam_break, tmp_path,
                                                                        stepping):
    scenario = dam_break(stepping, flux=True)
    whole = run(scenario, tmp_path / "whole")
    assert whole["status"] == "completed"
    assert whole["splits"] > 0 and whole["merges"] > 0  # refinement is exercised
    assert whole["volume_in_m3"] > 0 and whole["volume_out_m3"] > 0  # inflow, open edges

    first = run(scenario, tmp_path / "parts", stop_at=9)
    assert first["status"] == "interrupted" and "SIGTERM" in first["error"]
    assert 0 < first["steps"] < whole["steps"]
    assert not (tmp_path / "parts" / "max_depth.tif").exists()
    on_disk = json.loads((tmp_path / "parts" / "run.json").read_text())
    assert on_disk["status"] == "interrupted"
    assert on_disk["checkpoint_time_s"] == first["sim_time_s"]

    second = run(scenario, tmp_path / "parts", stop_at=first["steps"] + 30, resume=True)
    assert second["status"] == "interrupted" and second["steps"] > first["steps"]
    last = run(scenario, tmp_path / "parts", resume=True)
    assert last["status"] == "completed"
    assert last["resumed_from"] == [first["sim_time_s"], second["sim_time_s"]]
    for key in ("steps", "splits", "merges", "particles_final", "volume_in_m3",
                "mass_error_rel", "flux_lines", "volume_out_sides_m3"):
        assert last[key] == whole[key], key
    assert whole["flux_lines"][0]["volume_net_m3"] > 0  # water crossed the floor line
    assert (tmp_path / "whole" / "flux.csv").exists()
    out = (sum(whole["volume_out_sinks_m3"]) + sum(whole["volume_out_sides_m3"].values())
           + whole["volume_out_other_m3"])
    assert set(whole["volume_out_sides_m3"]) == {"west", "east", "south", "north"}
    assert out == pytest.approx(whole["volume_out_m3"], rel=1e-12)
    assert_same_outputs(tmp_path / "whole", tmp_path / "parts")


def test_mass_balance_rows_written_after_the_last_checkpoint_are_not_repeated(dam_break,
                                                                               tmp_path):
    """A run killed (no checkpoint at the kill) resumes from its last scheduled checkpoint:
    the rows after it are recomputed once, not appended twice."""
    scenario = dam_break()
    out = tmp_path / "run"
    first = run(scenario, out, stop_at=10**9)  # completes; its last checkpoint is at 40 s
    assert first["status"] == "completed"
    longer = dam_break(end_time=50.0)
    extended = run(longer, out, resume=True)
    assert extended["status"] == "completed" and extended["sim_time_s"] == pytest.approx(50.0)
    with open(out / "mass_balance.csv", newline="") as f:
        times = [float(r["time_s"]) for r in csv.DictReader(f)]
    assert times == sorted(set(times))
    assert times[0] == 0.0 and times[-1] == pytest.approx(50.0)
    assert extended["resumed_from"] == [pytest.approx(40.0)]


def test_resume_refuses_a_changed_scenario_and_a_folder_without_checkpoint(dam_break,
                                                                          tmp_path):
    from floodsph.errors import InputError

    scenario = dam_break()
    with pytest.raises(InputError, match="no run folder to resume"):
        run(scenario, tmp_path / "nothing", resume=True)
    out = tmp_path / "run"
    assert run(scenario, out, stop_at=5)["status"] == "interrupted"
    text = scenario.path.read_text().replace("manning = 0.03", "manning = 0.04")
    path = scenario.path.with_name("changed.toml")
    path.write_text(text)
    changed = load_scenario(path)
    with pytest.raises(InputError, match=r"terrain\.manning differs"):
        run(changed, out, resume=True)
    # Nothing was touched by the refusal: the interrupted run resumes as it was.
    assert json.loads((out / "run.json").read_text())["status"] == "interrupted"
    assert run(scenario, out, resume=True)["status"] == "completed"


def test_resume_refuses_a_checkpoint_of_another_format_and_leaves_the_run(dam_break, tmp_path,
                                                                           monkeypatch):
    """A checkpoint written by a floodsph whose particles carried other fields (its format
    differs) is refused with one message naming the file and both formats; the folder keeps
    its interrupted run."""
    from floodsph.errors import InputError
    from floodsph.simulation import checkpoint

    scenario = dam_break()
    out = tmp_path / "run"
    assert run(scenario, out, stop_at=5)["status"] == "interrupted"
    saved = (out / "checkpoint" / "state.npz").read_bytes()
    monkeypatch.setattr(checkpoint, "FORMAT", checkpoint.FORMAT + 1)
    with pytest.raises(InputError, match=rf"state\.npz: a checkpoint of format "
                                         rf"{checkpoint.FORMAT - 1}; this floodsph reads "
                                         rf"format {checkpoint.FORMAT} only"):
        run(scenario, out, resume=True)
    assert json.loads((out / "run.json").read_text())["status"] == "interrupted"
    assert (out / "checkpoint" / "state.npz").read_bytes() == saved


CREST = """
[scenario]
name = "crest"
end_time_s = 30.0

[terrain]
dem = "dem.tif"
manning = 0.03
edges = "closed"

[[initial_water]]
level_m = 101.0
polygon = [[{x0}, {y0}], [{x1}, {y0}], [{x1}, {y1}], [{x0}, {y1}]]

[[walls]]
polyline = [[{x1}, {y0}], [{x1}, {y1}]]
crest_m = 101.5

[walls.breach]
centre_m = 100.0
bottom_width_m = 60.0
invert_m = 100.0
start_s = 1.0
formation_s = 4.0

[[sinks]]
polygon = [[{xs}, {y0}], [{xe}, {y0}], [{xe}, {y1}], [{xs}, {y1}]]

[numerics]
particle_spacing_m = 10.0
momentum = "balanced"

[output]
resolution_m = 10.0
mass_balance_interval_s = 2.0
checkpoint_interval_s = 5.0
"""
"""A reservoir behind a crest wall whose breach opens at 1 s, a sink 30 m downstream, the
balanced momentum: the state of a weir, a breach, a sink and of still water held by its
banks goes through the checkpoint."""


def test_a_breached_crest_wall_and_a_sink_resume_bit_for_bit(valley_dem, tmp_path):
    from conftest import CELL, NX, NY, X0, Y0

    path = tmp_path / "crest.toml"
    path.write_text(CREST.format(x0=X0, y0=Y0, x1=X0 + 100, y1=Y0 + NY * CELL, xs=X0 + 130,
                                 xe=X0 + NX * CELL), encoding="utf-8")
    scenario = load_scenario(path)
    whole = run(scenario, tmp_path / "whole")
    assert whole["status"] == "completed"
    assert whole["walls_overtopped_m3"]["walls[0]"]["left_to_right_m3"] > 0.0
    assert whole["volume_out_sinks_m3"][0] > 0.0
    assert run(scenario, tmp_path / "parts", stop_at=9)["status"] == "interrupted"
    last = run(scenario, tmp_path / "parts", resume=True)
    assert last["status"] == "completed"
    for key in ("steps", "splits", "merges", "particles_final", "walls_overtopped_m3",
                "volume_out_sinks_m3", "mass_error_rel"):
        assert last[key] == whole[key], key
    for name in MAPS:
        with (rasterio.open(tmp_path / "whole" / f"{name}.tif") as x,
              rasterio.open(tmp_path / "parts" / f"{name}.tif") as y):
            assert np.array_equal(x.read(1), y.read(1), equal_nan=True), name
    assert ((tmp_path / "whole" / "mass_balance.csv").read_text()
            == (tmp_path / "parts" / "mass_balance.csv").read_text())
