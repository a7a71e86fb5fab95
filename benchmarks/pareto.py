"""Speed against error: floodsph against the grid codes GeoClaw and ANUGA on analytic cases.

What it measures: for each case, code, mode and resolution, the solver time on this machine
and the relative L1 error of the depth at the final time against the exact solution; then, for
each case, how long floodsph takes against the fastest peer at the same error (the peer's
solver time interpolated on its log-log time-error curve). The cases are those of
``floodsph.verification.cases`` (flat or smooth frictionless beds, walls all round):

* Ritter's dry dam break (Ritter 1892): 10 m of still water behind a dam at x = 1000 m in a
  2000 m x 100 m channel, dry bed beyond, t = 50 s (``cases.RITTER``).
* Stoker's wet dam break (Stoker 1957, *Water Waves*, ch. 10): the same with 2 m downstream
  (``cases.STOKER``).
* Thacker's planar oscillation in a paraboloid (Thacker 1981, J. Fluid Mech. 107, 499-508):
  bed 10 m r^2 / (3000 m)^2 in a 10 km square, the wet disc orbiting 1500 m off the centre,
  one period, 1346 s (``cases.THACKER``).

Exact solutions: ``floodsph.verification.exact``. Error: ``floodsph.verification.metrics.
l1_relative`` on the same points for every code: for the dam breaks the mean depth of four
lines along the channel (y = 12.5, 37.5, 62.5, 87.5 m) every 1 m, as
``cases.ritter``/``cases.stoker`` sample it; for Thacker the points of a 50 m grid inside the
exact wet disc (``cases.thacker``'s grid: floodsph's Thacker error is the one that function
returns, the same sum over the same points). floodsph's depth at a point is its SPH depth
(Shepard-interpolated, as the cases do); a grid code's is the depth of the cell (GeoClaw) or
triangle (ANUGA) holding the point.

Codes and resolutions (spacing of the particles, side of the square cells; ANUGA cuts each
square into four triangles):

* floodsph in five modes: no refinement with one global step; split+coalesce with the global
  step; split+coalesce with local steps (``Numerics.refinement``, ``Numerics.time_stepping``);
  and the first and the last again with the reconstructed dissipation
  (``Numerics.stabilisation = "muscl"``); dam breaks at 10, 5, 2.5 m, Thacker at 200, 100,
  50 m.
* GeoClaw 5.x and ANUGA 4.x (set-ups: ``benchmarks/pareto_peers.py``) at those resolutions and
  coarser and finer ones, so that their curves bracket floodsph's errors: dam breaks at 50,
  25, 10, 5 and 2.5 m (GeoClaw needs 4 cells across the channel: not at 50 m), Thacker at 400
  to 25 m. A peer run predicted (from the peer's previous resolution, cost ~ resolution^-3)
  to take longer than ``--peer-limit`` seconds is dropped, and the page says so.

Timing: the solver's time loop only (imports, set-up, compilation and output excluded).
floodsph's numba kernels are compiled (or loaded from the cache) by a small warm-up run of
each case and mode first; its time is the ``wall_s`` of the case functions. Each peer run is
one process of the peers' interpreter (``--peer-python``), which times its own loop; GeoClaw is
compiled once into ``--peer-work``. Runs go one at a time, interleaved between the codes at
each resolution, all with ``--threads`` threads (numba's for floodsph, ``OMP_NUM_THREADS``
and ``NUMBA_NUM_THREADS`` for the peers). A peer that is not installed for ``--peer-python``
is skipped with a printed line; nothing here imports clawpack or anuga.

Writes into ``--out`` (default ``docs/``): ``speed-vs-grid-codes.md`` (command, commit, machine
and load, the table of runs, the equal-error ratios), ``speed-vs-grid-codes.png`` (error
against solver time, log-log, one panel per case) and ``speed-vs-grid-codes.csv`` (every run).

Usage::

    python benchmarks/pareto.py [--peer-python /work/peers-venv/bin/python] [--threads 1]
        [--cases ritter stoker thacker] [--peers geoclaw anuga] [--peer-limit 300]
        [--peer-work DIR] [--claw DIR] [--out docs] [--quick]

``--quick``: one small resolution per case (Ritter and Stoker 20 m, Thacker 200 m), for
floodsph and the peers that are installed, written into a temporary folder unless ``--out``
is given: a few seconds.

The peers live in a virtualenv of their own, not floodsph's (about 6 minutes)::

    python3 -m venv /work/peers-venv
    /work/peers-venv/bin/pip install -U pip wheel setuptools
    /work/peers-venv/bin/pip install numpy scipy matplotlib numba
    /work/peers-venv/bin/pip install anuga                  # a wheel
    apt-get update && apt-get install -y gfortran           # GeoClaw is Fortran
    /work/peers-venv/bin/pip install clawpack               # an sdist, builds in ~2 minutes
    mkdir -p /work/peers-venv/src && cd /work/peers-venv/src
    /work/peers-venv/bin/pip download --no-deps clawpack==5.14.0
    tar xzf clawpack-5.14.0.tar.gz

(pip installs clawpack's Python part only; GeoClaw's Fortran sources come from the unpacked
sdist, found at ``<peer venv>/src/clawpack-<version>``, ``$CLAW`` or ``--claw``.)
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import provenance  # noqa: E402

from floodsph import __version__ as FLOODSPH_VERSION  # noqa: E402
from floodsph.constants import GRAVITY  # noqa: E402
from floodsph.output.tables import markdown, write_csv  # noqa: E402
from floodsph.run.pipeline import set_threads  # noqa: E402
from floodsph.scenario.numerics import (  # noqa: E402
    Momentum,
    Refinement,
    Stabilisation,
    TimeStepping,
)
from floodsph.verification import cases, exact, metrics  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
PEER_DRIVER = Path(__file__).resolve().with_name("pareto_peers.py")
PAGE = "speed-vs-grid-codes"
PEER_NAMES = {"geoclaw": "GeoClaw", "anuga": "ANUGA"}
MIN_CELLS_ACROSS = {"geoclaw": 4}
"""GeoClaw stops on a grid narrower than twice its two ghost cells."""
CHANNEL_LINES_Y = (12.5, 37.5, 62.5, 87.5)
"""The lines along the channel on which ``cases.ritter`` and ``cases.stoker`` read the depth."""


# -- cases, modes, sample points -------------------------------------------------------------
@dataclass(frozen=True)
class Mode:
    """A floodsph mode: its refinement, time stepping and stabilisation."""

    label: str
    refinement: Refinement
    time_stepping: TimeStepping
    stabilisation: Stabilisation = Stabilisation.LAX_FRIEDRICHS

    @property
    def numerics(self) -> dict:
        """The mode as fields of ``Numerics``."""
        momentum = (Momentum.BALANCED if self.stabilisation is Stabilisation.LAX_FRIEDRICHS
                    else Momentum.VARIATIONAL)  # the other stabilisations need "variational"
        return {"refinement": self.refinement, "time_stepping": self.time_stepping,
                "stabilisation": self.stabilisation, "momentum": momentum}


MODES = (Mode("none, global", Refinement.NONE, TimeStepping.GLOBAL),
         Mode("split+coalesce, global", Refinement.SPLIT_COALESCE, TimeStepping.GLOBAL),
         Mode("split+coalesce, local", Refinement.SPLIT_COALESCE, TimeStepping.LOCAL),
         Mode("none, global, muscl", Refinement.NONE, TimeStepping.GLOBAL, Stabilisation.MUSCL),
         Mode("split+coalesce, local, muscl", Refinement.SPLIT_COALESCE, TimeStepping.LOCAL,
              Stabilisation.MUSCL))


@dataclass(frozen=True)
class Samples:
    """Where every code's depth is read at the end time, in the case's frame, and the exact
    depth there. ``lines`` > 0: the points are that many rows along the channel, averaged into
    one profile; 0: the points are weighted by the exact wet area (1 inside, 0 outside)."""

    x: np.ndarray
    y: np.ndarray
    exact: np.ndarray
    lines: int

    def l1(self, depth: np.ndarray) -> float:
        """Relative L1 error of ``depth`` at the points (``metrics.l1_relative``)."""
        if self.lines:
            return self.profile_l1(np.asarray(depth).reshape(self.lines, -1).mean(axis=0))
        return metrics.l1_relative(depth, self.exact, weights=self.exact > 0.0)

    def profile_l1(self, profile: np.ndarray) -> float:
        """Relative L1 error of a channel profile, the depth averaged over the lines."""
        return metrics.l1_relative(profile, self.exact[:profile.size])


@dataclass(frozen=True)
class Case:
    """One analytic case: floodsph's function, the peers' description and the resolutions."""

    name: str
    run: Callable[..., cases.CaseResult]
    floodsph_res: tuple[float, ...]
    peer_res: tuple[float, ...]
    quick_res: float
    warm_up_res: float

    def peer_case(self) -> dict:
        """The case as ``pareto_peers.py`` takes it."""
        if self.name == "thacker":
            b, w = cases.THACKER, cases.THACKER.half_width
            return {"kind": "thacker", "x_range": [-w, w], "y_range": [-w, w], "h0": b.h0,
                    "a": b.a, "eta": b.eta, "t_end": exact.thacker_period(b.h0, b.a)}
        c = self.dam_break
        return {"kind": "dam_break", "x_range": [0.0, c.length], "y_range": [0.0, c.width],
                "x_dam": c.x_dam, "d_left": c.d_left, "d_right": c.d_right, "t_end": c.t_end}

    @property
    def dam_break(self) -> cases.DamBreak:
        return {"ritter": cases.RITTER, "stoker": cases.STOKER}[self.name]

    def samples(self) -> Samples:
        if self.name == "thacker":
            b = cases.THACKER
            q = np.arange(-b.half_width + b.cell / 2, b.half_width, b.cell)
            X, Y = (a.ravel() for a in np.meshgrid(q, q))
            d = exact.thacker_planar(X, Y, exact.thacker_period(b.h0, b.a), b.h0, b.a, b.eta)[0]
            return Samples(X, Y, d, 0)
        c = self.dam_break
        x = np.arange(0.5, c.length, 1.0)
        X, Y = (a.ravel() for a in np.meshgrid(x, CHANNEL_LINES_Y))
        d = exact.stoker(X, c.t_end, c.d_left, c.d_right, x_dam=c.x_dam)[0]
        return Samples(X, Y, d, len(CHANNEL_LINES_Y))

    def floodsph_l1(self, result: cases.CaseResult, samples: Samples) -> float:
        """floodsph's error: its channel profile through ``samples``; Thacker: the case's."""
        if self.name == "thacker":
            return result.l1
        profile = result.profile
        if not np.array_equal(profile.x, samples.x[:profile.x.size]):
            raise ValueError(f"{self.name}: floodsph's profile is not on the sample points")
        return samples.profile_l1(profile.d)


CASES = {
    "ritter": Case("ritter", cases.ritter, (10.0, 5.0, 2.5), (50.0, 25.0, 10.0, 5.0, 2.5),
                   20.0, 40.0),
    "stoker": Case("stoker", cases.stoker, (10.0, 5.0, 2.5), (50.0, 25.0, 10.0, 5.0, 2.5),
                   20.0, 40.0),
    "thacker": Case("thacker", cases.thacker, (200.0, 100.0, 50.0),
                    (400.0, 200.0, 100.0, 50.0, 25.0), 200.0, 400.0),
}


# -- runs --------------------------------------------------------------------------------------
@dataclass
class Run:
    """One run: its cost and its error. ``elements``: peak particles, cells or triangles."""

    case: str
    code: str
    version: str
    mode: str
    resolution_m: float
    elements: int
    element_kind: str
    steps: int
    solver_s: float
    l1: float
    threads: int


@dataclass(frozen=True)
class Skip:
    """A run not made, and why."""

    case: str
    code: str
    resolution_m: float
    reason: str


@dataclass(frozen=True)
class Peer:
    """An installed peer and how to run it."""

    code: str
    version: str
    python: str
    claw: str | None

    @property
    def name(self) -> str:
        return PEER_NAMES[self.code]


def floodsph_run(case: Case, mode: Mode, dx: float, samples: Samples, threads: int) -> Run:
    r = case.run(dx, **mode.numerics)
    return Run(case.name, "floodsph", FLOODSPH_VERSION, mode.label, dx, r.particles_max,
               "particles (peak)", r.steps, r.wall_s, case.floodsph_l1(r, samples), threads)


def warm_up(names, modes) -> None:
    """Compile (or load) floodsph's kernels: each case and mode once at a coarse spacing."""
    for name in names:
        for mode in modes:
            CASES[name].run(CASES[name].warm_up_res, **mode.numerics)


