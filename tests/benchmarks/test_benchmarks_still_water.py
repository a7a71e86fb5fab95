"""``benchmarks/still_water.py``: the still-water benchmark, run in its ``--quick`` form (the
synthetic cases through ``run_scenario``, a few hundred particles each, 60 s; the dam break
12 s), and its measures on points placed by hand."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import load_script

pytestmark = pytest.mark.benchmark

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
cases = load_script("still_water_cases", BENCHMARKS / "still_water_cases.py")
still = load_script("still_water", BENCHMARKS / "still_water.py")

STILL_ROWS = ["rectangle 0 deg", "rectangle 15 deg", "rectangle 30 deg", "rectangle 45 deg",
              "nodata staircase", "parabolic bowl", "building 30 deg"]
DAM_BREAK_ROWS = ["dam break 0 deg", "dam break 30 deg"]


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("still_water")
    bench = still.main(["--quick", "--out", str(out), "--doc", str(out / "doc.md")])
    return bench, out


def by_label(bench):
    return {r.case.label: r for r in bench.still + bench.dam_break}


def test_the_quick_benchmark_has_one_row_per_case_and_angle_in_its_table_csv_and_report(
        quick):
    bench, out = quick
    assert [r.case.label for r in bench.still] == STILL_ROWS
    assert [r.case.label for r in bench.dam_break] == DAM_BREAK_ROWS
    with open(out / "still_water.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["case"] for r in rows] == STILL_ROWS
    doc = (out / "doc.md").read_text(encoding="utf-8")
    for label in STILL_ROWS + DAM_BREAK_ROWS:
        assert f"| {label} |" in doc
    assert "python benchmarks/still_water.py --quick" in doc
    tables = [b for b in doc.split("\n\n") if b.startswith("| ")]
    assert len(tables) == 4  # still water, over time, dam break, its targets
    for table in tables:
        lines = table.splitlines()
        assert all(line.count("|") == lines[0].count("|") for line in lines), table
    assert "max < 1 cm/s" in doc and "shore within 5 m" in doc
    assert (out / "doc.png").stat().st_size > 0


def test_every_run_is_sampled_at_twenty_report_times_with_finite_speeds(quick):
    """Samples at 0, T/20, ..., T of each run's end time T; speeds finite and >= 0."""
    bench, _ = quick
    for run in bench.still + bench.dam_break:
        end = run.manifest["sim_time_s"]
        assert [s.t for s in run.samples] == pytest.approx(np.linspace(0.0, end, 21))
        for s in run.samples:
            assert math.isfinite(s.max_speed) and math.isfinite(s.p95_speed)
            assert 0.0 <= s.p95_speed <= s.max_speed
            assert s.particles > 0


def test_a_lake_walled_along_the_lattice_stays_still_and_level(quick):
    """2 m of water inside walls along the lattice rows: the seeded level is exact and the
    lake stays still (< 1 cm/s, the issue's target; no drift at all is measured)."""
    run = by_label(quick[0])["rectangle 0 deg"]
    assert run.samples[0].level_error < 1e-6
    assert run.worst("max_speed") < 0.01
    assert run.worst("level_error") < 1e-3
    assert still.still_row(run)["result"] == "pass"


def test_the_level_error_is_measured_against_the_known_level(quick):
    """On the flat bed (b = 0) of the turned rectangle the last sample's level error is
    max |eta - 2 m| of the particles at the end, eta their level (under the variational
    momentum, rho / rho_w)."""
    run = by_label(quick[0])["rectangle 30 deg"]
    p = run.probe.particles
    d = p["level"] if "level" in p else p["rho"] / 1000.0
    assert run.samples[-1].level_error == pytest.approx(np.abs(d - 2.0).max(), rel=1e-12)
    assert run.samples[-1].level_p95 == pytest.approx(
        np.percentile(np.abs(d - 2.0), 95), rel=1e-12)


