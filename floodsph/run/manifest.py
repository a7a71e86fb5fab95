"""The run manifest ``run.json``: what ran, how it ended, and its key numbers.

Keys (the contract, ``docs/run-folder.md`` and ``docs/outputs.md``): ``floodsph_version``,
``scenario`` (the resolved scenario), ``status`` (``"running"`` while the run is under way,
then ``"completed"``, ``"stopped"`` (``--max-steps`` reached first), ``"interrupted"`` or
``"failed"``), ``sim_time_s``, ``wall_time_s``, ``steps``,
``particles_initial``, ``particles_max``, ``particles_final``, ``splits``, ``merges``,
``mass_error_rel``, ``threads``; and in addition ``error`` (the message of a failed run),
``numba_version``, ``python_version``, ``started``/``finished`` (ISO 8601, UTC),
``start`` (the scenario's calendar start of t = 0, ISO 8601, or None without one),
``particle_spacing_m``, ``volume_*_m3`` totals, ``warnings`` (input problems a user could
mean, run anyway), ``checkpoint_time_s`` (the latest checkpoint) and ``resumed_from`` (the
checkpoint times the run was resumed from).

The file is written atomically (``floodsph.io.atomic_files``), so a reader never sees half a
manifest.
"""

from __future__ import annotations

import json
import math
import platform
from datetime import UTC, datetime
from pathlib import Path

from floodsph._version import __version__
from floodsph.io.atomic_files import atomic_path

MANIFEST_NAME = "run.json"


def now_iso() -> str:
    """The current UTC time in ISO 8601 with seconds."""
    return datetime.now(UTC).isoformat(timespec="seconds")


def new_manifest(scenario_dict: dict) -> dict:
    """A manifest for a run that is starting (status ``"running"``)."""
    import numba

    return {
        "floodsph_version": __version__,
        "numba_version": numba.__version__,
        "python_version": platform.python_version(),
        "status": "running",
        "error": None,
        "started": now_iso(),
        "finished": None,
        "sim_time_s": 0.0,
        "wall_time_s": 0.0,
        "steps": 0,
        "particles_initial": 0,
        "particles_max": 0,
        "particles_final": 0,
        "splits": 0,
        "merges": 0,
        "mass_error_rel": None,
        "threads": numba.get_num_threads(),
        "start": scenario_dict.get("scenario", {}).get("start"),
        "scenario": scenario_dict,
    }


def json_safe(value):
    """NaN/inf (not valid JSON) to None, recursively."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(v) for v in value]
    return value


def write_manifest(folder: Path, manifest: dict) -> Path:
    """Write ``manifest`` to ``folder/run.json`` atomically; returns the path."""
    target = Path(folder) / MANIFEST_NAME
    with atomic_path(target) as tmp, open(tmp, "w", encoding="utf-8") as f:
        json.dump(json_safe(manifest), f, indent=2, allow_nan=False)
        f.write("\n")
    return target


def read_manifest(folder: Path) -> dict | None:
    """The manifest in ``folder``, or None if there is none (or it is unreadable)."""
    path = Path(folder) / MANIFEST_NAME
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