def peer_env(threads: int) -> dict:
    """The peers' environment: ``threads`` OpenMP and numba threads; idle OpenMP threads wait
    passively unless the user chose otherwise (spinning threads stall on a shared machine,
    see ``versus_grid_code.import_anuga``)."""
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), NUMBA_NUM_THREADS=str(threads))
    env.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    return env


def find_peers(python: str, wanted, claw: str | None,
               work: Path) -> tuple[list[Peer], list[str]]:
    """The wanted peers that run with ``python``, and a line for each one that does not.
    The driver runs in ``work``: clawpack writes a log into the current folder."""
    if not wanted:
        return [], []
    command = [python, str(PEER_DRIVER), "check"] + (["--claw", claw] if claw else [])
    work.mkdir(parents=True, exist_ok=True)
    try:
        done = subprocess.run(command, capture_output=True, text=True, check=True, timeout=300,
                              env=peer_env(1), cwd=work)
        status = json.loads(done.stdout.strip().splitlines()[-1])
    except (OSError, subprocess.SubprocessError, ValueError, IndexError) as err:
        return [], [f"{PEER_NAMES[c]}: skipped, {python} cannot run the peer driver ({err})"
                    for c in wanted]
    peers, skipped = [], []
    for code in wanted:
        s = status[code]
        if s["ok"]:
            peers.append(Peer(code, s["version"], python, s.get("claw")))
        else:
            skipped.append(f"{PEER_NAMES[code]}: skipped, {s['why']}")
    return peers, skipped


