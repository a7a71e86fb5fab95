"""Checkpoints: the state of a run as named arrays, so that it can continue as if never stopped.

A checkpoint (``docs/run-folder.md``, "Checkpoints and ``--resume``") is one file,
``checkpoint/state.npz`` in the run folder: a numpy ``.npz`` archive of arrays named by dotted
paths (``floodsph.simulation.state_arrays``), written under a temporary name and renamed over
the previous one, so the previous checkpoint stays until the new one is complete. It holds

* ``format`` (:data:`FORMAT`), ``floodsph_version``, ``threads`` (numba threads),
  ``wall_time_s`` (wall time spent so far) and ``resumed_from`` (the checkpoint times the
  run had been resumed from);
* ``scenario``: the resolved scenario as canonical JSON (:func:`canonical_json`), and
  ``scenario_sha256``, the SHA-256 of that text;
* ``model.*``: the model's state (``floodsph.simulation.model_state``): particles, neighbour
  and wall lists, boundary and inflow state, refinement state, flux lines, the clock and the
  counters. The terrain, walls and boundaries themselves are not stored: a resumed run makes
  them again from the scenario and its inputs, which must be the same;
* ``recorders.*``: the envelope maps, the gauge rows, the number of snapshot frames;
* ``simulation.*``: the simulation loop's own state (when each callback last ran and is next
  due); ``mass_rows``: the mass-balance rows.

It is read with ``numpy.load(..., allow_pickle=False)``: reading it runs no code, and any
program that reads ``.npz`` files can read it. A checkpoint is read only by the same floodsph
version that wrote it; the pickled checkpoints of format 4 and before (``state.pkl``) are
refused, never read.

Resuming from the same state, with the same thread count, repeats the same arithmetic in the
same order (the neighbour lists are part of the state), so the resumed run's maps, gauges and
mass balance equal the uninterrupted run's bit for bit.
"""

from __future__ import annotations

import hashlib
import json
import os
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

import numpy as np

from floodsph._version import __version__
from floodsph.errors import InputError
from floodsph.io.atomic_files import atomic_path
from floodsph.io.run_names import CHECKPOINT_DIR, CHECKPOINT_NAME, PICKLED_CHECKPOINT_NAME
from floodsph.simulation.state_arrays import expect_fields, flatten, unflatten

FORMAT = 5
"""Checkpoint layout; 2 adds the particles' velocity gradient, 3 their level offset and seeded
level, 4 their flag of still water held by its banks (``floodsph.model.particles``), 5 is
named arrays in ``state.npz`` instead of a pickle in ``state.pkl``."""
SCENARIO = "scenario"
"""The name of the scenario's canonical JSON text in the file."""
FIELDS = ("format", "floodsph_version", "scenario_sha256", SCENARIO, "threads", "wall_time_s",
          "resumed_from", "model", "simulation", "recorders", "mass_rows")
"""The top-level fields of a checkpoint (module docstring)."""


@dataclass
class Checkpoint:
    """The state of a run at one step (module docstring).

    ``scenario``: the resolved scenario (``Scenario.to_dict``, as JSON reads it back:
    :func:`plain_scenario`); ``threads``: numba threads; ``model``:
    ``floodsph.simulation.model_state.model_state``; ``simulation``: ``Simulation.state()``;
    ``recorders``: ``Recorders.state()``; ``mass_rows``: the mass-balance rows;
    ``resumed_from``: the checkpoint times the run had been resumed from; ``wall_time_s``: wall
    time spent so far; ``path``: the file it was read from (None before it is written).
    """

    scenario: dict
    threads: int
    model: dict
    simulation: dict
    recorders: dict
    mass_rows: list
    resumed_from: list[float] = field(default_factory=list)
    wall_time_s: float = 0.0
    floodsph_version: str = __version__
    format: int = FORMAT
    path: Path | None = None

    @property
    def t(self) -> float:
        """Simulated time of the checkpoint [s]."""
        return float(self.model["t"])


def canonical_json(scenario: dict) -> str:
    """The resolved scenario as one canonical JSON text (sorted keys, no spaces), the text
    that ``scenario_sha256`` hashes."""
    return json.dumps(scenario, sort_keys=True, separators=(",", ":"), ensure_ascii=False,
                      allow_nan=True)


def plain_scenario(scenario: dict) -> dict:
    """``scenario`` as a checkpoint gives it back (tuples as lists), for comparisons."""
    return json.loads(canonical_json(scenario))


