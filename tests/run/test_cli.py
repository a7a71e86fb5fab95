"""The command line: bad inputs (exit 2, one message), check's summary, run folder, run.json."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import BASE_SCENARIO, NX, NY, RESERVOIR_VOLUME_M3, X0, Y0, write_geotiff

from floodsph._version import __version__
from floodsph.cli.main import cli
from floodsph.simulation.schedules import IterationInterval

INFLOW = """
[[inflows]]
line = [[{x1}, {y1}], [{x2}, {y2}]]
hydrograph = "q.csv"
"""


def invoke(*args, env=None):
    return CliRunner().invoke(cli, [str(a) for a in args], env=env)


def assert_input_error(result, *fragments):
    assert result.exit_code == 2, (result.exit_code, result.output)
    assert result.stderr.startswith("Error: ")
    assert len(result.stderr.strip().splitlines()) == 1
    assert "Traceback" not in result.output
    for fragment in fragments:
        assert fragment in result.stderr


def test_version():
    result = invoke("--version")
    assert result.exit_code == 0
    assert result.output.strip() == f"floodsph {__version__}"


def test_help_imports_no_heavy_modules():
    code = (
        "import sys\n"
        "from floodsph.cli.main import cli\n"
        "try:\n"
        "    cli(['--help'])\n"
        "except SystemExit:\n"
        "    pass\n"
        "heavy = [m for m in ('numba', 'rasterio', 'xarray', 'scipy') if m in sys.modules]\n"
        "print('HEAVY', heavy)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "HEAVY []" in out.stdout
    assert "run" in out.stdout and "check" in out.stdout


# ---- the bad-input battery (check and run) ------------------------------------------------------


@pytest.mark.parametrize("command", ["check", "run"])
def test_missing_scenario_file(tmp_path, command):
    result = invoke(command, tmp_path / "nope.toml")
    assert_input_error(result, "nope.toml: scenario file not found")


def test_invalid_toml_gives_line(write_scenario):
    text = BASE_SCENARIO.replace("cfl = 0.3", "cfl = 0.3.1")
    line = text.splitlines().index("cfl = 0.3.1") + 1
    path = write_scenario(text)
    assert_input_error(invoke("check", path), "scenario.toml: invalid TOML", f"(at line {line}, ")


@pytest.mark.parametrize(
    ("change", "fragment"),
    [
        (("[scenario]", "colour = 1\n[scenario]"), "scenario.toml: colour: unknown key"),
        (("cfl = 0.3", "cfl = 0.3\nspeed = 2"), "scenario.toml: numerics.speed: unknown key"),
        (("end_time_s = 20.0", 'end_time_s = "ten"'),
         "scenario.end_time_s: expected a number, got string 'ten'"),
        (("end_time_s = 20.0", "end_time_s = -1"), "scenario.end_time_s: must be > 0, got -1"),
        (("cfl = 0.3", "cfl = 2"), "numerics.cfl: must be <= 1, got 2"),
        (('dem = "dem.tif"', 'dem = "missing.tif"'), "terrain.dem: file not found: "),
        (("[[initial_water]]\nlevel_m = 100.0\npolygon = [",
          f"[[initial_water]]\nlevel_m = 100.0\npolygon = [[{X0}, {Y0}], [{X0 + 1}, {Y0 + 1}], "
          f"[{X0 + 2}, {Y0 + 2}]]\n_unused = ["),
         None),
    ],
)
def test_bad_scenario_values(write_scenario, change, fragment):
    text = BASE_SCENARIO.replace(*change)
    assert text != BASE_SCENARIO
    if fragment is None:  # a degenerate (collinear) reservoir polygon
        text = BASE_SCENARIO.replace(
            BASE_SCENARIO[BASE_SCENARIO.index("polygon = ["):BASE_SCENARIO.index("\n\n[numerics]")],
            f"polygon = [[{X0}, {Y0}], [{X0 + 10}, {Y0 + 10}], [{X0 + 20}, {Y0 + 20}]]",
        )
        fragment = "initial_water[0].polygon: polygon encloses no area"
    for command in ("check", "run"):
        assert_input_error(invoke(command, write_scenario(text)), fragment)


def test_corrupt_dem(write_scenario, tmp_path):
    (tmp_path / "broken.tif").write_text("this is not a GeoTIFF\n")
    path = write_scenario(BASE_SCENARIO.replace('dem = "dem.tif"', 'dem = "broken.tif"'))
    assert_input_error(invoke("check", path), "broken.tif")


def test_all_nodata_dem(write_scenario, tmp_path):
    write_geotiff(tmp_path / "empty.tif", np.full((NY, NX), -9999.0))
    path = write_scenario(BASE_SCENARIO.replace('dem = "dem.tif"', 'dem = "empty.tif"'))
    assert_input_error(invoke("check", path), "empty.tif", "nodata")


def write_hydrograph(tmp_path, rows):
    lines = "".join(f"{a},{b}\n" for a, b in rows)
    (tmp_path / "q.csv").write_text("time_s,discharge_m3s\n" + lines)


def test_inflow_line_off_the_dem(write_scenario, tmp_path):
    write_hydrograph(tmp_path, [(0, 0), (10, 5)])
    inflow = INFLOW.format(x1=X0 + 150, y1=Y0 + 50, x2=X0 + 150, y2=Y0 + 900)
    path = write_scenario(BASE_SCENARIO + inflow)
    assert_input_error(
        invoke("check", path),
        f"scenario.toml: inflows[0].line: point [{X0 + 150:.10g}, {Y0 + 900:.10g}] is outside "
        f"the DEM extent [{X0:.10g}, {Y0:.10g}, {X0 + 400:.10g}, {Y0 + 200:.10g}] in "
        "EPSG:32632 (WGS 84 / UTM zone 32N), the DEM file's CRS",
    )


@pytest.mark.parametrize(
    ("rows", "fragment"),
    [
        ([(0, 0), (10, 5), (5, 1)], "line 4: time_s = 5 is not greater than the previous time 10"),
        ([(0, 0), (10, -5)], "line 3: discharge_m3s = -5 is negative"),
    ],
)
def test_bad_hydrograph(write_scenario, tmp_path, rows, fragment):
    write_hydrograph(tmp_path, rows)
    inflow = INFLOW.format(x1=X0 + 150, y1=Y0 + 50, x2=X0 + 150, y2=Y0 + 150)
    path = write_scenario(BASE_SCENARIO + inflow)
    assert_input_error(invoke("check", path), "scenario.toml: inflows[0].hydrograph: ", fragment)


@pytest.mark.parametrize("command", ["check", "run"])
def test_too_large_for_memory(scenario_file, command):
    result = invoke(command, scenario_file, env={"FLOODSPH_MEMORY_LIMIT_BYTES": "1000"})
    assert_input_error(result, "the run needs an estimated", "FLOODSPH_MEMORY_LIMIT_BYTES")
    assert not (scenario_file.parent / "out").exists()


def test_debug_shows_the_exception(tmp_path):
    result = invoke("--debug", "check", tmp_path / "nope.toml")
    assert result.exit_code != 0
    assert type(result.exception).__name__ == "InputError"


# ---- check ---------------------------------------------------------------------------------------


def test_check_reports_what_seeding_gives(scenario_file):
    from floodsph.inputs.dem import load_terrain
    from floodsph.inputs.initial_water import depth_from_level, seed_particles

    terrain = load_terrain(scenario_file.parent / "dem.tif", manning=0.03)
    polygon = np.array([[0, 0], [400, 0], [400, 200], [0, 200]], dtype=float)
    seeded = seed_particles(terrain, depth_from_level(terrain, 100.0, polygon), 10.0, 1.3)

    result = invoke("check", scenario_file)
    assert result.exit_code == 0, result.output
    lines = dict(line.split(":", 1) for line in result.output.splitlines() if ":" in line)
    assert int(lines["Particles"]) == seeded.n == 10 * NY  # one per basin cell
    assert lines["Initial water"].split()[0] == f"{RESERVOIR_VOLUME_M3:g}"
    assert "EPSG:32632" in lines["CRS"]
    assert "0.400 km x 0.200 km, 40 x 20 cells of 10 m x 10 m" in lines["Domain"]


def test_check_integrates_the_hydrograph(write_scenario, tmp_path):
    write_hydrograph(tmp_path, [(0, 0), (10, 6), (30, 0)])  # 30 + 45 = 75 m3 up to t = 20 s
    inflow = INFLOW.format(x1=X0 + 150, y1=Y0 + 50, x2=X0 + 150, y2=Y0 + 150)
    # The floor is level there: a run (and so check) needs the direction.
    result = invoke("check", write_scenario(BASE_SCENARIO + inflow + "direction = [1, 0]\n"))
    assert result.exit_code == 0, result.output
    assert "Inflow volume:   75 m3 up to the end time (1 inflows)" in result.output


# ---- run -----------------------------------------------------------------------------------------


def read_run_json(folder):
    return json.loads((folder / "run.json").read_text())


def test_run_writes_manifest_and_mass_balance(scenario_file):
    folder = scenario_file.parent / "out" / "valley"
    result = invoke("-q", "run", scenario_file, "--max-steps", "3")
    assert result.exit_code == 0, result.output
    manifest = read_run_json(folder)
    for key in ("floodsph_version", "scenario", "status", "sim_time_s", "wall_time_s", "steps",
                "particles_initial", "particles_max", "particles_final", "splits", "merges",
                "mass_error_rel", "threads"):
        assert key in manifest
    assert manifest["status"] == "stopped" and manifest["end_time_reached"] is False
    assert manifest["steps"] == 3
    assert manifest["particles_initial"] == 10 * NY
    assert manifest["scenario"]["scenario"]["name"] == "valley"
    with open(folder / "mass_balance.csv") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == ["time_s", "volume_domain_m3", "volume_in_m3", "volume_out_m3",
                             "error_m3", "error_rel"]
    # Closed box, no inflow: the volume is the reservoir's and is conserved.
    assert float(rows[0]["volume_domain_m3"]) == pytest.approx(RESERVOIR_VOLUME_M3, rel=1e-12)
    assert all(float(r["error_rel"]) < 1e-12 for r in rows)
    assert (folder / "scenario.resolved.toml").exists()
    # Maps of a completed run, on the DEM's grid and CRS; the basin holds 2 m of water and
    # the far east of the valley (> 100 m from the reservoir after 3 steps) stayed dry.
    import rasterio

    with rasterio.open(folder / "max_depth.tif") as src:
        assert src.crs.to_epsg() == 32632
        assert (src.transform.c, src.transform.f) == (X0, Y0 + NY * 10.0)
        max_depth = src.read(1)
    assert max_depth[NY // 2, 5] == pytest.approx(2.0, rel=0.05)
    assert np.isnan(max_depth[:, 30:]).all()
    assert (folder / "flood_maps.nc").exists()
    assert "run folder" in (folder / "floodsph.log").read_text()

    again = invoke("run", scenario_file, "--max-steps", "1")
    assert_input_error(again, "already holds a stopped run", "--overwrite")
    again = invoke("-q", "run", scenario_file, "--max-steps", "1", "--overwrite")
    assert again.exit_code == 0
    assert read_run_json(folder)["steps"] == 1


def raise_at_step(exc, step):
    def callback(sim):
        if sim.model.steps >= step:
            raise exc

    return callback, IterationInterval(1)


def test_seeds_settled_at_an_oblique_wall_are_in_run_json_and_the_mass_balance(
        write_scenario, tmp_path):
    """A flat 2 m lake over the whole DEM, cut in two by a wall at about 56 degrees, under the
    variational momentum: the seeds along the wall are settled and their masses matched
    (``floodsph.walls.seeding``; the balanced momentum needs no settling). run.json reports
    how many and the volume change, and the mass balance starts from the adjusted volume, so
    its error stays at round-off."""
    path = write_scenario(BASE_SCENARIO.replace(
        "cfl = 0.3", 'cfl = 0.3\nmomentum = "variational"') + f"""