def peer_run(peer: Peer, case: Case, res: float, samples: Samples, threads: int, work: Path,
             timeout_s: float) -> Run:
    """One peer run in its own process (``pareto_peers.py run``)."""
    folder = work / case.name / f"{peer.code}_{res:g}m"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "result.json").unlink(missing_ok=True)
    job = {"code": peer.code, "case": case.peer_case(), "resolution": res, "threads": threads,
           "gravity": GRAVITY, "points": [samples.x.tolist(), samples.y.tolist()],
           "folder": str(folder), "work": str(work), "claw": peer.claw}
    (folder / "job.json").write_text(json.dumps(job))
    with open(folder / "driver.log", "w") as log:
        subprocess.run([peer.python, str(PEER_DRIVER), "run", str(folder / "job.json")],
                       stdout=log, stderr=subprocess.STDOUT, env=peer_env(threads), check=True,
                       timeout=timeout_s, cwd=folder)
    r = json.loads((folder / "result.json").read_text())
    mode = r["flow_algorithm"] if peer.code == "anuga" else "1 level, order 2"
    kind = "triangles" if peer.code == "anuga" else "cells"
    return Run(case.name, peer.name, r["version"], mode, res, r["cells"], kind, r["steps"],
               r["solver_s"], samples.l1(np.asarray(r["depth"])), r["threads"])


