"""Run-folder safety and the ending of every run (docs/run-folder.md, "Safety rules").

Each test is a hostile but ordinary situation: an output folder that holds the user's files,
a replacement that fails, two runs into one folder, a signal from a batch scheduler, a full
disk. Each ends with one message, nothing the user had is lost, and nothing half-written
stands under a contract name.
"""

from __future__ import annotations

import errno
import json
import os
import signal
import stat
import subprocess
import sys
import time

import filelock
import pytest
from click.testing import CliRunner
from conftest import BASE_SCENARIO

from floodsph.cli.main import cli
from floodsph.run.pipeline import run_scenario
from floodsph.scenario.reader import load_scenario
from floodsph.simulation.schedules import IterationInterval


def invoke(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def assert_one_error(result, status, *fragments):
    assert result.exit_code == status, (result.exit_code, result.output)
    # stderr is not a terminal here: the progress lines of a run that got that far come first
    lines = [line for line in result.stderr.strip().splitlines()
             if not line.startswith("progress: ")]
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.stderr
    assert "Traceback" not in result.output
    for fragment in fragments:
        assert fragment in result.stderr


def manifest(folder):
    return json.loads((folder / "run.json").read_text())


def contract_names(folder):
    return sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))


def signal_at(step, signum=signal.SIGTERM):
    sent = []

    def callback(sim):
        if sim.model.steps >= step and not sent:
            sent.append(step)
            os.kill(os.getpid(), signum)

    return callback, IterationInterval(1)


def raise_at(step, exc):
    def callback(sim):
        if sim.model.steps >= step:
            raise exc

    return callback, IterationInterval(1)


# ---- what a run may write ---------------------------------------------------------------------


def test_output_into_the_scenario_folder_never_overwrites_an_input(write_scenario, tmp_path):
    """``-o .`` beside an input called gauges.csv: refused, the input intact."""
    gauges = "id,x,y\ng1,500050,4000100\n"
    (tmp_path / "gauges.csv").write_text(gauges)
    path = write_scenario(BASE_SCENARIO + '\n[gauges]\nfile = "gauges.csv"\n')
    result = invoke("run", path, "-o", tmp_path, "--max-steps", "1")
    assert_one_error(result, 2, "gauges.csv", "input file")
    assert (tmp_path / "gauges.csv").read_text() == gauges
    assert not (tmp_path / "run.json").exists()


def test_a_folder_with_the_users_files_is_refused_and_left_alone(scenario_file, tmp_path):
    out = tmp_path / "results"
    out.mkdir()
    (out / "notes.txt").write_text("my notes")
    (out / "max_depth.tif").write_text("not floodsph's: there is no run.json")
    result = invoke("run", scenario_file, "-o", out, "--max-steps", "1")
    assert_one_error(result, 2, "not a floodsph run's", "max_depth.tif", "notes.txt")
    assert sorted(os.listdir(out)) == ["max_depth.tif", "notes.txt"]
    assert (out / "notes.txt").read_text() == "my notes"


def test_check_reports_the_same_folder_problems_before_any_run(scenario_file, tmp_path):
    (tmp_path / "taken").write_text("a file")
    assert_one_error(invoke("check", scenario_file, "-o", tmp_path / "taken"), 2,
                     "is a file")
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "report.docx").write_text("x")
    assert_one_error(invoke("check", scenario_file, "-o", tmp_path / "full"), 2,
                     "report.docx")


@pytest.mark.parametrize(("name", "fragment"), [("a\x00b", "NUL"), ("x" * 300, "longer")])
def test_impossible_folder_names_are_one_message(scenario_file, tmp_path, name, fragment):
    assert_one_error(invoke("run", scenario_file, "-o", f"{tmp_path}/{name}"), 2, fragment)


