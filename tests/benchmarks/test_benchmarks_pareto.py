"""``benchmarks/pareto.py``: the quick benchmark (floodsph only) and the equal-error reading.

The quick form runs each analytic case once per floodsph mode at a coarse resolution (Ritter
and Stoker 20 m, Thacker 200 m); the peers are asked for but not needed: without them the page
says they were skipped. No timing is asserted.
"""

from __future__ import annotations

import csv
import math
import sys
from pathlib import Path

import pytest
from conftest import load_script

pytestmark = pytest.mark.benchmark

REPO = Path(__file__).resolve().parents[2]
pareto = load_script("pareto", REPO / "benchmarks" / "pareto.py")

L1_BOUND = {"ritter": 0.05, "stoker": 0.05, "thacker": 0.10}
"""Sane upper bounds of the quick runs' errors (the coarse Ritter at 20 m below 5 %)."""


def test_quick_benchmark_writes_one_row_per_run_and_the_page(tmp_path):
    page = pareto.main(["--quick", "--out", str(tmp_path), "--peer-python", sys.executable,
                        "--peer-work", str(tmp_path / "peers")])
    with open(tmp_path / "speed-vs-grid-codes.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    keys = [(r["case"], r["code"], r["mode"], r["resolution_m"]) for r in rows]
    assert len(keys) == len(set(keys))  # one row per (case, code, mode, resolution)
    fs = [r for r in rows if r["code"] == "floodsph"]
    assert sorted((r["case"], r["mode"]) for r in fs) == sorted(
        (case, mode.label) for case in pareto.CASES for mode in pareto.MODES)
    for r in fs:
        assert float(r["resolution_m"]) == pareto.CASES[r["case"]].quick_res
        assert math.isfinite(float(r["l1"])) and 0.0 < float(r["l1"]) < L1_BOUND[r["case"]]
        assert int(r["elements"]) > 0 and int(r["steps"]) > 0 and int(r["threads"]) == 1
    text = page.read_text()
    assert page == tmp_path / "speed-vs-grid-codes.md"
    for case in pareto.CASES:
        assert f"| {case} | floodsph | none, global |" in text
    for name in ("GeoClaw", "ANUGA"):  # run, or said to be skipped
        assert f"| {name} |" in text or f"* {name}: skipped" in text
    assert "python benchmarks/pareto.py --quick" in text
    assert (tmp_path / "speed-vs-grid-codes.png").stat().st_size > 10_000


def test_time_at_equal_error_interpolates_on_the_peers_front_only():
    points = [(1.0, 0.04), (8.0, 0.02), (64.0, 0.01), (30.0, 0.03)]  # (30 s, 3 %) is beaten
    assert pareto.pareto_front(points) == [(1.0, 0.04), (8.0, 0.02), (64.0, 0.01)]
    assert math.isclose(pareto.time_at_error(points, 0.02), 8.0)
    assert math.isclose(pareto.time_at_error(points, 0.04 / math.sqrt(2.0)), math.sqrt(8.0))
    assert pareto.time_at_error(points, 0.05) is None  # above the coarsest
    assert pareto.time_at_error(points, 0.005) is None  # below the finest: no extrapolation