def peer_refusal(peer: Peer, case: Case, res: float) -> str | None:
    """Why ``peer`` cannot run ``case`` at ``res``, or None."""
    c = case.peer_case()
    across = min(c["x_range"][1] - c["x_range"][0], c["y_range"][1] - c["y_range"][0])
    cells = MIN_CELLS_ACROSS.get(peer.code, 1)
    if across / res < cells:
        return (f"not run: {peer.name} needs {cells} or more cells across the domain "
                f"({across:g} m)")
    return None


def failure(err: Exception, folder: Path, peer: Peer, res: float) -> str:
    """The last line of a failed peer run's log, or the error itself."""
    log = folder / f"{peer.code}_{res:g}m" / "driver.log"
    lines = log.read_text().strip().splitlines() if log.exists() else []
    return lines[-1] if lines else str(err)


def predicted_s(last: Run | None, res: float) -> float:
    """A peer's time at ``res`` from its run at a coarser resolution: cells ~ res^-2, steps ~
    res^-1."""
    return 0.0 if last is None else last.solver_s * (last.resolution_m / res) ** 3


@dataclass
class Benchmark:
    runs: list[Run]
    skips: list[Skip]
    peer_lines: list[str]
    threads: int
    load: tuple[float, float]
    wall_s: float
    command: str
    source: str
    """the commit measured, and the uncommitted changes to the package at the start"""


def ladder(case: Case, peers: list[Peer], quick: bool) -> list[float]:
    """The resolutions of ``case``, coarse to fine."""
    if quick:
        return [case.quick_res]
    return sorted(set(case.floodsph_res) | (set(case.peer_res) if peers else set()),
                  reverse=True)


