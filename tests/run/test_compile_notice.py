"""The first run says that it is compiling; a run with every kernel cached says nothing.

A tiny kernel module with ``cache=True`` is run twice in fresh processes sharing one empty
numba cache folder, as a first and a second ``floodsph run`` do with floodsph's kernels.
"""

from __future__ import annotations

import os
import subprocess
import sys

from floodsph.run.compile_notice import START_MESSAGE

KERNELS = """
from numba import njit

from floodsph.run.compile_notice import CompileNotice


@njit(cache=True)
def add_one(x):
    return x + 1.0


@njit(cache=True)
def twice_plus_two(x):
    return 2.0 * add_one(x)


with CompileNotice(print):
    print("result", twice_plus_two(3.0))
"""


def run_kernels(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    done = subprocess.run([sys.executable, str(tmp_path / "kernels.py")], env=env,
                          capture_output=True, text=True, timeout=300, check=True)
    return done.stdout.splitlines()


def test_compiling_is_announced_once_and_timed_then_silent_from_the_cache(tmp_path):
    (tmp_path / "kernels.py").write_text(KERNELS)
    first = run_kernels(tmp_path)
    assert first[0] == START_MESSAGE
    assert first[1] == "result 8.0"
    # One top-level compilation (the inner kernel compiles inside it).
    assert first[2].startswith("compiled 1 numerical kernel in ")
    assert run_kernels(tmp_path) == ["result 8.0"]
