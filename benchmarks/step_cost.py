"""The cost of one time step at 1,000 to 64,000 particles, stage by stage.

A Ritter-like dam break (``floodsph.verification.cases.ritter``'s channel: 10 m of still water
over the west half of a closed, flat 2000 m x 100 m channel, dry east half), with one global
time step (a step updates every particle, in any checkout), is seeded at the spacings of
:data:`SIZES` (10, 5, 2.5 and 1.25 m: about 1,000, 4,000, 16,000 and 64,000
particles). Each measurement builds the model afresh, takes ``--warmup`` untimed steps (the
kernels compile there on a first run) and then ``--steps`` timed steps, with the model's
stage timer (``floodsph.model.stage_timer``) adding up the wall time of each stage. Reported per
size: particle-steps/s, ms per step and the stages' share in us per step, medians over
``--repeats``; and a least-squares fit of the time per step, t = fixed + per_particle n, over
the sizes: ``fixed`` is the cost of a step that does not grow with the particles.
``--momentum balanced`` or ``variational`` measures that momentum (``numerics.momentum``);
without it, each checkout's default. Each row also gives the neighbour-list builds per step
(the model's ``neighbour_builds`` counter, where the checkout has it).

``--scaling`` measures this checkout on ``--threads`` threads and on one thread, alternately
in one process, and reports their ratio (what the second thread adds).

``--compare REF`` runs the same measurements on a second checkout in the same invocation,
each checkout in its own worker process, alternating one measurement of each (so that both
see the same load on a shared machine; compare them by their ratio only). REF is a path to a
checkout (a directory holding ``floodsph/``) or a git commit of this repository, extracted
once with ``git archive`` into ``--ref-dir`` (so its compiled kernels are cached there).
A checkout without the stage timer reports its totals only.

    python benchmarks/step_cost.py [--steps 200] [--repeats 3] [--threads 1]
        [--momentum variational|balanced] [--compare REF | --scaling]
        [--out docs/step-cost.md] [--quick]
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SIZES = {1000: 10.0, 4000: 5.0, 16000: 2.5, 64000: 1.25}
"""Nominal particle count -> particle spacing [m] of the dam break."""
DEPTH_M = 10.0
"""Depth of the still water behind the dam [m]."""


LOCATIONS = {
    "set_up_model": (("floodsph.model.builder", "set_up_model"), ("floodsph.model", "FloodModel")),
    "ParticleSet": (("floodsph.model.particles", "ParticleSet"),
                    ("floodsph.particles", "ParticleSet")),
    "Terrain": (("floodsph.model.terrain", "Terrain"), ("floodsph.terrain", "Terrain")),
    "Numerics": (("floodsph.scenario.numerics", "Numerics"), ("floodsph.numerics", "Numerics")),
    "TimeStepping": (("floodsph.scenario.numerics", "TimeStepping"),
                     ("floodsph.numerics", "TimeStepping")),
    "Momentum": (("floodsph.scenario.numerics", "Momentum"), ("floodsph.numerics", "Momentum")),
    "set_threads": (("floodsph.run.pipeline", "set_threads"), ("floodsph.run", "set_threads")),
    "StageTimer": (("floodsph.model.stage_timer", "StageTimer"),
                   ("floodsph.stage_timer", "StageTimer")),
}
"""Where each piece the worker uses lives: in this layout, then in the flat layout of the
commits before the package's folders (so that ``--compare`` reaches back across it)."""


def piece(name: str):
    """The object ``name`` of :data:`LOCATIONS` from the floodsph being measured."""
    import importlib

    for module, attribute in LOCATIONS[name]:
        try:
            return getattr(importlib.import_module(module), attribute)
        except (ImportError, AttributeError):
            continue
    raise ImportError(f"step_cost: this floodsph has no {name}")


def dam_break(spacing: float, momentum: str | None = None):
    """The FloodModel of the dam break at ``spacing`` [m] (module docstring) under the
    ``momentum`` named (``numerics.momentum``; None: the checkout's default), built from the
    public pieces only (``Terrain``, ``ParticleSet``, ``Numerics``, the model's set-up), so
    that any checkout builds the same case."""
    from floodsph.constants import RHO_WATER

    set_up_model, ParticleSet, Terrain, Numerics = (
        piece(name) for name in ("set_up_model", "ParticleSet", "Terrain", "Numerics"))

    terrain = Terrain.from_function(lambda x, y: 0.0 * x, (0.0, 2000.0), (0.0, 100.0), 10.0)
    x1 = np.arange(spacing / 2, 1000.0, spacing)
    y1 = np.arange(spacing / 2, terrain.height, spacing)
    x, y = (a.ravel() for a in np.meshgrid(x1, y1))
    p = ParticleSet(x.size)
    # one global step, so that a step is one update of every particle in every checkout
    chosen = {} if momentum is None else {"momentum": piece("Momentum")(momentum)}
    numerics = Numerics(particle_spacing_m=spacing,
                        time_stepping=piece("TimeStepping").GLOBAL, **chosen)
    p.append(x=x, y=y, m=np.full(x.size, RHO_WATER * DEPTH_M * spacing * spacing),
             rho=np.full(x.size, RHO_WATER * DEPTH_M),
             h=np.full(x.size, numerics.kappa * spacing))
    return set_up_model(terrain, p, numerics)