def test_the_result_column_names_exactly_the_targets_missed(quick):
    bench, _ = quick
    for run in bench.still:
        row = still.still_row(run)
        lim = run.case.limits
        missed = []
        if row["max speed cm/s"] > 100 * lim.max_speed:
            missed.append("max speed")
        if lim.p95_speed is not None and row["p95 speed cm/s"] > 100 * lim.p95_speed:
            missed.append("p95 speed")
        if lim.shore is not None and run.worst("shore_error") > lim.shore:
            missed.append("shore")
        assert row["result"] == ("pass" if not missed else "miss: " + ", ".join(missed))


def test_the_seeded_shore_of_the_bowl_lies_within_one_spacing(quick):
    run = by_label(quick[0])["parabolic bowl"]
    assert run.samples[0].shore_error < 5.0


def test_the_dam_break_keeps_its_water_in_the_channel_and_follows_ritter_at_both_angles(
        quick):
    """Ritter's dam break at 12 s in a 600 m channel along x and turned by 30 degrees: no
    particle outside the walls, L1 against the exact depth a few per cent (measured 1.5 %
    along x, 2.3 % turned)."""
    runs = quick[0].dam_break
    for run in runs:
        assert run.figures["outside"] == 0
        assert 0.0 < run.figures["l1"] < 0.05
    too_far = still.Check("L1 ratio - 1", -0.3, 0.25, two_sided=True)
    assert not too_far.met and too_far.limit_text == "+/- 0.25"


@pytest.mark.xfail(strict=True, reason="the balanced momentum: the turned channel's L1 is 2.3 % "
                   "against 1.5 % along x (the variational force: 1.5 % at both); while the "
                   "water is slow the level form acts, and the rows along the turned walls are "
                   "pushed less evenly (docs/balanced-momentum.md)")
def test_the_turned_dam_break_is_within_25_percent_of_the_one_along_x(quick):
    runs = quick[0].dam_break
    assert runs[1].figures["l1"] == pytest.approx(runs[0].figures["l1"], rel=0.25)
    assert [c.met for c in still.dam_break_checks(runs)] == [True] * 5


def test_shore_error_is_the_worst_sector_of_the_outermost_particles():
    shore = cases.Shore(10.0, -5.0, 100.0)
    angle = np.linspace(-np.pi, np.pi, 360, endpoint=False) + 0.001
    r = np.full(angle.size, 101.0)
    r[:5] = 97.0  # the first sector's outermost particle at 101 m still
    x, y = shore.x + r * np.cos(angle), shore.y + r * np.sin(angle)
    assert still.shore_error(x, y, shore) == pytest.approx(1.0)
    inner = np.abs(angle) > np.pi - 0.25  # the sectors around 180 degrees keep only these
    r[inner] = 95.0
    x, y = shore.x + r * np.cos(angle), shore.y + r * np.sin(angle)
    assert still.shore_error(x, y, shore) == pytest.approx(5.0)
    assert still.shore_error(x[~inner], y[~inner], shore) == pytest.approx(100.0)


def test_particles_outside_a_turned_channel_are_counted():
    channel = cases.Channel(100.0, 50.0, 30.0, 2000.0, 100.0, 1000.0, 10.0, 50.0)
    s = np.array([1.0, 1999.0, 1000.0, -0.5, 2000.5, 500.0, 500.0])
    n = np.array([1.0, 99.0, 50.0, 50.0, 50.0, -0.5, 100.5])
    x, y = channel.to_world(s, n)
    assert still.particles_outside(x, y, channel) == 4
    back = channel.to_channel(x, y)
    assert np.allclose(back, (s, n))


def test_a_bad_end_time_names_the_option_and_the_value():
    with pytest.raises(SystemExit, match="'lake' is not one of malpasset"):
        still.end_times(still.parse_args(["--end-time", "lake=10"]))
    with pytest.raises(SystemExit, match="'ten' is not a number"):
        still.end_times(still.parse_args(["--end-time", "bowl=ten"]))
    times = still.end_times(still.parse_args(["--time-scale", "0.5", "--end-time",
                                              "bowl=30"]))
    assert times["bowl"] == 30.0 and times["rectangle"] == 500.0 and times["malpasset"] == 300.0