def scenario_sha256(text: str) -> str:
    """The SHA-256 of a scenario's canonical JSON text, in hex."""
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def save_checkpoint(folder: Path, checkpoint: Checkpoint) -> Path:
    """Write ``checkpoint`` to ``folder/checkpoint/state.npz`` atomically; return its path."""
    directory = Path(folder) / CHECKPOINT_DIR
    directory.mkdir(exist_ok=True)
    target = directory / CHECKPOINT_NAME
    text = canonical_json(checkpoint.scenario)
    arrays = flatten({
        "format": checkpoint.format,
        "floodsph_version": checkpoint.floodsph_version,
        "scenario_sha256": scenario_sha256(text),
        "threads": checkpoint.threads,
        "wall_time_s": checkpoint.wall_time_s,
        "resumed_from": list(checkpoint.resumed_from),
        "model": checkpoint.model,
        "simulation": checkpoint.simulation,
        "recorders": checkpoint.recorders,
        "mass_rows": list(checkpoint.mass_rows),
    })
    arrays[SCENARIO] = np.asarray(text)
    with atomic_path(target) as tmp, open(tmp, "wb") as f:
        np.savez(f, **cast(dict[str, Any], arrays))
        f.flush()
        os.fsync(f.fileno())
    return target


def load_checkpoint(directory: Path) -> Checkpoint:
    """Read the checkpoint in ``directory`` (a ``checkpoint/`` folder).

    Raises
    ------
    InputError
        No checkpoint, a pickled checkpoint of format 4 or before, a file that cannot be
        read (truncated, changed), another format or floodsph version, or a field missing,
        extra or of the wrong kind.
    """
    path = Path(directory) / CHECKPOINT_NAME
    pickled = Path(directory) / PICKLED_CHECKPOINT_NAME
    if not path.is_file() and pickled.is_file():
        raise InputError(f"{pickled}: a checkpoint of format 4 or before (a Python pickle, "
                         f"which is never read); this floodsph reads format {FORMAT} only: "
                         "run the scenario again with --overwrite")
    arrays = _read_arrays(path)
    source = str(path)
    if "format" not in arrays:
        raise InputError(f"{path}: not a floodsph checkpoint (it has no format)")
    found = arrays["format"]
    if found.ndim != 0 or found.dtype.kind not in "iu" or int(found) != FORMAT:
        raise InputError(f"{path}: a checkpoint of format {found}; this floodsph reads "
                         f"format {FORMAT} only: run the scenario again with --overwrite")
    tree = unflatten(arrays, source)
    expect_fields(tree, FIELDS, "", source)
    if tree["floodsph_version"] != __version__:
        raise InputError(f"{path}: written by floodsph {tree['floodsph_version']}, this is "
                         f"{__version__}; resume it with that version")
    if scenario_sha256(str(arrays[SCENARIO])) != tree["scenario_sha256"]:
        raise InputError(f"{path}: the scenario stored in the checkpoint does not match its "
                         "scenario_sha256: the file was changed")
    for name, kind in (("threads", int), ("wall_time_s", float), ("resumed_from", list),
                       ("model", dict), ("simulation", dict), ("recorders", dict),
                       ("mass_rows", list), (SCENARIO, dict)):
        value = tree[name]
        if not isinstance(value, kind) or (kind is float and isinstance(value, bool)):
            raise InputError(f"{path}: the field {name} is not a {kind.__name__}")
    if not isinstance(tree["model"].get("t"), float):
        raise InputError(f"{path}: the field model.t is missing or not a number")
    if not all(isinstance(row, list) for row in tree["mass_rows"]):
        raise InputError(f"{path}: the field mass_rows is not a list of rows")
    return Checkpoint(scenario=tree[SCENARIO], threads=tree["threads"], model=tree["model"],
                      simulation=tree["simulation"], recorders=tree["recorders"],
                      mass_rows=[tuple(row) for row in tree["mass_rows"]],
                      resumed_from=tree["resumed_from"], wall_time_s=tree["wall_time_s"],
                      floodsph_version=tree["floodsph_version"], format=FORMAT, path=path)


def _read_arrays(path: Path) -> dict[str, np.ndarray]:
    """Every array of the ``.npz`` file ``path``, read without unpickling anything."""
    try:
        with np.load(path, allow_pickle=False) as npz:
            return {name: npz[name] for name in npz.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile,
            TypeError) as exc:
        raise InputError(f"{path}: the checkpoint cannot be read ({exc})") from None


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