def run_case(case: Case, modes, peers: list[Peer], args, threads: int, runs: list[Run],
             skips: list[Skip]) -> None:
    """All runs of one case, interleaved between the codes at each resolution."""
    samples = case.samples()
    last: dict[str, Run] = {}
    for res in ladder(case, peers, args.quick):
        if args.quick or res in case.floodsph_res:
            for mode in modes:
                runs.append(floodsph_run(case, mode, res, samples, threads))
                print_run(runs[-1])
        for peer in peers if args.quick or res in case.peer_res else ():
            made = try_peer(peer, case, res, samples, threads, args, last.get(peer.code))
            if isinstance(made, Run):
                runs.append(made)
                last[peer.code] = made
                print_run(made)
            else:
                skips.append(Skip(case.name, peer.name, res, made))
                print(f"{case.name} {peer.name} {res:g} m: {made}")


def try_peer(peer: Peer, case: Case, res: float, samples: Samples, threads: int, args,
             last: Run | None) -> Run | str:
    """A peer's run at ``res``, or why it was not made (too slow after the previous
    resolution ``last``, refused, failed)."""
    guess = predicted_s(last, res)
    if guess > args.peer_limit:
        return (f"not run: predicted {guess:.0f} s from the {last.resolution_m:g} m run, over "
                f"the {args.peer_limit:g} s limit")
    refusal = peer_refusal(peer, case, res)
    if refusal is not None:
        return refusal
    try:
        return peer_run(peer, case, res, samples, threads, args.peer_work,
                        3.0 * args.peer_limit + 60.0)
    except (subprocess.SubprocessError, OSError, ValueError, KeyError) as err:
        return f"failed: {failure(err, args.peer_work / case.name, peer, res)}"


def print_run(r: Run) -> None:
    print(f"{r.case:8s} {r.code:8s} {r.mode:24s} {r.resolution_m:6g} m {r.elements:8d} "
          f"{r.element_kind:16s} {r.steps:6d} steps {r.solver_s:9.3f} s L1 {100 * r.l1:.3f} %",
          flush=True)


# -- equal error -----------------------------------------------------------------------------
def pareto_front(points) -> list[tuple[float, float]]:
    """The (time, error) points that no faster point beats: by time, errors falling."""
    front: list[tuple[float, float]] = []
    for t, e in sorted(points):
        if not front or e < front[-1][1]:
            front.append((t, e))
    return front


def time_at_error(points, error: float) -> float | None:
    """The time at ``error`` on the log-log line through the Pareto front of ``points``
    ((time, error) pairs); None when ``error`` is outside the front's range (no
    extrapolation)."""
    front = pareto_front(points)
    if not front or not front[-1][1] <= error <= front[0][1]:
        return None
    for (t0, e0), (t1, e1) in zip(front[:-1], front[1:], strict=True):
        if e1 <= error <= e0:
            f = math.log(error / e0) / math.log(e1 / e0)
            return math.exp(math.log(t0) + f * math.log(t1 / t0))
    return front[0][0]  # a front of one point, at exactly its error


@dataclass(frozen=True)
class Comparison:
    """A floodsph run against one peer at the same error."""

    run: Run
    peer: str
    peer_s: float | None
    """the peer's interpolated solver time; None: outside its range"""
    peer_front: list[tuple[float, float]]
    """the peer's Pareto front, (time, error) from the fastest"""

    @property
    def ratio(self) -> float | None:
        return None if self.peer_s is None else self.run.solver_s / self.peer_s

    def text(self) -> str:
        if self.peer_s is not None:
            return f"{self.peer_s:.3g} s ({self.ratio:.3g}x)"
        (t_fast, hi), (t_best, lo) = self.peer_front[0], self.peer_front[-1]
        span = f"{100 * lo:.3g} %" if lo == hi else f"{100 * lo:.3g}-{100 * hi:.3g} %"
        t, bound = self.run.solver_s, ""
        if self.run.l1 < lo:
            if t < t_best:
                bound = f"; its most accurate took {t_best:.3g} s: ratio < {t / t_best:.3g}x"
            return f"outside the peer's range (below its {span}{bound})"
        if t > t_fast:
            bound = f"; its fastest took {t_fast:.3g} s: ratio > {t / t_fast:.3g}x"
        return f"outside the peer's range (above its {span}{bound})"