def measure(spacing: float, steps: int, warmup: int, momentum: str | None = None) -> dict:
    """One measurement of the dam break at ``spacing`` under ``momentum``: ``particles``,
    ``steps``, ``particle_steps_per_s`` and ``ms_per_step`` of the timed steps,
    ``list_builds_per_step`` and each stage's ``us_<stage>`` per step when the checkout has
    the counter and the stage timer."""
    model = dam_break(spacing, momentum)
    for _ in range(warmup):
        model.step()
    timer = None
    if hasattr(model, "stage_timer"):  # else a checkout from before the stage timer
        timer = model.stage_timer = piece("StageTimer")()
    counters = getattr(model, "state", model).counters  # a checkout before the State: the model's
    updates = counters["particle_updates"]
    builds = counters.get("neighbour_builds")
    t0 = time.perf_counter()
    for _ in range(steps):
        model.step()
    wall = time.perf_counter() - t0
    row = {"particles": model.particles.n, "steps": steps,
           "particle_steps_per_s": (counters["particle_updates"] - updates) / wall,
           "ms_per_step": 1e3 * wall / steps}
    if builds is not None:
        row["list_builds_per_step"] = (counters["neighbour_builds"] - builds) / steps
    if timer is not None:
        row |= {f"us_{stage}": 1e6 * s / steps for stage, s in timer.seconds.items()}
    return row


def worker() -> int:
    """Serve measurements: one JSON request (spacing, steps, warmup) per stdin line, one JSON
    result per stdout line."""
    import floodsph

    root = Path(os.environ["PYTHONPATH"]).resolve()
    if not Path(floodsph.__file__).resolve().is_relative_to(root):
        raise SystemExit(f"step_cost worker: floodsph imported from {floodsph.__file__}, "
                         f"not from {root}")
    piece("set_threads")(int(os.environ.get("STEP_COST_THREADS", "1")))
    for line in sys.stdin:
        request = json.loads(line)
        print(json.dumps(measure(**request)), flush=True)
    return 0


class Checkout:
    """A worker process measuring with the floodsph of ``root``."""

    def __init__(self, name: str, root: Path, threads: int):
        self.name = name
        env = {**os.environ, "PYTHONPATH": str(root), "STEP_COST_THREADS": str(threads)}
        if threads:
            env["NUMBA_NUM_THREADS"] = str(threads)
        self.proc = subprocess.Popen([sys.executable, str(Path(__file__).resolve()), "--worker"],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                                     env=env, cwd=root)

    def measure(self, **request) -> dict:
        self.proc.stdin.write(json.dumps(request) + "\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        if not line:
            raise RuntimeError(f"step_cost: the {self.name} worker stopped (see its stderr)")
        return json.loads(line)

    def close(self) -> None:
        self.proc.stdin.close()
        self.proc.wait()


class InProcess:
    """Measure with the floodsph this process imports, on ``threads`` numba threads (None:
    as they are set)."""

    def __init__(self, name: str = "this", threads: int | None = None):
        self.name = name
        self.threads = threads

    def measure(self, **request) -> dict:
        if self.threads is not None:
            piece("set_threads")(self.threads)
        return measure(**request)

    def close(self) -> None:
        pass


def reference_root(ref: str, ref_dir: Path) -> Path:
    """The checkout of ``ref``: a directory holding ``floodsph/``, or a commit of this
    repository extracted into ``ref_dir / <commit>`` (once)."""
    path = Path(ref)
    if (path / "floodsph").is_dir():
        return path.resolve()
    try:
        sha = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--verify", f"{ref}^{{commit}}"],
                             capture_output=True, text=True, check=True).stdout.strip()
    except subprocess.CalledProcessError as exc:
        raise SystemExit(f"--compare {ref!r}: neither a checkout (no floodsph/ in it) nor a "
                         f"commit of {REPO}: {exc.stderr.strip()}") from None
    root = ref_dir / sha
    if not (root / "floodsph").is_dir():
        root.mkdir(parents=True, exist_ok=True)
        archive = subprocess.run(["git", "-C", str(REPO), "archive", "--format=tar", sha,
                                  "floodsph"], capture_output=True, check=True).stdout
        with tempfile.TemporaryFile() as f:
            f.write(archive)
            f.seek(0)
            with tarfile.open(fileobj=f) as tar:
                tar.extractall(root, filter="data")
    return root


def fixed_cost(rows: list[dict]) -> tuple[float, float]:
    """Least-squares (fixed [ms], per particle [us]) of ms_per_step = fixed + k particles."""
    n = np.array([r["particles"] for r in rows], dtype=float)
    t = np.array([r["ms_per_step"] for r in rows])
    if n.size < 2:
        return float("nan"), float("nan")
    k, fixed = np.polyfit(n, t, 1)
    return float(fixed), 1e3 * float(k)


