"""Golden regression: small runs must reproduce their stored numbers.

The stored files (``tests/golden/*.json``, written by ``python tests/golden_cases.py``) hold
depth-error figures, step and refinement counters, volumes and gauge depths of Ritter,
Stoker and Thacker, a refined run, a local-step run and a scenario run with an inflow,
open edges, refinement and local steps. A refactoring must leave every number as it was
(step counts exactly, values to 1e-10 relative); a change meant to move them regenerates
the files and says why in its commit.
"""

from __future__ import annotations

import json

import numba
import pytest
from golden_cases import CASES, GOLDEN, THREADS, compute


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < THREADS,
                    reason=f"the golden numbers were made with {THREADS} threads")
@pytest.mark.parametrize("name", sorted(CASES))
def test_the_run_reproduces_its_golden_numbers(name, tmp_path):
    stored = json.loads((GOLDEN / f"{name}.json").read_text())
    values = compute(name, tmp_path)
    assert sorted(values) == sorted(stored)
    for key, expected in stored.items():
        if isinstance(expected, int):
            assert values[key] == expected, key
        else:
            assert values[key] == pytest.approx(expected, rel=1e-10, abs=1e-12, nan_ok=True), key