def comparisons(runs: list[Run], case: str) -> list[Comparison]:
    """Every floodsph run of ``case`` against every peer that ran it."""
    out = []
    for peer in dict.fromkeys(r.code for r in runs if r.case == case and r.code != "floodsph"):
        points = [(r.solver_s, r.l1) for r in runs if r.case == case and r.code == peer]
        front = pareto_front(points)
        for r in runs:
            if r.case == case and r.code == "floodsph":
                out.append(Comparison(r, peer, time_at_error(points, r.l1), front))
    return out


def best_ratio(comps: list[Comparison]) -> Comparison | None:
    """Of each floodsph run against the fastest peer at its error, the smallest time ratio;
    None when no floodsph error is within a peer's range."""
    fastest: dict[int, Comparison] = {}
    for c in comps:
        if c.peer_s is not None and (id(c.run) not in fastest
                                     or c.peer_s < fastest[id(c.run)].peer_s):
            fastest[id(c.run)] = c
    return min(fastest.values(), key=lambda c: c.ratio, default=None)


def mode_ratio(comps: list[Comparison], mode: str) -> str:
    """The best ratio of ``mode``'s floodsph runs, as text."""
    c = best_ratio([c for c in comps if c.run.mode == mode])
    if c is None:
        return f"{mode}: outside the peers' ranges"
    return f"{mode} {c.ratio:.3g}x ({c.run.resolution_m:g} m, {c.peer})"


# -- page, table, picture ----------------------------------------------------------------------
CSV_COLUMNS = [f.name for f in fields(Run)]


def percent(x: float) -> str:
    return f"{100 * x:.3g}"


def runs_table(runs: list[Run]) -> str:
    return markdown([{"case": r.case, "code": r.code, "mode": r.mode,
                      "resolution m": f"{r.resolution_m:g}",
                      "particles / cells": f"{r.elements} {r.element_kind}",
                      "steps": r.steps, "solver s": f"{r.solver_s:.3g}", "L1 %": percent(r.l1)}
                     for r in runs])


def ratio_section(runs: list[Run], case: str) -> list[str]:
    comps = comparisons(runs, case)
    if not comps:
        return [f"**{case}**: no peer ran this case.", ""]
    peers = list(dict.fromkeys(c.peer for c in comps))
    rows = []
    for r in (r for r in runs if r.case == case and r.code == "floodsph"):
        row = {"floodsph mode": r.mode, "resolution m": f"{r.resolution_m:g}",
               "L1 %": percent(r.l1), "solver s": f"{r.solver_s:.3g}"}
        for c in comps:
            if c.run is r:
                row[f"{c.peer} at that error (ratio)"] = c.text()
        rows.append(row)
    c = best_ratio(comps)
    if c is None:
        summary = (f"**{case}**: no floodsph error lies within a peer's range; no ratio at "
                   "equal error.")
    else:
        summary = (f"**{case}**: best floodsph run {c.run.mode} at {c.run.resolution_m:g} m "
                   f"(L1 {percent(c.run.l1)} %, {c.run.solver_s:.3g} s) takes {c.ratio:.3g}x "
                   f"the solver time of the fastest peer at that error, {c.peer} "
                   f"({c.peer_s:.3g} s, interpolated).")
        summary += " Best by mode: " + "; ".join(mode_ratio(comps, m.label) for m in MODES) + "."
    return [summary, "", markdown(rows, ["floodsph mode", "resolution m", "L1 %", "solver s",
                                        *(f"{p} at that error (ratio)" for p in peers)]), ""]


