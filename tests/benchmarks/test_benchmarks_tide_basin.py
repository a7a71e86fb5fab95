"""``benchmarks/tide_basin.py``: a tide in a basin open at one end, the far-end level against
the forced standing wave (a short run of a small basin)."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import load_script

pytestmark = pytest.mark.benchmark

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
tide_basin = load_script("tide_basin_benchmark", BENCHMARKS / "tide_basin.py")


def test_a_small_basin_follows_the_tide_and_keeps_its_volume_balance():
    """A 40 m basin under a 200 s tide of 0.5 m amplitude, 1.5 periods: after the first
    period the far-end level stays within 5 cm of the standing wave (the default, finer case
    is within 2 cm: docs/level-boundary-benchmark.md), and V_0 + V_in - V_out = V to
    round-off at every sample, with water both entering and leaving."""
    row = tide_basin.run_case(40.0, 6.0, 2.0, 1.5, period=200.0)
    assert row["error_wave"] < 0.05
    assert row["imbalance"] < 1e-9 * row["volume_initial"]
    assert row["volume_in"] > 0.2 * row["volume_initial"]
    assert row["volume_out"] > 0.2 * row["volume_initial"]


def test_the_table_reports_the_errors_and_the_balance():
    row = {"length": 100.0, "width": 10.0, "spacing": 2.0, "periods": 2.0, "kL": 0.236,
           "amplification": 1.0285, "error_wave": 0.0167, "error_imposed": 0.0201,
           "volume_initial": 1500.0, "volume_in": 2100.0, "volume_out": 2099.0,
           "volume_final": 1501.0, "imbalance": 2e-12, "particles": 380, "steps": 9000,
           "wall_s": 30.0}
    text = tide_basin.table([row], "python benchmarks/tide_basin.py")
    assert "| 2 | 1.67 cm | 2.01 cm | 1500.000 | 2100.000 | 2099.000 |" in text
    assert "| 2.00e-12 | 380 |" in text
