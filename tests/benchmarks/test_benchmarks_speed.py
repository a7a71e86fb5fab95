"""``benchmarks/speed_vs_error.py`` and ``benchmarks/refinement_benchmark.py``, run briefly.

The analytic part runs the coarse Stoker dam break in the three default modes; the real cases
(third-party data, skipped when absent) run two steps per mode at their coarsest spacing,
which checks the chain: run folders, the agreement with the reference run, the CSV, the
markdown report and the picture.
"""

from __future__ import annotations

import csv
from pathlib import Path

import pytest
from conftest import load_script

pytestmark = pytest.mark.benchmark

REPO = Path(__file__).resolve().parents[2]
BENCHMARKS = REPO / "benchmarks"


speed = load_script("speed_vs_error", BENCHMARKS / "speed_vs_error.py")
bench = load_script("refinement_benchmark", BENCHMARKS / "refinement_benchmark.py")


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_speed_vs_error_analytic_rows_and_report(tmp_path):
    speed.main(["--quick", "--cases", "stoker", "--no-throughput", "--out", str(tmp_path)])
    rows = _rows(tmp_path / "speed_vs_error.csv")
    assert [(r["case"], r["refinement"], r["spacing"]) for r in rows] == [
        ("stoker", "none", "10"), ("stoker", "split", "10"), ("stoker", "split+coalesce", "10")]
    for r in rows:
        assert 0.0 < float(r["l1"]) < 0.015  # the coarse Stoker target of the core tests
        assert abs(float(r["front_error_m"])) <= 20.0 and float(r["mass_error_rel"]) < 1e-12
    report = (tmp_path / "speed_vs_error.md").read_text()
    assert "| stoker | none | global | 10 |" in report and "speed_vs_error.png" in report
    assert (tmp_path / "speed_vs_error.png").stat().st_size > 10_000


def test_speed_vs_error_runs_both_time_steppings(tmp_path):
    speed.main(["--quick", "--cases", "stoker", "--modes", "none", "--time-stepping", "global",
                "local", "--no-throughput", "--out", str(tmp_path)])
    glob, loc = _rows(tmp_path / "speed_vs_error.csv")
    assert (glob["time_stepping"], loc["time_stepping"]) == ("global", "local")
    assert float(loc["mass_error_rel"]) < 1e-12
    assert float(loc["l1"]) < 1.1 * float(glob["l1"])  # same error as the global step
    assert abs(float(loc["front_error_m"])) <= 20.0


def test_speed_vs_error_real_cases_agree_with_their_reference(tmp_path):
    if speed.mp_setup.data_folder() is None and speed.ea4.data_folder() is None:
        pytest.skip("benchmark data not found (set FLOODSPH_BENCHMARKS)")
    speed.main(["--quick", "--cases", "malpasset", "ea_test4", "--max-steps", "2",
                "--no-throughput", "--out", str(tmp_path)])
    rows = _rows(tmp_path / "real_cases.csv")
    assert {r["mode"] for r in rows} == {"none", "split", "split+coalesce"}
    for r in rows:
        assert r["reference"] == f"split+coalesce {r['spacing_m']} m global"
        assert int(r["steps"]) == 2 and float(r["mass_error_rel"]) < 1e-12
        if r["mode"] == "split+coalesce":  # the reference against itself
            assert r["csi"] in ("1", "nan") and r["rmse_m"] in ("0", "nan")
    assert "## Real terrain" in (tmp_path / "speed_vs_error.md").read_text()


def test_refinement_benchmark_two_steps_on_the_valley(tmp_path):
    bench.main(["--cases", "valley", "--modes", "none", "split", "--max-steps", "2",
                "--time-stepping", "local", "--out", str(tmp_path)])
    rows = _rows(tmp_path / "refinement_benchmark.csv")
    assert [(r["mode"], r["time_stepping"]) for r in rows] == [("none", "local"),
                                                               ("split", "local")]
    # --max-steps counts finest steps, as run.json does: the run ends with the big step (of
    # up to 2^3 finest steps) that holds the second
    assert all(2 <= int(r["steps"]) < 2 + 2 ** 3 and float(r["mass_error_rel"]) < 1e-12
               for r in rows)
    (pair,) = _rows(tmp_path / "agreement.csv")
    assert (pair["mode"], pair["against"]) == ("split", "none")
    assert float(pair["csi"]) > 0.99  # two steps: the same water in both
