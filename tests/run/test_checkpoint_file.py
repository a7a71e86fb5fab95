"""The checkpoint file (docs/run-folder.md, "Checkpoints and `--resume`"): named arrays any
numpy reads without pickle, holding the state of the step it was written at; a damaged file
or a pickled checkpoint of format 4 is refused with one message, and never unpickled."""

from __future__ import annotations

import hashlib
import json
import os
import pickle
import signal

import numpy as np
import pytest
from run_cases import write_dam_break

from floodsph.errors import InputError
from floodsph.run.pipeline import run_scenario
from floodsph.scenario.reader import load_scenario
from floodsph.simulation.schedules import IterationInterval


def stop_and_keep(step: int, kept: dict):
    """A callback that keeps the particles' positions and the clock at the first step >=
    ``step`` and sends SIGTERM to this process there (the checkpoint follows at that step)."""

    def callback(sim):
        if sim.model.steps >= step and not kept:
            p = sim.model.particles
            kept.update(x=p.x.copy(), y=p.y.copy(), t=sim.model.t, steps=sim.model.steps,
                        inflow_phase=sim.model.boundaries[1].phase)
            os.kill(os.getpid(), signal.SIGTERM)

    return callback, IterationInterval(1)


@pytest.fixture
def interrupted(valley_dem, tmp_path):
    """(scenario, run folder, kept state) of the dam break stopped at step 5."""
    scenario = load_scenario(write_dam_break(tmp_path, flux=True))
    kept: dict = {}
    out = tmp_path / "run"
    m = run_scenario(scenario, out, progress=False, callbacks=[stop_and_keep(5, kept)])
    assert m["status"] == "interrupted"
    return scenario, out, kept


def resume(scenario, out):
    return run_scenario(scenario, out, progress=False, resume=True)


def test_the_checkpoint_holds_the_state_of_its_step_as_named_arrays(interrupted):
    scenario, out, kept = interrupted
    path = out / "checkpoint" / "state.npz"
    assert not (out / "checkpoint" / "state.pkl").exists()
    with np.load(path, allow_pickle=False) as npz:
        assert int(npz["format"]) == 5
        assert int(npz["model.steps"]) == kept["steps"]
        assert float(npz["model.t"]) == kept["t"]
        assert np.array_equal(npz["model.particles.x"], kept["x"])
        assert np.array_equal(npz["model.particles.y"], kept["y"])
        assert int(npz["model.particles.n"]) == kept["x"].size
        text = str(npz["scenario"])
        assert json.loads(str(npz["scenario_sha256"])) == hashlib.sha256(
            text.encode()).hexdigest()
        assert json.loads(text)["numerics"]["refinement"] == "split+coalesce"
        # the open edges come first, then the inflow, each under its place
        assert json.loads(str(npz["model.boundary_kinds"])) == ["OpenEdges", "Inflow"]
        assert npz["model.boundaries.0.buffer.x"].ndim == 1
        assert float(npz["model.boundaries.1.phase"]) == kept["inflow_phase"]
        assert float(npz["model.boundaries.1.t"]) == kept["t"]
        assert npz["recorders.envelopes.max_depth"].shape == (20, 40)
        assert json.loads(str(npz["model.flux_lines.rows"])) != []


def test_a_damaged_checkpoint_is_refused_with_one_message(interrupted):
    scenario, out, _ = interrupted
    path = out / "checkpoint" / "state.npz"
    whole = path.read_bytes()
    path.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(InputError, match=r"state\.npz: the checkpoint cannot be read"):
        resume(scenario, out)
    flipped = bytearray(whole)
    flipped[len(whole) // 2] ^= 0xFF  # one byte of some array changed: its checksum fails
    path.write_bytes(bytes(flipped))
    with pytest.raises(InputError, match=r"state\.npz: the checkpoint cannot be read \(Bad "
                                         r"CRC-32"):
        resume(scenario, out)
    path.write_bytes(whole)
    with np.load(path, allow_pickle=False) as npz:
        arrays = {name: npz[name] for name in npz.files}
    changed = json.loads(str(arrays["scenario"]))
    changed["terrain"]["manning"] = 0.05
    np.savez(path, **{**arrays, "scenario": np.asarray(json.dumps(changed))})
    with pytest.raises(InputError, match=r"state\.npz: the scenario stored in the checkpoint "
                                         r"does not match its scenario_sha256"):
        resume(scenario, out)
    np.savez(path, **{name: a for name, a in arrays.items() if name != "model.particles.x"})
    with pytest.raises(InputError, match=r"state\.npz: the field model\.particles\.x is "
                                         r"missing"):
        resume(scenario, out)


class Trap:
    """Unpickling this creates the file ``marker``: proof that a pickle was read."""

    def __init__(self, marker):
        self.marker = str(marker)

    def __reduce__(self):
        return (open, (self.marker, "w"))


def test_a_pickled_checkpoint_of_format_4_is_refused_never_read(interrupted, tmp_path):
    scenario, out, _ = interrupted
    (out / "checkpoint" / "state.npz").unlink()
    marker = tmp_path / "unpickled"
    (out / "checkpoint" / "state.pkl").write_bytes(pickle.dumps(Trap(marker)))
    with pytest.raises(InputError, match=r"state\.pkl: a checkpoint of format 4 or before .*"
                                         r"reads format 5 only: run the scenario again with "
                                         r"--overwrite"):
        resume(scenario, out)
    with pytest.raises(InputError, match="already holds a checkpointed run"):
        run_scenario(scenario, out, progress=False)
    assert not marker.exists()
