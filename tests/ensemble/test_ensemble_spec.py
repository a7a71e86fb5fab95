"""The ensemble file: its resolved form, and one message naming the key for each bad input.

Every bad input is refused before any member runs, through ``floodsph ensemble`` (exit 2, one
line on stderr, no traceback), without starting a cluster.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from click.testing import CliRunner
from ensemble_cases import LEVEL, ensemble_text, write_case

from floodsph.cli.main import cli
from floodsph.ensemble.spec import load_ensemble


def invoke(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def assert_input_error(result, *fragments):
    assert result.exit_code == 2, (result.exit_code, result.output)
    assert result.stderr.startswith("Error: ")
    assert len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert "Traceback" not in result.output
    for fragment in fragments:
        assert fragment in result.stderr, result.stderr


def parameter(key: str, distribution: str, **values) -> str:
    lines = ["[[ensemble.parameters]]", f'key = "{key}"', f'distribution = "{distribution}"']
    lines += [f"{k} = {json.dumps(v)}" for k, v in values.items()]
    return "\n".join(lines) + "\n"


def test_resolved_ensemble_fills_the_defaults(tmp_path):
    path = write_case(tmp_path, ensemble_text())
    spec = load_ensemble(path)
    data = spec.to_dict()
    assert data["base"] == str(tmp_path.resolve() / "scenario.toml")
    assert data["sampling"] == "latin-hypercube"
    assert data["output"] == {"depth_thresholds_m": [0.1, 0.5, 1.0, 2.0],
                              "quantiles": [0.05, 0.5, 0.95]}
    assert data["parameters"] == [{"key": "initial_water[0].level_m",
                                   "distribution": "uniform", "low": 101.5, "high": 103.5,
                                   "mode": "value"}]
    assert spec.output_directory == tmp_path.resolve() / "out" / "tiny"


def test_triangular_peak_beside_mode_factor(tmp_path):
    """The triangle's mode is spelled ``peak`` where ``mode = "factor"`` takes the key."""
    text = ensemble_text(parameter("terrain.manning", "triangular", low=0.5, peak=1.0,
                                   high=2.0, mode="factor"))
    p = load_ensemble(write_case(tmp_path, text)).parameters[0]
    assert (p.mode.value, p.distribution.low, p.distribution.mode, p.distribution.high) == (
        "factor", 0.5, 1.0, 2.0)


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        (ensemble_text(header="colour = 1"), ["ensemble.toml: ensemble.colour: unknown key"]),
        (ensemble_text(parameter("terrain.manning", "uniform", low=0.02, high=0.04, std=1.0)),
         ["ensemble.parameters[0].std: unknown key", "allowed keys: distribution, high, key"]),
        (ensemble_text(parameter("terrain.manning", "normal", mean=0.03)),
         ["ensemble.parameters[0].std: required key is missing",
          "a normal distribution needs mean and std"]),
        (ensemble_text(parameter("terrain.manning", "uniform", low=0.04, high=0.04)),
         ["ensemble.parameters[0].high: must be > low = 0.04, got 0.04"]),
        (ensemble_text(parameter("terrain.manning", "lognormal", median=0.03, sigma=0.0)),
         ["ensemble.parameters[0].sigma: must be > 0, got 0"]),
        (ensemble_text(parameter("terrain.manning", "triangular", low=1.0, peak=3.0, high=2.0)),
         ["ensemble.parameters[0].peak: must lie between low = 1 and high = 2, got 3"]),
        (ensemble_text(parameter("terrain.manning", "choice", values=[0.02, 0.03],
                                 weights=[1.0, -1.0])),
         ["ensemble.parameters[0].weights[1]: expected a number > 0, got number -1.0"]),
        (ensemble_text(parameter("terrain.manning", "gamma", k=2.0)),
         ["ensemble.parameters[0].distribution: expected one of 'uniform'"]),
        (ensemble_text(LEVEL + LEVEL),
         ["ensemble.parameters[1].key: initial_water[0].level_m is sampled twice"]),
        (ensemble_text(header="sampling = \"sobol\""),
         ["ensemble.sampling: expected one of 'latin-hypercube', 'monte-carlo'"]),
        (ensemble_text().replace("seed = 3\n", ""), ["ensemble.seed: required key is missing"]),
        (ensemble_text(header="[ensemble.output]\nquantiles = [0.5, 1.5]"),
         ["ensemble.output.quantiles[1]: expected a number > 0 and < 1, got number 1.5"]),
    ],
)
def test_bad_ensemble_file_names_the_key(tmp_path, text, fragments):
    assert_input_error(invoke("ensemble", write_case(tmp_path, text)), *fragments)