def test_an_output_folder_that_is_a_file_is_refused(scenario_file, tmp_path):
    (tmp_path / "out.txt").write_text("keep me")
    assert_one_error(invoke("run", scenario_file, "-o", tmp_path / "out.txt"), 2, "is a file")
    assert (tmp_path / "out.txt").read_text() == "keep me"


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_parent_is_refused(scenario_file, tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        assert_one_error(invoke("run", scenario_file, "-o", locked / "run"), 2, "not writable")
    finally:
        locked.chmod(stat.S_IRWXU)


def test_outputs_are_group_readable_and_run_json_is_written_last(scenario_file, tmp_path):
    out = tmp_path / "run"
    old = os.umask(0o022)
    try:
        result = invoke("-q", "run", scenario_file, "-o", out, "--max-steps", "2")
    finally:
        os.umask(old)
    assert result.exit_code == 0, result.output
    for path in out.iterdir():
        if path.is_file() and not path.name.startswith("."):
            assert path.stat().st_mode & stat.S_IRGRP, path.name
    outputs = [p for p in out.iterdir() if p.is_file() and not p.name.startswith(".")
               and p.name != "floodsph.log"]  # the log is appended to the very end
    newest = max(outputs, key=lambda p: p.stat().st_mtime_ns)
    assert newest.name == "run.json"
    assert manifest(out)["status"] == "stopped"  # --max-steps before the end time


# ---- replacing a run --------------------------------------------------------------------------


def test_a_failed_replacement_leaves_the_completed_run_untouched(scenario_file, tmp_path):
    out = tmp_path / "run"
    sc = load_scenario(scenario_file)
    first = run_scenario(sc, out, progress=False)
    assert first["status"] == "completed"
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()
              and not p.name.startswith(".")}
    with pytest.raises(RuntimeError, match="boom"):
        run_scenario(sc, out, progress=False, overwrite=True,
                     callbacks=[raise_at(3, RuntimeError("boom"))])
    after = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()
             and not p.name.startswith(".")}
    assert after == before
    assert manifest(out)["status"] == "completed"
    assert manifest(out / ".floodsph-new")["status"] == "failed"
    assert manifest(out / ".floodsph-new")["error"] == "RuntimeError: boom"


def test_an_interrupted_replacement_keeps_the_old_maps_and_resumes_into_place(write_scenario,
                                                                           tmp_path):
    path = write_scenario(BASE_SCENARIO.replace("mass_balance_interval_s = 5.0",
                                                "mass_balance_interval_s = 5.0\n"
                                                "checkpoint_interval_s = 5.0"))
    sc = load_scenario(path)
    out = tmp_path / "run"
    run_scenario(sc, out, progress=False)
    old_map = (out / "max_depth.tif").read_bytes()
    old_started = manifest(out)["started"]
    stopped = run_scenario(sc, out, progress=False, overwrite=True,
                           callbacks=[signal_at(4, signal.SIGINT)])
    assert stopped["status"] == "interrupted" and "SIGINT" in stopped["error"]
    assert (out / "max_depth.tif").read_bytes() == old_map
    assert manifest(out)["started"] == old_started
    # Without --resume or --overwrite the folder is now refused (it holds a checkpoint too).
    assert_one_error(invoke("run", path, "-o", out), 2, "--resume")
    resumed = run_scenario(sc, out, progress=False, resume=True,
                           callbacks=[signal_at(10**9)])
    assert resumed["status"] == "completed"
    assert manifest(out)["resumed_from"] == [stopped["sim_time_s"]]
    assert not (out / ".floodsph-new").exists()


def test_a_completed_replacement_is_swapped_in_whole(scenario_file, tmp_path):
    out = tmp_path / "run"
    assert invoke("-q", "run", scenario_file, "-o", out, "--max-steps", "2").exit_code == 0
    result = invoke("-q", "run", scenario_file, "-o", out, "--overwrite")
    assert result.exit_code == 0, result.output
    m = manifest(out)
    assert m["status"] == "completed" and m["steps"] > 2
    assert not (out / ".floodsph-new").exists()
    assert "max_depth.tif" in contract_names(out)


def test_overwrite_and_resume_together_are_refused(scenario_file, tmp_path):
    assert_one_error(invoke("run", scenario_file, "-o", tmp_path / "r", "--overwrite",
                            "--resume"), 2, "exclude each other")


# ---- two writers ------------------------------------------------------------------------------


def test_a_second_run_into_a_locked_folder_is_refused(scenario_file, tmp_path):
    out = tmp_path / "run"
    out.mkdir()
    holder = filelock.FileLock(out / ".floodsph.lock")  # as a run in another process holds it
    with holder:
        result = invoke("run", scenario_file, "-o", out, "--max-steps", "1")
    assert_one_error(result, 2, "another floodsph run is writing")
    assert not (out / "run.json").exists()
    # The lock dies with its holder: the folder is free again at once.
    assert invoke("-q", "run", scenario_file, "-o", out, "--max-steps", "1").exit_code == 0


