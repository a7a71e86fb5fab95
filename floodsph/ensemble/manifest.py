"""``ensemble.json`` (the ensemble manifest) and ``samples.csv`` (one row per member).

``ensemble.json`` keys (contract, ``ensemble-format.md``): ``floodsph_version``, ``ensemble``
(the resolved ensemble file), ``status``, ``members``, ``members_completed``,
``members_failed``, ``scheduler`` (its address, or ``"local"``), ``workers``,
``wall_time_s``; and in addition ``error`` (why an ensemble failed), ``threads_per_worker``,
``members_kept`` (completed members that ``--resume`` did not run again),
``members_interrupted`` (running when the ensemble was interrupted), ``started`` /
``finished`` (ISO 8601, UTC), ``maps`` and ``pictures`` (the files written).

``status`` is ``"running"`` while the members run, then ``"completed"`` (every member
completed), ``"completed_with_failures"`` (some failed; the maps are over the completed
ones), ``"interrupted"`` or ``"failed"`` (no member completed, or the ensemble itself failed).

``samples.csv`` columns: ``member``, one per parameter key (the drawn value: for a
``mode = "factor"`` parameter the factor), ``status`` (a member's run status --
``interrupted`` for one running when the ensemble was interrupted -- or ``"not run"``),
``wall_time_s``, ``error``.

Both files are written atomically (``floodsph.io.atomic_files``), readable by the group.
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

from floodsph._version import __version__
from floodsph.io.atomic_files import atomic_path
from floodsph.run.manifest import json_safe, now_iso

ENSEMBLE_JSON = "ensemble.json"
SAMPLES_CSV = "samples.csv"
NOT_RUN = "not run"


def new_manifest(ensemble: dict, members: int, scheduler: str | None) -> dict:
    """The manifest of an ensemble that is starting."""
    return {
        "floodsph_version": __version__,
        "ensemble": ensemble,
        "status": "running",
        "error": None,
        "members": members,
        "members_completed": 0,
        "members_failed": 0,
        "members_interrupted": 0,
        "members_kept": 0,
        "scheduler": scheduler or "local",
        "workers": None,
        "threads_per_worker": None,
        "started": now_iso(),
        "finished": None,
        "wall_time_s": 0.0,
        "maps": [],
        "pictures": [],
    }


def final_status(completed: int, failed: int) -> str:
    """``completed``, ``completed_with_failures`` or ``failed`` from the member counts."""
    if completed == 0:
        return "failed"
    return "completed_with_failures" if failed else "completed"


def write_manifest(folder: Path, manifest: dict) -> Path:
    """Write ``folder/ensemble.json``."""
    path = Path(folder) / ENSEMBLE_JSON
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(json_safe(manifest), indent=2, allow_nan=False) + "\n",
                       encoding="utf-8")
    return path


def read_manifest(folder: Path) -> dict | None:
    """The ensemble manifest in ``folder``, or None when there is none (or it is unreadable)."""
    try:
        return json.loads((Path(folder) / ENSEMBLE_JSON).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(float(value))
    if isinstance(value, list | tuple):
        return json.dumps(value)
    return str(value)


def write_samples(folder: Path, keys, ids, rows, results: dict) -> Path:
    """Write ``folder/samples.csv``: member ``ids[m]`` drew ``rows[m]``; ``results`` maps a
    member id to its :class:`~floodsph.ensemble.members.MemberResult` (absent: not run)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["member", *keys, "status", "wall_time_s", "error"])
    for mid, drawn in zip(ids, rows, strict=True):
        result = results.get(mid)
        status = NOT_RUN if result is None else result.status
        wall = None if result is None else result.wall_time_s
        error = None if result is None else result.error
        writer.writerow([mid, *(_cell(v) for v in drawn), status, _cell(wall), _cell(error)])
    path = Path(folder) / SAMPLES_CSV
    with atomic_path(path) as tmp:
        tmp.write_text(buffer.getvalue(), encoding="utf-8", newline="")
    return path