SETUP = (
    "* Cases (`floodsph.verification.cases`): Ritter's dry dam break (Ritter 1892; 10 m "
    "behind a dam in the middle of a 2000 m x 100 m channel, t = 50 s), Stoker's wet dam "
    "break (Stoker 1957; 10 m over 2 m, same channel and time), Thacker's planar oscillation "
    "in a paraboloid (Thacker 1981, J. Fluid Mech. 107; h0 = 10 m, a = 3000 m, eta = 1500 m, "
    "10 km square, one period); flat or smooth frictionless beds, walls all round.",
    "* Error: relative L1 of the depth at the final time against the exact solution "
    "(`metrics.l1_relative`), on the same points for every code: dam breaks, the mean of four "
    "lines along the channel (y = 12.5, 37.5, 62.5, 87.5 m) every 1 m over 0-2000 m; Thacker, "
    "a 50 m grid over the exact wet disc. floodsph: SPH depth at the points; GeoClaw: the "
    "cell holding each point; ANUGA: the triangle holding it.",
    "* Solver s: the time loop only (no imports, set-up, compilation or output); floodsph's "
    "kernels compiled by a warm-up run of each case and mode first. One run at a time, the "
    "codes interleaved at each resolution.",
    "* floodsph: particle spacing; GeoClaw: one uniform level of square cells (no AMR), order "
    "2, MC limiter, f-waves, CFL 0.9, dry tolerance 1 mm; ANUGA: `rectangular_cross_domain`, "
    "four triangles per square of the given side, default flow algorithm, reflective walls "
    "(`benchmarks/pareto_peers.py`).",
    "* Equal error: the peer's solver time at floodsph's error, interpolated log-log between "
    "the two neighbouring points of the peer's Pareto front (its runs that no faster run "
    "beats); no extrapolation: an error outside the front is reported as outside the peer's "
    "range. Ratio = floodsph's time / the peer's. Outside the range a bound is given where "
    "one follows from the peer needing more time for a smaller error: floodsph more accurate "
    "than the peer's most accurate run and faster than it (ratio below), or less accurate "
    "than its fastest run and slower (ratio above).",
)


def source_note() -> str:
    """The commit, and the uncommitted changes under ``floodsph/`` (they are measured too)."""
    try:
        changed = subprocess.run(["git", "-C", str(REPO), "status", "--porcelain", "floodsph"],
                                 capture_output=True, text=True, check=True).stdout.split("\n")
    except (OSError, subprocess.CalledProcessError):
        return f"`{provenance.commit(REPO)}`"
    files = [line[3:] for line in changed if line.strip()]
    changes = f" with uncommitted changes to {', '.join(files)}" if files else ""
    return f"`{provenance.commit(REPO)}`{changes}"


def page(bench: Benchmark, picture: Path | None) -> str:
    note = provenance.machine_note(bench.load, bench.wall_s,
                                   "Solver times are of this machine and this run.")
    threads = (f"Threads: {bench.threads} for every code (floodsph's numba threads; "
               f"`OMP_NUM_THREADS={bench.threads}` and `NUMBA_NUM_THREADS={bench.threads}` "
               "for the peers' processes).")
    lines = ["# floodsph against grid codes: solver time against error", "",
             f"Made by `{bench.command}` on {time.strftime('%Y-%m-%d')} at commit "
             f"{bench.source} (at the start); {note} {threads}", ""]
    if bench.peer_lines:
        lines += [f"* {line}" for line in bench.peer_lines] + [""]
    lines += [*SETUP, "", "## Runs", "", runs_table(bench.runs), ""]
    if bench.skips:
        lines += ["Runs not made:", ""] + [f"* {s.case} {s.code} {s.resolution_m:g} m: "
                                           f"{s.reason}" for s in bench.skips] + [""]
    lines += ["## floodsph against the peers at equal error", ""]
    for case in dict.fromkeys(r.case for r in bench.runs):
        lines += ratio_section(bench.runs, case)
    if picture is not None:
        lines += [f"![L1 error against solver time]({picture.name})", ""]
    return "\n".join(lines)


LINES = {**{f"floodsph {m.label}": (f"C{k}", "o-") for k, m in enumerate(MODES)},
         **{name: (f"C{len(MODES) + k}", "s--") for k, name in enumerate(PEER_NAMES.values())}}
"""Colour and style of each line of the picture (code and mode), in the legend's order."""


def series(runs: list[Run], case: str) -> dict[str, list[Run]]:
    """The runs of ``case`` by line of the picture, each coarse to fine."""
    out: dict[str, list[Run]] = {label: [] for label in LINES}
    for r in runs:
        if r.case == case:
            out[f"floodsph {r.mode}" if r.code == "floodsph" else r.code].append(r)
    return {k: sorted(v, key=lambda r: -r.resolution_m) for k, v in out.items() if v}


def tick_label(value: float, _position=None) -> str:
    """A log axis's label at 1, 2 and 5 times a power of ten, none elsewhere."""
    mantissa = value / 10.0 ** math.floor(math.log10(value))
    return f"{value:g}" if any(abs(mantissa - m) < 1e-6 for m in (1, 2, 5)) else ""


