"""``floodsph ensemble`` stopped by a signal, as a batch scheduler or a terminal stops it.

The command runs in its own process group on the tiny dam break (``ensemble_cases``) with a
long end time, one worker and ``NUMBA_NUM_THREADS=1`` in its environment. Once the first
member's ``run.json`` says ``running``, the signal goes to the main process (SIGTERM: a
scheduler's ``kill``) or to the whole group (SIGINT: Ctrl-C at the terminal, SIGHUP: the
terminal closed). Every ending must be recorded: the ensemble and the running member
``interrupted``, ``samples.csv`` written, exit status 130, one line on stderr without a
traceback or a leaked-semaphore warning.
"""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time

import pytest
from ensemble_cases import DAM_BREAK, ensemble_text, write_case

from floodsph.ensemble.engine import plan_workers, thread_budget

LONG = DAM_BREAK.replace("end_time_s = 20.0", "end_time_s = 5000.0")


def wait_for_running(members, limit_s=240.0) -> None:
    deadline = time.monotonic() + limit_s
    while time.monotonic() < deadline:
        for run_json in members.glob("m*/run.json"):
            if '"running"' in run_json.read_text():
                return
        time.sleep(0.5)
    raise AssertionError("no member started")


@pytest.mark.parametrize(("signum", "to_group"), [(signal.SIGTERM, False),
                                                  (signal.SIGINT, True),
                                                  (signal.SIGHUP, True)])
def test_a_signal_ends_the_ensemble_and_its_running_member_interrupted(tmp_path, signum,
                                                                     to_group):
    path = write_case(tmp_path, ensemble_text(members=2), scenario=LONG)
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    process = subprocess.Popen([sys.executable, "-m", "floodsph", "ensemble", str(path),
                                "--workers", "1"], cwd=tmp_path, env=env,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)
    out = tmp_path / "out" / "tiny"
    try:
        wait_for_running(out / "members")
        time.sleep(1.0)
        if to_group:
            os.killpg(process.pid, signum)
        else:
            process.send_signal(signum)
        _, stderr = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
    name = signal.Signals(signum).name
    assert process.returncode == 130, stderr
    assert stderr.strip().splitlines()[-1] == f"Interrupted: interrupted by {name}."
    assert "Traceback" not in stderr and "leaked semaphore" not in stderr, stderr
    manifest = json.loads((out / "ensemble.json").read_text())
    assert (manifest["status"], manifest["error"]) == ("interrupted", f"interrupted by {name}")
    assert manifest["members_interrupted"] == 1 and manifest["members_completed"] == 0
    with open(out / "samples.csv", newline="") as f:
        rows = {row["member"]: row for row in csv.DictReader(f)}
    assert [rows[m]["status"] for m in ("m0000", "m0001")] == ["interrupted", "not run"]
    member = json.loads((out / "members" / "m0000" / "run.json").read_text())
    assert member["status"] == "interrupted"
    assert (out / "members" / "m0000" / "checkpoint" / "state.npz").is_file()
    assert member["threads"] == 1  # NUMBA_NUM_THREADS=1 honoured with --workers 1


def test_the_thread_budget_is_the_users_numba_num_threads(monkeypatch):
    monkeypatch.setattr("floodsph.ensemble.engine.machine_cores", lambda: 8)
    monkeypatch.delenv("NUMBA_NUM_THREADS", raising=False)
    assert thread_budget() == 8
    monkeypatch.setenv("NUMBA_NUM_THREADS", "3")
    assert thread_budget() == 3
    plan = plan_workers(4, thread_budget(), 1, None, workers=1)
    assert (plan.workers, plan.threads_per_worker) == (1, 3)