def run(checkouts, sizes, steps: int, warmup: int, repeats: int,
        momentum: str | None = None) -> list[dict]:
    """Median measurement per checkout and size, the checkouts alternating (in turned order
    from one repeat to the next)."""
    samples = {(c.name, size): [] for c in checkouts for size in sizes}
    for rep in range(repeats):
        for size in sizes:
            order = checkouts if rep % 2 == 0 else checkouts[::-1]
            for c in order:
                samples[c.name, size].append(
                    c.measure(spacing=SIZES[size], steps=steps, warmup=warmup,
                              momentum=momentum))
    rows = []
    for (name, size), got in samples.items():
        row = {"checkout": name, "size": size}
        for key in got[0]:
            values = [g[key] for g in got]
            row[key] = values[0] if key in ("particles", "steps") else float(np.median(values))
        rows.append(row)
    return rows


def report(rows: list[dict], names: list[str], command: str) -> str:
    """docs/step-cost.md: the table, the fits, the ratios and the command."""
    from floodsph.output.tables import markdown

    stages = [k for k in rows[0] if k.startswith("us_")]
    builds = ["list_builds_per_step"] if "list_builds_per_step" in rows[0] else []
    columns = ["checkout", "particles", "steps", "particle_steps_per_s", "ms_per_step",
               *builds, *stages]
    table = [{c: r.get(c, float("nan")) for c in columns} for r in rows]
    fits = []
    for name in names:
        fixed, per = fixed_cost([r for r in rows if r["checkout"] == name])
        fits.append({"checkout": name, "fixed_ms_per_step": fixed,
                     "us_per_particle_step": per})
    lines = ["# Cost of a time step", "",
             "Made by `benchmarks/step_cost.py` (its docstring describes the case and the "
             "stages):", "", f"    {command}", "",
             "Medians of the repeats. Stage times are microseconds per step (`us_<stage>`, "
             "`floodsph.model.stage_timer`).", "", markdown(table, spec=".4g"), "",
             "Least-squares fit of ms per step = fixed + per particle x particles:", "",
             markdown(fits, spec=".4g")]
    if len(names) == 2:
        a, b = names
        ratios = []
        for size in dict.fromkeys(r["size"] for r in rows):
            ra, rb = (next(r for r in rows if r["checkout"] == n and r["size"] == size)
                      for n in names)
            ratios.append({"particles": ra["particles"],
                           f"speed {a} / {b}": ra["particle_steps_per_s"]
                           / rb["particle_steps_per_s"]})
        lines += ["", "Ratio of particle-steps/s, measured alternately in the same run "
                  "(the machine is shared: ratios, not absolute figures, compare):", "",
                  markdown(ratios, spec=".3f")]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200, help="timed steps per measurement")
    ap.add_argument("--warmup", type=int, default=5, help="untimed steps first")
    ap.add_argument("--repeats", type=int, default=3, help="measurements per size")
    ap.add_argument("--threads", type=int, default=1, help="numba threads (0 = all cores)")
    ap.add_argument("--sizes", type=int, nargs="+", default=sorted(SIZES),
                    choices=sorted(SIZES), help="nominal particle counts")
    ap.add_argument("--momentum", choices=("variational", "balanced"), default=None,
                    help="numerics.momentum of the dam break (default: each checkout's)")
    ap.add_argument("--compare", metavar="REF", help="a second checkout: path or commit")
    ap.add_argument("--scaling", action="store_true",
                    help="measure on --threads threads and on one, alternately, in one process")
    ap.add_argument("--ref-dir", type=Path,
                    default=Path(tempfile.gettempdir()) / "floodsph-step-cost",
                    help="where a commit given to --compare is extracted")
    ap.add_argument("--out", type=Path, default=REPO / "docs" / "step-cost.md")
    ap.add_argument("--quick", action="store_true",
                    help="two small sizes, few steps, one repeat (checks that it works)")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        return worker()
    if args.quick:
        args.sizes, args.steps, args.warmup, args.repeats = [1000, 4000], 5, 2, 1
    if args.scaling:
        from floodsph.run.pipeline import set_threads

        threads = set_threads(args.threads)
        if threads < 2:
            print("Error: --scaling needs --threads of 2 or more (0: all cores)",
                  file=sys.stderr)
            return 2
        checkouts = [InProcess(f"{threads} threads", threads), InProcess("1 thread", 1)]
    elif args.compare:
        checkouts = [Checkout("this", REPO, args.threads),
                     Checkout("ref", reference_root(args.compare, args.ref_dir), args.threads)]
    else:
        from floodsph.run.pipeline import set_threads

        set_threads(args.threads)
        checkouts = [InProcess()]
    try:
        rows = run(checkouts, args.sizes, args.steps, args.warmup, args.repeats,
                   args.momentum)
    finally:
        for c in checkouts:
            c.close()
    command = "python benchmarks/step_cost.py " + shlex.join(argv if argv is not None
                                                            else sys.argv[1:])
    text = report(rows, [c.name for c in checkouts], command.strip())
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