def test_the_lock_works_where_fcntl_does_not_exist(tmp_path):
    # Windows has no fcntl: the run folder's lock must not need it.
    code = f"""
import sys
sys.modules["fcntl"] = None  # importing it now fails, as on Windows
from floodsph.errors import InputError
from floodsph.run.folder import RunFolder
first = RunFolder({str(tmp_path / "run")!r})
first.open()
try:
    RunFolder({str(tmp_path / "run")!r}).open()
except InputError as exc:
    print("refused:", exc)
first.close()
RunFolder({str(tmp_path / "run")!r}).open()
print("free again")
"""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert "refused:" in done.stdout and "another floodsph run is writing" in done.stdout
    assert done.stdout.rstrip().endswith("free again")


# ---- every ending recorded --------------------------------------------------------------------


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_each_stop_signal_writes_a_checkpoint_then_interrupted(scenario_file, tmp_path,
                                                                signum):
    out = tmp_path / "run"
    m = run_scenario(load_scenario(scenario_file), out, progress=False,
                     callbacks=[signal_at(3, signum)])
    assert m["status"] == "interrupted"
    assert signal.Signals(signum).name in m["error"]
    assert (out / "checkpoint" / "state.npz").is_file()
    assert manifest(out)["checkpoint_time_s"] == m["sim_time_s"] > 0
    assert "max_depth.tif" not in contract_names(out)


def test_sigterm_from_outside_ends_the_command_with_status_130(write_scenario, tmp_path):
    """A real ``floodsph run`` process, sent SIGTERM while it steps, as a scheduler does."""
    path = write_scenario(BASE_SCENARIO.replace("end_time_s = 20.0", "end_time_s = 1e6"))
    out = tmp_path / "run"
    proc = subprocess.Popen([sys.executable, "-m", "floodsph", "-q", "run", str(path),
                             "-o", str(out)], stderr=subprocess.PIPE, text=True)
    log = out / "floodsph.log"
    deadline = time.monotonic() + 600
    while not (log.exists() and "simulation started" in log.read_text()):
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.2)
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130
    assert "SIGTERM" in stderr and "--resume" in stderr
    m = manifest(out)
    assert m["status"] == "interrupted" and m["checkpoint_time_s"] > 0
    assert (out / "checkpoint" / "state.npz").is_file()


def test_a_full_disk_while_writing_the_maps_fails_cleanly(scenario_file, tmp_path,
                                                          monkeypatch):
    """ENOSPC in the middle of a GeoTIFF: status failed with the one message, no partial
    file under any name, nothing but the log and run.json."""
    import floodsph.output.geotiff as geotiff

    real = geotiff.write_geotiff
    calls = []

    def full_disk(path, *args, **kwargs):
        calls.append(path)
        if len(calls) == 3:
            path.with_name(path.name + ".part").write_bytes(b"half a file")
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        return real(path, *args, **kwargs)

    monkeypatch.setattr(geotiff, "write_geotiff", full_disk)
    out = tmp_path / "run"
    result = invoke("run", scenario_file, "-o", out)
    assert_one_error(result, 1, "No space left on device")
    m = manifest(out)
    assert m["status"] == "failed" and "No space left on device" in m["error"]
    assert not [n for n in contract_names(out) if n.endswith((".tif", ".nc", ".csv", ".part"))]
    assert not [n for n in os.listdir(out) if n.startswith(".tmp-") or n.endswith(".part")]


def test_a_failed_run_is_not_protected_and_its_leftovers_are_cleared(scenario_file, tmp_path):
    out = tmp_path / "run"
    with pytest.raises(RuntimeError):
        run_scenario(load_scenario(scenario_file), out, progress=False,
                     callbacks=[raise_at(2, RuntimeError("boom"))])
    (out / "max_speed.tif.part").write_bytes(b"left by a killed writer")
    (out / ".tmp-run.json").write_bytes(b"{")
    result = invoke("-q", "run", scenario_file, "-o", out, "--max-steps", "1")
    assert result.exit_code == 0, result.output
    assert not (out / "max_speed.tif.part").exists() and not (out / ".tmp-run.json").exists()
    assert manifest(out)["status"] == "stopped"


def test_input_warnings_are_recorded_in_run_json(write_scenario, tmp_path):
    """A Manning n of 0.5 is possible (dense vegetation, debris) but suspicious: the run goes
    on, and run.json records the warning the terminal showed."""
    path = write_scenario(BASE_SCENARIO.replace("manning = 0.03", "manning = 0.5"))
    result = invoke("run", path, "-o", tmp_path / "run", "--max-steps", "1")
    assert result.exit_code == 0, result.output
    (warning,) = manifest(tmp_path / "run")["warnings"]
    assert "terrain.manning" in warning and "0.5" in warning
    assert warning in result.stderr
