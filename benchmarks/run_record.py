"""Where a long run came from: the commit, date, load and wall time kept beside its folder.

The pages that compare floodsph with ANUGA on real terrain reuse run folders made earlier (a
full run takes minutes to tens of minutes), so the commit and machine line of the page is not
that of the runs. Each run a page script starts leaves ``provenance.json`` in its folder:
the commit of the repository, the start date, the 1-minute load average before and after and
the wall time of the whole process [s]; the page quotes it for each run.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import provenance

NAME = "provenance.json"


def run_recorded(cmd: list[str], folder: Path, repo: Path, env: dict | None = None) -> dict:
    """Run ``cmd`` (a list of arguments), then write ``folder/provenance.json``; the record.

    Raises SystemExit with the command when it fails.
    """
    load0, t0 = os.getloadavg()[0], time.perf_counter()
    started = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    code = subprocess.run(cmd, env=env, check=False).returncode
    if code:
        raise SystemExit(f"failed (exit status {code}): {' '.join(cmd)}")
    record = {"commit": provenance.commit(repo), "started": started,
              "load_start": load0, "load_end": os.getloadavg()[0],
              "process_wall_s": time.perf_counter() - t0,
              "command": " ".join("python" if a == sys.executable else
                                  a.replace(f"{repo}/", "") for a in cmd)}
    folder.mkdir(parents=True, exist_ok=True)
    (folder / NAME).write_text(json.dumps(record, indent=2) + "\n")
    return record


def read(folder: Path) -> dict | None:
    """The record of ``folder``, or None when the run was not made by a page script."""
    path = folder / NAME
    return json.loads(path.read_text()) if path.is_file() else None


def note(record: dict | None) -> str:
    """One sentence on where a run came from (the fields the record has)."""
    if record is None:
        return "commit and machine load not recorded (a folder made outside the page script)"
    text = f"commit `{record['commit']}`, started {record['started']}"
    if "load_start" in record:
        text += (f", 1-minute load average {record['load_start']:.1f} before and "
                 f"{record['load_end']:.1f} after, {record['process_wall_s']:.0f} s for the "
                 "whole process")
    return text + f": `{record['command']}`"