@pytest.mark.parametrize(
    ("param", "fragments"),
    [
        (parameter("inflows[0].breach.average_width_m", "uniform", low=20.0, high=40.0),
         ["ensemble.parameters[0].key: inflows[0].breach.average_width_m: the base scenario "
          "has no inflows"]),
        (parameter("terrain.colour", "uniform", low=1.0, high=2.0),
         ["ensemble.parameters[0].key: terrain.colour: the scenario has no key terrain.colour"]),
        (parameter("initial_water[2].level_m", "uniform", low=101.0, high=102.0),
         ["the base scenario has no initial_water[2] (initial_water has 1 entry)"]),
        (parameter("numerics", "uniform", low=1.0, high=2.0),
         ["ensemble.parameters[0].key: numerics: numerics is a table, not a value"]),
        (parameter("output.resolution_m", "uniform", low=5.0, high=20.0),
         ["ensemble.parameters[0].key: output.resolution_m cannot be sampled"]),
        (parameter("terrain.edges", "uniform", low=0.5, high=1.5, mode="factor"),
         ['ensemble.parameters[0].mode: mode = "factor" needs a number or a raster at '
          "terrain.edges", "the base scenario has 'closed'"]),
        (parameter("terrain.manning", "choice", values=[1.0, "two"], mode="factor"),
         ['ensemble.parameters[0].values[1]: mode = "factor" needs numbers, got \'two\'']),
    ],
)
def test_key_path_the_scenario_lacks(tmp_path, param, fragments):
    assert_input_error(invoke("ensemble", write_case(tmp_path, ensemble_text(param))),
                       *fragments)


def test_sampled_value_the_scenario_refuses(tmp_path):
    """A normal Manning n of mean 0.03 and std 0.03 draws negative values for some of 16
    members: the first such member is named with its value and the scenario's own message."""
    text = ensemble_text(parameter("terrain.manning", "normal", mean=0.03, std=0.03),
                         members=16)
    result = invoke("ensemble", write_case(tmp_path, text))
    assert_input_error(result, "ensemble.toml: ensemble.parameters[0]: terrain.manning = -",
                       "is refused by the base scenario: scenario.toml: terrain.manning: "
                       "must be > 0, got -")
    assert not (tmp_path / "out").exists()


def test_values_refused_together_name_the_member(tmp_path):
    """Each value alone is valid; together they break refine_area_min < refine_area_max / 2."""
    text = ensemble_text(parameter("numerics.refine_area_max", "choice", values=[1.9])
                         + parameter("numerics.refine_area_min", "choice", values=[0.96]))
    assert_input_error(
        invoke("ensemble", write_case(tmp_path, text)),
        "ensemble.toml: member m0000: the base scenario refuses its sampled values together "
        "(numerics.refine_area_max = 1.9; numerics.refine_area_min = 0.96): scenario.toml: "
        "numerics.refine_area_min: must be below refine_area_max / 2 = 0.95")


def test_factor_value_named_with_the_base(tmp_path):
    """A factor's message gives the base value, the factor and the product."""
    text = ensemble_text(parameter("numerics.cfl", "choice", values=[4.0], mode="factor"))
    assert_input_error(invoke("ensemble", write_case(tmp_path, text)),
                       "ensemble.parameters[0]: numerics.cfl = 0.3 x 4.0 = 1.2 (member m0000) "
                       "is refused by the base scenario: scenario.toml: numerics.cfl: must be "
                       "<= 1, got 1.2")


def test_existing_ensemble_folder_needs_resume_or_overwrite(tmp_path):
    path = write_case(tmp_path, ensemble_text())
    out = tmp_path / "out" / "tiny"
    out.mkdir(parents=True)
    (out / "ensemble.json").write_text("{}")
    assert_input_error(invoke("ensemble", path),
                       "already holds an ensemble (ensemble.json); pass --resume")
    assert_input_error(invoke("ensemble", path, "--resume", "--overwrite"),
                       "give one of them")


def test_folder_with_other_files_is_refused(tmp_path):
    path = write_case(tmp_path, ensemble_text())
    other = tmp_path / "elsewhere"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    assert_input_error(invoke("ensemble", path, "-o", other),
                       "is not empty and holds no ensemble")
    assert (other / "notes.txt").read_text() == "mine"


def test_missing_dask_says_how_to_install(tmp_path, monkeypatch):
    path = write_case(tmp_path, ensemble_text())
    monkeypatch.setitem(sys.modules, "distributed", None)
    assert_input_error(invoke("ensemble", path),
                       "floodsph ensemble needs dask.distributed",
                       "pip install 'floodsph[ensemble]'")


def test_ensemble_help_imports_nothing_heavy():
    code = (
        "import sys\n"
        "from floodsph.cli.main import cli\n"
        "try:\n"
        "    cli(['ensemble', '--help'])\n"
        "except SystemExit:\n"
        "    pass\n"
        "heavy = ('numba', 'rasterio', 'xarray', 'scipy', 'dask', 'distributed', 'matplotlib')\n"
        "print('HEAVY', [m for m in heavy if m in sys.modules])\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert "HEAVY []" in out.stdout
    assert "--threads-per-worker" in out.stdout and "--scheduler" in out.stdout
