"""The run-time range ``floodsph check`` prints and the warnings of a huge run."""

from __future__ import annotations

import json

from click.testing import CliRunner
from conftest import BASE_SCENARIO

from floodsph.cli.main import cli
from floodsph.inputs.run_time import format_duration, warn_if_huge


def invoke(*args, env=None):
    return CliRunner().invoke(cli, [str(a) for a in args], env=env)


def test_check_prints_the_steps_a_run_then_takes_within_a_factor_of_two(scenario_file):
    checked = invoke("check", scenario_file, env={"NUMBA_NUM_THREADS": "1"})
    assert checked.exit_code == 0, checked.output
    line = next(x for x in checked.stdout.splitlines() if x.startswith("Run time:"))
    assert "on 1 thread (about 50 steps" in line  # 20 s / (0.3 x 12 m / 2 sqrt(g 2 m))
    assert invoke("-q", "run", scenario_file).exit_code == 0
    run = json.loads((scenario_file.parent / "out" / "valley" / "run.json").read_text())
    assert 0.5 <= 50 / run["steps"] <= 2.0, run["steps"]


def test_a_spacing_finer_than_a_quarter_cell_is_warned_of(write_scenario):
    fine = write_scenario(BASE_SCENARIO.replace("particle_spacing_m = 10.0",
                                                "particle_spacing_m = 2.0"))
    result = invoke("check", fine)
    assert result.exit_code == 0, result.output
    assert ("WARNING: scenario.toml: numerics.particle_spacing_m = 2 m is finer than a quarter "
            "of the DEM cell (10 m)") in result.stderr
    assert "Warnings:        1" in result.stdout


def test_millions_of_particles_are_warned_of_with_the_count():
    warnings: list[str] = []
    warn_if_huge(None, 0.2, 10.0, 7_300_000, "s.toml", warnings)
    assert warnings[0].startswith("s.toml: numerics.particle_spacing_m = 0.2 m gives about "
                                  "7,300,000 particles at peak")
    assert "2.5e+03 times the particles of one per cell" in warnings[1]
    quiet: list[str] = []
    warn_if_huge(None, 10.0, 10.0, 4_000_000, "s.toml", quiet)
    assert quiet == []


def test_durations_read_in_the_unit_that_fits():
    assert [format_duration(s) for s in (0.2, 42, 720, 12600, 190000)] == [
        "under 1 s", "42 s", "12 min", "3.5 h", "2.2 days"]