[[walls]]
polyline = [[{X0 + 100.0}, {Y0 - 10.0}], [{X0 + 250.0}, {Y0 + 210.0}]]
""")
    write_geotiff(tmp_path / "dem.tif", np.full((NY, NX), 98.0))
    result = invoke("-q", "run", path, "--max-steps", "3")
    assert result.exit_code == 0, result.output
    folder = path.parent / "out" / "valley"
    manifest = read_run_json(folder)
    lake = NX * NY * 100.0 * 2.0
    assert manifest["seeds_settled"] > 10
    assert 0.0 < abs(manifest["volume_seed_adjustment_m3"]) < 0.01 * lake
    assert manifest["volume_initial_m3"] == pytest.approx(lake, rel=1e-12)
    with open(folder / "mass_balance.csv") as f:
        rows = list(csv.DictReader(f))
    assert float(rows[0]["volume_domain_m3"]) == pytest.approx(
        lake + manifest["volume_seed_adjustment_m3"], rel=1e-12)
    assert all(float(r["error_rel"]) < 1e-12 for r in rows)


@pytest.mark.parametrize(
    ("exc", "status", "error"),
    [(KeyboardInterrupt(), "interrupted", "interrupted by the user (KeyboardInterrupt)"),
     (RuntimeError("boom"), "failed", "RuntimeError: boom")],
)
def test_run_json_records_how_the_run_ended(scenario_file, tmp_path, exc, status, error):
    from floodsph.run.pipeline import run_scenario
    from floodsph.scenario.reader import load_scenario

    out = tmp_path / "run"
    with pytest.raises(type(exc)):
        run_scenario(load_scenario(scenario_file), out_dir=out, progress=False,
                     callbacks=[raise_at_step(exc, 2)])
    manifest = read_run_json(out)
    assert manifest["status"] == status
    assert manifest["error"] == error
    assert manifest["steps"] == 2
    assert not list(out.glob("*.tif")) and not (out / "flood_maps.nc").exists()
    # An unfinished run is not protected: it can be rerun without --overwrite.
    assert invoke("-q", "run", scenario_file, "-o", out, "--max-steps", "1").exit_code == 0


def test_progress_reaches_a_piped_stderr_and_the_log_every_tenth_of_the_time(scenario_file):
    """stderr is not a terminal here (no progress bar): a line per 10 % of the 20 s."""
    result = invoke("run", scenario_file)
    assert result.exit_code == 0, result.output
    lines = [line for line in result.stderr.splitlines() if line.startswith("progress: ")]
    percents = [int(line.split("(")[1].split(" %")[0]) for line in lines]
    # One line at the first step past each tenth (a step is about 3 % of the time here).
    assert [p // 10 for p in percents] == list(range(1, 11)), percents
    assert "of 20 s" in lines[0] and "particles" in lines[0] and "to go" in lines[0]
    log = (scenario_file.parent / "out" / "valley" / "floodsph.log").read_text()
    assert [line.split("INFO floodsph.simulation.probes: ")[1] for line in log.splitlines()
            if "progress: " in line] == lines
    quiet = invoke("-q", "run", scenario_file, "--overwrite")
    assert "progress: " not in quiet.stderr


def test_progress_lines_come_every_minute_of_wall_time_between_tenths():
    from types import SimpleNamespace

    from floodsph.simulation.probes import ProgressLines

    lines = ProgressLines(1000.0, to_stderr=False)
    printed = []
    for t, wall in [(5.0, 30.0), (6.0, 61.0), (7.0, 100.0), (8.0, 122.0), (100.0, 125.0),
                    (150.0, 126.0)]:
        sim = SimpleNamespace(model=SimpleNamespace(t=t, steps=1), wall_time=wall,
                              end_time=1000.0, last_dt=0.1, n=10)
        before = lines.last_wall
        lines(sim)
        printed.append(lines.last_wall != before)
    # 61 s and 122 s of wall time, then 10 % of the time; 15 % waits for 20 %.
    assert printed == [False, True, False, True, True, False]
