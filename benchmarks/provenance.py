"""The provenance line of a page a benchmark writes: the commit and the machine around the runs.

Figures on the project's pages come from one run on one (often shared) machine; the line says
which commit made them, the cores and numba threads, and the load before and after, so that a
reader can tell a quiet run from a crowded one.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path


def commit(repo: Path) -> str:
    """The short hash of ``repo``'s HEAD, or "unknown" outside a git checkout."""
    try:
        return subprocess.run(["git", "-C", str(repo), "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def machine_note(load: tuple[float, float], wall_s: float, timing: str) -> str:
    """Cores, numba threads, the 1-minute load average at the start and the end (flagged when
    above the threads used), the total wall time [s], then ``timing``: what the wall times
    mean."""
    import numba

    threads = numba.get_num_threads()
    busy = max(load) > threads + 0.5
    return (f"{os.cpu_count()} cores, {threads} numba thread(s); 1-minute load average "
            f"{load[0]:.1f} at the start and {load[1]:.1f} at the end"
            + (" (above the threads used: other jobs shared the machine)" if busy else "")
            + f"; {wall_s:.0f} s in all. {timing}")
