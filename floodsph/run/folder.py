"""The run folder: what a run may write there, its lock, and the swap of a replaced run.

Rules (``docs/run-folder.md``, the run-folder contract):

* A run writes only its own files (:data:`RUN_FILES`, ``breach_hydrograph_<i>.csv``,
  ``checkpoint/``) and never deletes or overwrites a file it did not write. A folder that
  holds anything else is refused, except the scenario's own input files, which are left
  alone; an input whose name is an output name (``-o .`` beside ``gauges.csv``) is refused.
  A folder is recognised as a previous run by its ``run.json``.
* A folder holding a completed run, or a checkpoint, is refused unless the run is asked to
  replace it (``overwrite``) or to continue it (``resume``). A replacing run is written beside
  the old one, in ``.floodsph-new/``, and swapped in when it completes: an interrupted or
  failed replacement leaves the old maps as they were.
* While a run writes a folder it holds an exclusive lock on ``.floodsph.lock`` (``filelock``:
  ``flock`` on POSIX, ``msvcrt.locking`` on Windows); the operating system releases it when
  the process ends, however it ends, so a killed run never leaves a stale lock.
* Every file goes in under a temporary name and is renamed into place
  (``floodsph.io.atomic_files``); files are readable by the group, as the user's umask allows.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

from floodsph.errors import InputError
from floodsph.io.atomic_files import TEMP_PREFIX
from floodsph.io.run_names import (
    BREACH_GLOB,
    CHECKPOINT_DIR,
    CHECKPOINT_NAMES,
    FLUX_NAME,
    GAUGES_NAME,
    LOCK_NAME,
    LOG_NAME,
    MAP_NAMES,
    MASS_BALANCE_NAME,
    PICTURE_NAMES,
    REPORT_NAME,
    RESOLVED_NAME,
    SERIES_PICTURE_NAMES,
    SNAPSHOTS_NAME,
    STAGING_DIR,
)
from floodsph.run.manifest import MANIFEST_NAME, read_manifest

if TYPE_CHECKING:
    from filelock import BaseFileLock

#: Every file name a run writes (``docs/run-folder.md``); a run's files in progress
#: carry one of these names with a suffix (``snapshots.nc.part``, ``max_depth.tif.part``).
RUN_FILES = (*MAP_NAMES, SNAPSHOTS_NAME, GAUGES_NAME, FLUX_NAME, MASS_BALANCE_NAME,
             MANIFEST_NAME, RESOLVED_NAME, LOG_NAME, *PICTURE_NAMES, *SERIES_PICTURE_NAMES,
             REPORT_NAME)
#: Statuses of a run whose maps are written: its folder is only replaced on request.
FINISHED = ("completed", "stopped")


def is_run_file(name: str) -> bool:
    """True for the names a run writes into its folder."""
    return (name in RUN_FILES or name in (CHECKPOINT_DIR, STAGING_DIR, LOCK_NAME)
            or Path(name).match(BREACH_GLOB) or name.startswith(TEMP_PREFIX)
            or any(name.startswith(f"{run_file}.") for run_file in RUN_FILES))


class RunFolder:
    """The folder of one run, its lock, and where the run writes (``work``).

    Parameters
    ----------
    path : Path
        The run folder the user asked for.
    inputs : iterable of Path
        The scenario file and every file it reads: they may lie in the folder and are never
        touched.
    overwrite : bool
        Replace a completed (or checkpointed) run: the new one is built in ``.floodsph-new``.
    resume : bool
        Continue the run whose checkpoint is in the folder.
    """

    def __init__(self, path: Path, inputs: Iterable[Path] = (), overwrite: bool = False,
                 resume: bool = False):
        self.path = Path(path)
        self.inputs = {Path(p).resolve() for p in inputs}
        self.overwrite = bool(overwrite)
        self.resume = bool(resume)
        self.staged = False
        self._lock_file: BaseFileLock | None = None  # held while the run writes the folder

    # -- checks (nothing written) ------------------------------------------------------------
    def check(self) -> None:
        """Refuse a folder the run may not write: one message, nothing created or changed."""
        path = self.path
        problem = _name_problem(path)
        if problem:
            raise InputError(f"{str(path)!r}: {problem}")
        if path.exists() and not path.is_dir():
            raise InputError(f"{path}: the output folder is a file; choose another --output")
        existing = _nearest_existing(path)
        if not os.access(existing, os.W_OK | os.X_OK):
            raise InputError(f"{existing}: not writable; choose another --output folder")
        if not path.is_dir():
            if self.resume:
                raise InputError(f"{path}: no run folder to resume (it does not exist)")
            return
        self._check_contents()
        previous = read_manifest(path)
        status = None if previous is None else previous.get("status")
        checkpointed = self.checkpoint_dir() is not None
        if self.resume:
            if not checkpointed:
                raise InputError(f"{path}: no checkpoint to resume from (set "
                                 "output.checkpoint_interval_s > 0 to write checkpoints)")
            return
        if (status in FINISHED or checkpointed) and not self.overwrite:
            what = f"a {status} run" if status in FINISHED else "a checkpointed run"
            raise InputError(f"{path}: already holds {what} (run.json); pass --overwrite to "
                             "replace it, --resume to continue it, or choose another --output")

    def _check_contents(self) -> None:
        names = sorted(os.listdir(self.path))
        has_manifest = MANIFEST_NAME in names
        foreign, clashes = [], []
        for name in names:
            full = (self.path / name).resolve()
            if full in self.inputs:
                if is_run_file(name):
                    clashes.append(name)
                continue
            if not (has_manifest and is_run_file(name)) and name not in (LOCK_NAME,
                                                                           STAGING_DIR):
                foreign.append(name)
        if clashes:
            raise InputError(f"{self.path}: the input file {clashes[0]} lies in the output "
                             "folder and has the name of a run output; choose another "
                             "--output folder")
        if foreign:
            shown = ", ".join(foreign[:3]) + (f" and {len(foreign) - 3} more"
                                              if len(foreign) > 3 else "")
            raise InputError(f"{self.path}: holds files that are not a floodsph run's "
                             f"({shown}); a run never overwrites them: choose an empty or "
                             "new --output folder")

    def checkpoint_dir(self) -> Path | None:
        """The folder of the latest checkpoint (a replacing run's first), or None."""
        for base in (self.path / STAGING_DIR, self.path):
            candidate = base / CHECKPOINT_DIR
            if any((candidate / name).is_file() for name in CHECKPOINT_NAMES):
                return candidate
        return None

    # -- writing -----------------------------------------------------------------------------
    def open(self) -> Path:
        """Create the folder, take the lock, clear what an earlier run left; return ``work``.

        ``work`` is the folder itself, or ``.floodsph-new`` inside it when the run replaces
        a completed run (or extends one on resume) and is swapped in by :meth:`swap_in`.
        """
        self.path.mkdir(parents=True, exist_ok=True)
        self._lock()
        previous = read_manifest(self.path)
        completed = previous is not None and previous.get("status") in FINISHED
        resumed_staging = self.resume and self.checkpoint_dir() == (
            self.path / STAGING_DIR / CHECKPOINT_DIR)
        self.staged = completed or resumed_staging
        if not self.resume and not self.staged:  # an unfinished run's files are replaced
            self._remove_run_files(self.path)
        if self.staged:
            staging = self.path / STAGING_DIR
            if not self.resume:
                shutil.rmtree(staging, ignore_errors=True)
            staging.mkdir(exist_ok=True)
        self.clear_temporaries()
        return self.work

    def clear_temporaries(self) -> None:
        """Remove half-written files (temporary and ``.part`` names) from ``work``; the
        snapshots in progress stay, for a resume."""
        for entry in self.work.iterdir():
            name = entry.name
            if name.startswith(TEMP_PREFIX) or (name.endswith(".part")
                                                and name != f"{SNAPSHOTS_NAME}.part"):
                _remove(entry)

    def finished_snapshots(self) -> Path | None:
        """The finished run's ``snapshots.nc`` when this run extends it from its checkpoint
        (a resume of a finished run, written in ``.floodsph-new``), else None."""
        if not (self.resume and self.staged):
            return None
        source = self.path / SNAPSHOTS_NAME
        resumed_in_place = any((self.work / CHECKPOINT_DIR / name).is_file()
                               for name in CHECKPOINT_NAMES)
        return None if resumed_in_place or not source.exists() else source

    @property
    def work(self) -> Path:
        """Where the run writes now."""
        return self.path / STAGING_DIR if self.staged else self.path

    def _remove_run_files(self, folder: Path) -> None:
        """Delete a previous run's own files in ``folder`` (never an input, nothing else)."""
        for entry in folder.iterdir():
            if entry.name in (STAGING_DIR, LOCK_NAME) or entry.resolve() in self.inputs:
                continue
            if is_run_file(entry.name):
                _remove(entry)

    def swap_in(self) -> None:
        """Put a completed replacement in place of the old run (``run.json`` last)."""
        if not self.staged:
            return
        staging = self.path / STAGING_DIR
        old_manifest = self.path / MANIFEST_NAME
        if old_manifest.exists():  # from here on the folder no longer claims the old run
            old_manifest.unlink()
        self._remove_run_files(self.path)
        for entry in sorted(staging.iterdir(), key=lambda e: e.name == MANIFEST_NAME):
            os.replace(entry, self.path / entry.name)
        staging.rmdir()
        self.staged = False

    def _lock(self) -> None:
        from filelock import FileLock, Timeout

        lock = FileLock(self.path / LOCK_NAME, timeout=0, mode=0o664)
        try:
            lock.acquire()
        except Timeout:
            raise InputError(f"{self.path}: another floodsph run is writing this folder "
                             "(it is locked); wait for it or choose another --output"
                             ) from None
        self._lock_file = lock

    def close(self) -> None:
        """Release the lock (the lock file stays: removing it would race another run)."""
        if self._lock_file is not None:
            self._lock_file.release()
            self._lock_file = None


def _remove(entry: Path) -> None:
    if entry.is_dir() and not entry.is_symlink():
        shutil.rmtree(entry)
    else:
        entry.unlink(missing_ok=True)


def _nearest_existing(path: Path) -> Path:
    """``path`` or its nearest existing parent."""
    path = path.absolute()
    while True:
        try:
            if path.exists():
                return path
        except OSError:  # a name too long for the system, say
            pass
        path = path.parent


def _name_problem(path: Path) -> str | None:
    """Why ``path`` cannot be a folder name on this system, or None."""
    if "\x00" in str(path):
        return "the output folder's name contains a NUL character"
    limit = os.pathconf(_nearest_existing(path), "PC_NAME_MAX")
    for part in path.parts:
        if len(os.fsencode(part)) > limit:
            return (f"the folder name {part[:40]!r}... is longer than the {limit} bytes a "
                    "file name may have here")
    return None
