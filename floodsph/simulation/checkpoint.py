"""Checkpoints: the whole state of a run, saved so that it can continue as if never stopped.

A checkpoint (``docs/run-folder.md``, "Checkpoints and ``--resume``") holds:

* the model: particles, neighbour and wall lists, boundary and inflow state, refinement
  state, the clock and the counters (the terrain is not stored: it is read again from the
  scenario's DEM, and must be the same);
* the recorders: the envelope maps, the gauge rows, the number of snapshot frames;
* the mass-balance rows and the simulation loop's own state (when each callback last ran
  and is next due);
* the resolved scenario, the floodsph version and the thread count it was written with.

It is one file, ``checkpoint/state.pkl`` in the run folder, a Python pickle (protocol 5)
written under a temporary name and renamed over the previous one, so the previous checkpoint
stays until the new one is complete. A pickle runs code when it is read: only resume from a
run folder you trust, as with any file your runs wrote. A checkpoint is read only by the same
floodsph version that wrote it.

Resuming from the same state, with the same thread count, repeats the same arithmetic in the
same order (the neighbour lists are part of the state), so the resumed run's maps, gauges and
mass balance equal the uninterrupted run's bit for bit.
"""

from __future__ import annotations

import os
import pickle
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from floodsph._version import __version__
from floodsph.errors import InputError
from floodsph.io.atomic_files import atomic_path
from floodsph.io.run_names import CHECKPOINT_DIR

STATE_NAME = "state.pkl"
FORMAT = 4
"""Checkpoint layout; 2 adds the particles' velocity gradient, 3 their level offset and seeded
level, 4 their flag of still water held by its banks (``floodsph.model.particles``)."""
_TERRAIN = "terrain"


@dataclass
class Checkpoint:
    """The state of a run at one step (module docstring).

    ``scenario``: the resolved scenario (``Scenario.to_dict``); ``threads``: numba threads;
    ``model``: the FloodModel; ``simulation``: ``Simulation.state()``; ``recorders``:
    ``Recorders.state()``; ``mass_rows``: the mass-balance rows; ``resumed_from``: the
    checkpoint times the run had been resumed from; ``wall_time_s``: wall time spent so far.
    """

    scenario: dict
    threads: int
    model: Any
    simulation: dict
    recorders: dict
    mass_rows: list
    resumed_from: list[float] = field(default_factory=list)
    wall_time_s: float = 0.0
    floodsph_version: str = __version__
    format: int = FORMAT

    @property
    def t(self) -> float:
        """Simulated time of the checkpoint [s]."""
        return float(self.model.t)


class _Pickler(pickle.Pickler):
    """Stores the terrain as a reference, to be given back by :class:`_Unpickler`."""

    def __init__(self, file, terrain):
        super().__init__(file, protocol=5)
        self._terrain = terrain

    def persistent_id(self, obj):
        return _TERRAIN if obj is self._terrain else None


class _Unpickler(pickle.Unpickler):
    def __init__(self, file, terrain):
        super().__init__(file)
        self._terrain = terrain

    def persistent_load(self, pid):
        if pid != _TERRAIN:
            raise pickle.UnpicklingError(f"unknown reference {pid!r}")
        return self._terrain


def save_checkpoint(folder: Path, checkpoint: Checkpoint, terrain) -> Path:
    """Write ``checkpoint`` to ``folder/checkpoint/state.pkl`` atomically; return its path."""
    directory = Path(folder) / CHECKPOINT_DIR
    directory.mkdir(exist_ok=True)
    target = directory / STATE_NAME
    with atomic_path(target) as tmp, open(tmp, "wb") as f:
        _Pickler(f, terrain).dump(checkpoint)
        f.flush()
        os.fsync(f.fileno())
    return target


def load_checkpoint(directory: Path, terrain) -> Checkpoint:
    """Read the checkpoint in ``directory`` (a ``checkpoint/`` folder) onto ``terrain``."""
    path = Path(directory) / STATE_NAME
    try:
        with open(path, "rb") as f:
            checkpoint = _Unpickler(f, terrain).load()
    except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError) as exc:
        raise InputError(f"{path}: the checkpoint cannot be read ({exc})") from None
    if not isinstance(checkpoint, Checkpoint):
        raise InputError(f"{path}: not a floodsph checkpoint")
    if checkpoint.format != FORMAT:
        raise InputError(f"{path}: a checkpoint of format {checkpoint.format}; this floodsph "
                         f"reads format {FORMAT} only: run the scenario again with --overwrite")
    if checkpoint.floodsph_version != __version__:
        raise InputError(f"{path}: written by floodsph {checkpoint.floodsph_version}, this is "
                         f"{__version__}; resume it with that version")
    return checkpoint


def scenario_difference(saved: dict, current: dict, path: str = "") -> str | None:
    """The first key path at which two resolved scenarios differ, ignoring
    ``scenario.end_time_s`` (a resumed run may go further); None when they agree."""
    if isinstance(saved, dict) and isinstance(current, dict):
        for key in sorted(set(saved) | set(current)):
            where = f"{path}.{key}" if path else key
            if where == "scenario.end_time_s":
                continue
            if key not in saved or key not in current:
                return where
            found = scenario_difference(saved[key], current[key], where)
            if found:
                return found
        return None
    return None if saved == current else path