def plot(path: Path, runs: list[Run]) -> Path | None:
    """Error against solver time, log-log, one panel per case, one line per code and mode."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.ticker import FuncFormatter, NullFormatter
    except ImportError:
        print("plot skipped: matplotlib not installed")
        return None
    names = list(dict.fromkeys(r.case for r in runs))
    if not names:
        return None
    fig, axes = plt.subplots(1, len(names), figsize=(4.6 * len(names), 4.2), squeeze=False)
    for ax, name in zip(axes[0], names, strict=True):
        for label, sel in series(runs, name).items():
            colour, style = LINES[label]
            ax.loglog([r.solver_s for r in sel], [100 * r.l1 for r in sel], style, color=colour,
                      label=label)
            for r in sel:
                ax.annotate(f"{r.resolution_m:g}", (r.solver_s, 100 * r.l1), fontsize=7,
                            textcoords="offset points", xytext=(3, 3))
        ax.set_title(f"{name} (labels: resolution, m)")
        ax.set_xlabel("solver time [s]")
        ax.set_ylabel("L1 relative depth error [%]")
        for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            axis.set_major_formatter(FuncFormatter(tick_label))
            axis.set_minor_formatter(FuncFormatter(tick_label) if hi < 100.0 * lo
                                     else NullFormatter())
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def write_outputs(out: Path, bench: Benchmark) -> Path:
    out.mkdir(parents=True, exist_ok=True)
    write_csv(out / f"{PAGE}.csv", [asdict(r) for r in bench.runs], CSV_COLUMNS)
    picture = plot(out / f"{PAGE}.png", bench.runs)
    path = out / f"{PAGE}.md"
    path.write_text(page(bench, picture))
    return path


# -- command line ------------------------------------------------------------------------------
def parse(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--peer-python", default=sys.executable,
                    help="Python interpreter with the peers installed (default: this one)")
    ap.add_argument("--peers", nargs="*", choices=tuple(PEER_NAMES), default=list(PEER_NAMES),
                    help="peers to run if installed (none: floodsph only)")
    ap.add_argument("--cases", nargs="+", choices=tuple(CASES), default=list(CASES))
    ap.add_argument("--threads", type=int, default=1, help="threads of every code (0 = all)")
    ap.add_argument("--peer-limit", type=float, default=300.0,
                    help="drop a peer run predicted to take longer [s]")
    ap.add_argument("--peer-work", type=Path,
                    default=Path(tempfile.gettempdir()) / "floodsph-pareto",
                    help="folder of the peers' runs and GeoClaw's build (kept between runs)")
    ap.add_argument("--claw", default=None,
                    help="clawpack source tree with GeoClaw's Fortran (default: $CLAW, else "
                         "<peer venv>/src/clawpack-<version>)")
    ap.add_argument("--out", type=Path, default=None,
                    help="folder of the page, picture and CSV (default docs/; --quick: a "
                         "temporary folder)")
    ap.add_argument("--quick", action="store_true",
                    help="one small resolution per case, a few seconds")
    return ap.parse_args(argv)


def main(argv=None) -> Path:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parse(argv)
    out = args.out or (Path(tempfile.mkdtemp(prefix="pareto-")) if args.quick else REPO / "docs")
    args.peer_work = args.peer_work.resolve()
    load0, start, source = os.getloadavg()[0], time.perf_counter(), source_note()
    threads = set_threads(args.threads)
    peers, peer_lines = find_peers(args.peer_python, args.peers, args.claw, args.peer_work)
    peer_lines += [f"{p.name} {p.version}: run with {p.python}" for p in peers]
    for line in peer_lines:
        print(line)
    warm_up(args.cases, MODES)
    runs: list[Run] = []
    skips: list[Skip] = []
    for name in args.cases:
        run_case(CASES[name], MODES, peers, args, threads, runs, skips)
    command = " ".join(["python benchmarks/pareto.py", *argv])
    bench = Benchmark(runs, skips, peer_lines, threads, (load0, os.getloadavg()[0]),
                      time.perf_counter() - start, command, source)
    path = write_outputs(out.resolve(), bench)
    print(f"page: {path}")
    return path


if __name__ == "__main__":
    main()
