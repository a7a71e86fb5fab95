"""``floodsph check ENSEMBLE.toml`` checks the ensemble as ``floodsph ensemble`` does before a
member runs, and writes nothing."""

from __future__ import annotations

from click.testing import CliRunner
from ensemble_cases import LEVEL, ensemble_text, write_case

from floodsph.cli.main import cli


def check(path):
    return CliRunner().invoke(cli, ["check", str(path)])


def test_a_valid_ensemble_is_checked_and_summarised(tmp_path):
    path = write_case(tmp_path, ensemble_text(members=5))
    result = check(path)
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert lines[0] == f"Ensemble:        tiny ({path})"
    assert "Members:         5 (latin-hypercube sampling, seed 3)" in lines[1]
    assert ("Parameter:       initial_water[0].level_m: uniform (low = 101.5, high = 103.5), "
            "mode value") in lines
    assert f"Base scenario:   dam-break ({tmp_path / 'scenario.toml'})" in lines
    assert "Particles:       200" in lines  # the base scenario's inputs were prepared
    assert lines[-1] == "OK: the ensemble is valid."
    assert not (tmp_path / "out").exists()


def test_a_sampled_level_below_the_bed_is_refused_naming_the_member(tmp_path):
    low = LEVEL.replace("low = 101.5", "low = 90.0")  # the basin's bed is at 98 m
    path = write_case(tmp_path, ensemble_text(low, members=4))
    result = check(path)
    assert result.exit_code == 2, result.output
    error = result.stderr.strip()
    assert error.startswith("Error: ensemble.toml: member m")
    assert "initial_water[0].level_m: 9" in error and "is below the bed" in error
    assert "(the member's sampled values: initial_water[0].level_m = 9" in error
    assert not (tmp_path / "out").exists()


def test_a_value_the_scenario_refuses_is_named_with_its_parameter(tmp_path):
    negative = LEVEL.replace('key = "initial_water[0].level_m"', 'key = "terrain.manning"'
                             ).replace("low = 101.5", "low = -0.5").replace("high = 103.5",
                                                                           "high = 0.05")
    result = check(write_case(tmp_path, ensemble_text(negative)))
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith("Error: ensemble.toml: ensemble.parameters[0]: ")
