"""The state of a run as named arrays (``floodsph.simulation.state_arrays``): every value comes
back exactly, through a real ``.npz`` file read without pickle, and a field missing, extra or of
the wrong kind is refused with its name."""

from __future__ import annotations

import math

import numpy as np
import pytest

from floodsph.boundaries import Inflow, OpenEdges, Sink, Weir
from floodsph.errors import InputError
from floodsph.simulation.state_arrays import capture, flatten, restore, unflatten


def through_file(tree, tmp_path):
    path = tmp_path / "state.npz"
    np.savez(path, **flatten(tree))
    with np.load(path, allow_pickle=False) as npz:
        return {name: npz[name] for name in npz.files}


def test_values_come_back_exactly_by_their_dotted_names(tmp_path):
    x = np.array([0.1, 1e-300, -np.inf, np.nan])
    tree = {
        "model": {"t": 0.1 + 0.2, "steps": 7, "fresh": True, "x": x,
                  "counters": {"splits": 3}, "sides": {}},
        "rows": [(1.5, "g1", np.float64(2.0) / 3.0, math.nan), (math.inf, "g2", 0.0, -1.0)],
        "t_last": None,
        "regime": "critical",
    }
    arrays = through_file(tree, tmp_path)
    assert {"model.t", "model.x", "model.counters.splits", "rows", "t_last"} <= set(arrays)
    assert arrays["model.x"].dtype == np.float64 and arrays["model.t"].ndim == 0
    back = unflatten(arrays, "state.npz")
    assert back["model"]["t"] == 0.1 + 0.2 and isinstance(back["model"]["t"], float)
    assert back["model"]["steps"] == 7 and back["model"]["fresh"] is True
    assert np.array_equal(back["model"]["x"], x, equal_nan=True)
    assert back["model"]["counters"] == {"splits": 3} and back["model"]["sides"] == {}
    assert back["rows"][0][2] == 2.0 / 3.0 and math.isnan(back["rows"][0][3])
    assert back["rows"][1][0] == math.inf
    assert back["t_last"] is None and back["regime"] == "critical"


class Gauge:
    STATE = ("level", "history")

    def __init__(self):
        self.level = np.zeros(3)
        self.history = {"n": 0}


def test_restore_names_the_field_missing_extra_or_of_the_wrong_kind():
    saved = Gauge()
    saved.level[:] = [1.0, 2.0, 3.0]
    saved.history["n"] = 4
    state = capture(saved)
    fresh = Gauge()
    restore(fresh, state, "model.boundaries.2", "ck.npz")
    assert np.array_equal(fresh.level, [1.0, 2.0, 3.0]) and fresh.history == {"n": 4}
    with pytest.raises(InputError, match=r"ck\.npz: the field model\.boundaries\.2\.level is "
                                         r"missing"):
        restore(Gauge(), {"history": {"n": 4}}, "model.boundaries.2", "ck.npz")
    with pytest.raises(InputError, match=r"the field model\.boundaries\.2\.speed is not one"):
        restore(Gauge(), {**state, "speed": 1.0}, "model.boundaries.2", "ck.npz")
    with pytest.raises(InputError, match=r"the field model\.boundaries\.2\.history\.n is "
                                         r"not a number"):
        restore(Gauge(), {**state, "history": {"n": "four"}}, "model.boundaries.2", "ck.npz")
    with pytest.raises(InputError, match=r"model\.boundaries\.2\.level is not a 1-d array of "
                                         r"float64"):
        restore(Gauge(), {**state, "level": np.zeros(3, dtype=np.int64)}, "model.boundaries.2",
                "ck.npz")


@pytest.mark.parametrize("boundary", [Inflow, OpenEdges, Sink, Weir])
def test_every_boundary_declares_its_state(boundary):
    """A boundary without STATE could not be checkpointed (``Boundary.STATE``)."""
    assert isinstance(boundary.STATE, tuple)
    assert all(isinstance(name, str) and not name.startswith("_") for name in boundary.STATE)
