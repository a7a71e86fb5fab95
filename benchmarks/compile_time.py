"""The first run's compile: how long numba takes to compile floodsph's kernels, kernel by kernel.

A worker process with an empty numba cache (``NUMBA_CACHE_DIR`` set to a new temporary
folder, so nothing is loaded from an earlier run) runs the sample scenario
(``data_samples/valley/scenario.toml``) for ``--steps`` time steps through the public chain
(``floodsph.run.pipeline.run_scenario``), which compiles every kernel a run uses. It listens
to numba's ``"numba:compile"`` event (raised only when a function is actually compiled) and
reports each compiled function's wall time. Functions compiled inside another's compilation
(a helper a kernel calls) are counted within that kernel and also listed on their own, so the
per-function times add up to more than the total.

Writes ``--out`` (default ``docs/compile-time.md``): the command, commit and machine, the total
compile time (the sum over the outermost compilations), and the slowest functions.

    python benchmarks/compile_time.py [--threads 2] [--steps 3] [--out docs/compile-time.md]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import provenance  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
SAMPLE = REPO / "data_samples" / "valley" / "scenario.toml"
LISTED = 15
"""Functions listed on the page, slowest first."""


def worker(steps: int, out: Path) -> None:
    """Run the sample for ``steps`` steps and print one JSON line: the outermost compile
    time [s] and every compiled function's (name, seconds, nested)."""
    from numba.core import event

    from floodsph.run.pipeline import run_scenario
    from floodsph.scenario.reader import load_scenario

    records = []
    open_starts = []

    class Listener(event.Listener):
        def on_start(self, ev):
            open_starts.append(time.perf_counter())

        def on_end(self, ev):
            start = open_starts.pop()
            func = ev.data["dispatcher"].py_func
            records.append({"name": f"{func.__module__}.{func.__qualname__}",
                            "seconds": time.perf_counter() - start,
                            "nested": bool(open_starts)})

    event.register("numba:compile", Listener())
    scenario = load_scenario(SAMPLE)
    run_scenario(scenario, out, progress=False, max_steps=steps)
    outer = sum(r["seconds"] for r in records if not r["nested"])
    print(json.dumps({"compile_s": outer, "functions": records}))


def measure(threads: int, steps: int) -> dict:
    """The worker's result, run with a cold numba cache and ``threads`` numba threads."""
    with tempfile.TemporaryDirectory(prefix="floodsph-compile-") as tmp:
        env = {**os.environ, "NUMBA_CACHE_DIR": str(Path(tmp) / "cache"),
               "NUMBA_NUM_THREADS": str(threads)}
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, __file__, "--worker", "--steps", str(steps),
                               "--run", str(Path(tmp) / "run")],
                              capture_output=True, text=True, env=env, cwd=REPO)
        wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"compile_time: the worker failed:\n{proc.stderr[-3000:]}")
    result = json.loads(proc.stdout.strip().splitlines()[-1])
    result["process_s"] = wall
    return result


def page(result: dict, command: str, load: tuple[float, float], wall: float) -> str:
    """The Markdown report of one measurement."""
    by_name: dict[str, list[float]] = {}
    for r in result["functions"]:
        by_name.setdefault(r["name"], []).append(r["seconds"])
    slowest = sorted(by_name.items(), key=lambda kv: -sum(kv[1]))[:LISTED]
    lines = [
        "# The first run's compile",
        "",
        f"Made by `{command}` at commit `{provenance.commit(REPO)}`; "
        + provenance.machine_note(load, wall, "Times are of this machine and this run.")
        + " `benchmarks/compile_time.py` says how it is measured.",
        "",
        f"A cold compile of the kernels a run of the sample uses: **{result['compile_s']:.0f} s** "
        f"({len(by_name)} functions; the whole first run of {result['process_s']:.0f} s "
        "includes reading the inputs, a few steps and writing the maps).",
        "",
        "| function | compile s | times compiled |",
        "|---|---|---|",
    ]
    lines += [f"| `{name}` | {sum(times):.1f} | {len(times)} |" for name, times in slowest]
    lines += ["", "A function compiled inside another's compilation is counted in both rows.", ""]
    return "\n".join(lines)


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=2, help="numba threads")
    parser.add_argument("--steps", type=int, default=3, help="time steps of the sample")
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "compile-time.md")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--run", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        worker(args.steps, args.run)
        return {}
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    result = measure(args.threads, args.steps)
    wall = time.perf_counter() - t0
    command = "python benchmarks/compile_time.py " + " ".join(argv or sys.argv[1:])
    args.out.write_text(page(result, command.strip(), (load0, os.getloadavg()[0]), wall),
                        encoding="utf-8")
    print(f"compile {result['compile_s']:.1f} s; wrote {args.out}")
    return result


if __name__ == "__main__":
    main()
