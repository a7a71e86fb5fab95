"""Still water next to walls, nodata borders, shores and buildings, and a dam break turned
away from the lattice: the benchmark of floodsph's wall and shore model.

Each case (``still_water_cases``) is a scenario folder run through the public chain
(``floodsph.run.pipeline.run_scenario``: default numerics, closed edges, run folder and maps); a
callback samples the particles (``sim.model.particles``) at ``SAMPLES`` report times.

Still water: the largest and the 95th-percentile particle speed, and the level error
max |d + b - L| over the particles (d the SPH depth, b the bed under the particle, L the
known level) and its 95th percentile; in the bowl also the shore error, the largest distance
of the outermost particle of any of ``SHORE_SECTORS`` sectors from the exact shoreline r_s;
for every case the splits and merges of the refinement (``run.json``: it should not start
in still water). Malpasset at rest adds its maps: DEM cells outside the reservoir wet
(``max_depth.tif`` above the scenario's wet threshold; the same count on the map of the
particles at t = 0, which the map's kernel smoothing alone gives), ``max_level.tif`` over
the reservoir, the ``max_speed.tif`` of the reservoir's cells (median, 95th percentile,
max). A case passes when every figure with a target stays within it at every report time
after t = 0 (the issue's targets, in the tables).

The dam break: Ritter's solution (``floodsph.verification.exact.ritter``) against the SPH depth
interpolated (``floodsph.output.rasterise.interpolate``) on four lines along the channel
axis at 1/8, 3/8, 5/8 and 7/8 of its width (12.5, 37.5, 62.5 and 87.5 m, as
``floodsph.verification.cases.ritter``), L1 relative of their mean; the two lines next to the
walls against the two middle ones (a wall-hugging jet makes the wall lines worse: targeted
at no more than 25 % worse); the front error (last point deeper than 0.1 m); particles
outside the channel at any report time. Targets: the L1 of the channel turned by 30 degrees
within 25 % of the one along x (either way), no particle outside.

Writes into ``--out``: the run folders, ``still_water_samples.csv`` (every report time of
every case), ``still_water.csv`` (the table); and the report ``--doc`` (default
``docs/still-water.md``; with ``--quick`` ``<out>/still-water.md``) with the picture of the
speeds over time beside it (same name, ``.png``). The Malpasset data is read from
``$FLOODSPH_BENCHMARKS/malpasset`` or ``<repo>/../shared/benchmarks/malpasset``; without it
that case is skipped with a message.

    python benchmarks/still_water.py [--cases malpasset rectangle staircase bowl building
        dam-break] [--time-scale 1] [--end-time rectangle=200 ...] [--quick]
        [--out results/still_water] [--doc docs/still-water.md]

``--quick``: the synthetic cases only, a few hundred particles each, 60 s (12 s for the dam
break): well under a minute in all, for the tests.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import provenance  # noqa: E402
import still_water_cases as cases  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
KINDS = ("malpasset", "rectangle", "staircase", "bowl", "building", "dam-break")
END_TIME_S = {"malpasset": 600.0, "rectangle": 1000.0, "staircase": 1000.0, "bowl": 1000.0,
              "building": 1000.0, "dam-break": 50.0}
QUICK_END_TIME_S = {"malpasset": 20.0, "rectangle": 60.0, "staircase": 60.0, "bowl": 60.0,
                    "building": 60.0, "dam-break": 12.0}
SAMPLES = 20
"""Report times per run: every end_time / SAMPLES seconds, and t = 0."""
SHORE_SECTORS = 36
LINE_FRACTIONS = (0.125, 0.375, 0.625, 0.875)
"""The dam break's lines along the channel, as fractions of its width from the right wall."""
FRONT_DEPTH_M = 0.1
PLOT_FLOOR_MS = 1e-4
"""Speeds below this [m/s] are drawn at it."""
ORIENTATION_TOLERANCE = 0.25
"""Dam break: |L1 turned / L1 along x - 1| and wall lines / middle lines - 1 at most this."""


@dataclass(frozen=True)
class Sample:
    """The particles of one run at one report time (speeds [m/s], errors [m])."""

    t: float
    particles: int
    max_speed: float
    p95_speed: float
    level_error: float = math.nan
    """max |d + b - L| over the particles"""
    level_p95: float = math.nan
    """its 95th percentile"""
    shore_error: float = math.nan
    outside: int = 0
    """dam break: particles outside the channel"""


class Probe:
    """A ``run_scenario`` callback: a :class:`Sample` of the case at each call, the particles
    of the latest call (local coordinates, with the terrain's origin) and, for a case with a
    reservoir, the map cells outside it that the particles at t = 0 wet."""

    def __init__(self, case: cases.Case, wet_threshold: float = 0.01):
        self.case = case
        self.wet_threshold = wet_threshold
        self.samples: list[Sample] = []
        self.particles: dict[str, np.ndarray] = {}
        self.origin = (0.0, 0.0)
        self.outside_at_start: int | None = None

    def __call__(self, sim) -> None:
        from floodsph.simulation.schedules import time_tolerance

        model = sim.model
        if self.samples and abs(self.samples[-1].t - model.t) <= time_tolerance(model.t):
            return  # the final call at the last report time
        p = model.particles
        terrain = model.terrain
        self.origin = (terrain.x0, terrain.y0)
        self.particles = {k: getattr(p, k).copy() for k in ("x", "y", "u", "v", "m", "rho",
                                                             "h")}
        speed = np.hypot(p.u, p.v)
        case = self.case
        eta = model.surface_levels()
        if eta is not None:  # the balanced momentum: maps report the level less the bed
            self.particles["level"] = eta.copy()
        else:  # the variational momentum: the summed depth on the bed
            eta = model.depth() + model.state.bed[: p.n, 0]
        level = (np.abs(eta - case.level_m) if case.level_m is not None and p.n
                 else np.array([math.nan]))
        x, y = terrain.to_world(p.x, p.y)
        self.samples.append(Sample(
            t=float(model.t), particles=int(p.n),
            max_speed=float(speed.max()) if p.n else math.nan,
            p95_speed=float(np.percentile(speed, 95)) if p.n else math.nan,
            level_error=float(level.max()), level_p95=float(np.percentile(level, 95)),
            shore_error=shore_error(x, y, case.shore) if case.shore else math.nan,
            outside=particles_outside(x, y, case.channel) if case.channel else 0))
        if case.reservoir is not None and self.outside_at_start is None:
            self.outside_at_start = self._cells_wet_outside(model)

    def _cells_wet_outside(self, model) -> int:
        from floodsph.output.grid import OutputGrid
        from floodsph.output.rasterise import rasterise

        p = model.particles
        d = rasterise(OutputGrid.from_terrain(model.terrain), p.x, p.y, p.u, p.v, p.m, p.rho,
                      p.h, level=model.surface_levels())[0][::-1]  # north-up, as the mask
        wet = np.nan_to_num(d) > self.wet_threshold
        return int(np.count_nonzero(wet & ~self.case.reservoir))


def shore_error(x, y, shore: cases.Shore) -> float:
    """Largest |r_out - r_s| [m] over ``SHORE_SECTORS`` equal sectors around the shore's
    centre, r_out the distance of the sector's outermost particle (0 in an empty sector)."""
    r = np.hypot(x - shore.x, y - shore.y)
    sector = ((np.arctan2(y - shore.y, x - shore.x) + math.pi) / (2 * math.pi)
              * SHORE_SECTORS).astype(np.int64) % SHORE_SECTORS
    r_out = np.zeros(SHORE_SECTORS)
    np.maximum.at(r_out, sector, r)
    return float(np.abs(r_out - shore.radius).max())


def particles_outside(x, y, channel: cases.Channel, tol: float = 1e-6) -> int:
    """Particles outside the channel's walls (``tol`` [m] of round-off allowed)."""
    s, n = channel.to_channel(x, y)
    out = (s < -tol) | (s > channel.length + tol) | (n < -tol) | (n > channel.width + tol)
    return int(np.count_nonzero(out))


@dataclass
class CaseRun:
    """A finished run: its case, samples, manifest (``run.json``) and run folder."""

    case: cases.Case
    samples: list[Sample]
    manifest: dict
    run_dir: Path
    probe: Probe
    figures: dict = field(default_factory=dict)
    """case-specific results (Malpasset's maps, the dam break's profile errors)"""

    @property
    def later(self) -> list[Sample]:
        """The samples after t = 0."""
        return [s for s in self.samples if s.t > 0.0]

    def worst(self, name: str) -> float:
        values = [getattr(s, name) for s in self.later]
        return float(np.max(values)) if values else math.nan


def run_case(case: cases.Case, out: Path) -> CaseRun:
    """Run the case's scenario into ``out`` with a :class:`Probe` every end_time /
    ``SAMPLES`` s."""
    import floodsph.run.pipeline as runner
    from floodsph.scenario.reader import load_scenario
    from floodsph.simulation.schedules import TimeInterval

    scenario = load_scenario(case.scenario)
    probe = Probe(case, scenario.output.wet_threshold_m)
    every = scenario.end_time_s / SAMPLES
    manifest = runner.run_scenario(scenario, out, progress=False, overwrite=True,
                                   callbacks=[(probe, TimeInterval(every))])
    run = CaseRun(case, probe.samples, manifest, out, probe)
    if case.reservoir is not None:
        run.figures = reservoir_figures(run)
    if case.channel is not None:
        run.figures = dam_break_figures(run)
    return run


def read_map(run_dir: Path, name: str) -> np.ndarray:
    """A run folder's map, north-up, NaN where never wet."""
    import rasterio

    with rasterio.open(run_dir / f"{name}.tif") as src:
        return src.read(1, masked=True).astype(np.float64).filled(np.nan)


def reservoir_figures(run: CaseRun) -> dict:
    """Malpasset: cells outside the reservoir wet (the run's envelope and the particles at
    t = 0), the highest water level over the reservoir, its cells' max speed."""
    reservoir = run.case.reservoir
    depth = read_map(run.run_dir, "max_depth")
    level = read_map(run.run_dir, "max_level")
    speed = read_map(run.run_dir, "max_speed")[reservoir]
    speed = speed[np.isfinite(speed)]
    wet = np.nan_to_num(depth) > run.probe.wet_threshold
    return {
        "cells_outside_wet": int(np.count_nonzero(wet & ~reservoir)),
        "cells_outside_wet_at_0": run.probe.outside_at_start,
        "max_level_m": float(np.nanmax(level[reservoir])),
        "max_speed_median": float(np.median(speed)),
        "max_speed_p95": float(np.percentile(speed, 95)),
        "max_speed_max": float(speed.max()),
    }


def dam_break_figures(run: CaseRun) -> dict:
    """L1 of the mean depth profile against Ritter, of the lines next to the walls and of
    the middle lines, and the front error, at the end time; the depth as the maps show it
    (under the balanced momentum, the particles' level less the bed)."""
    from floodsph.output.rasterise import interpolate
    from floodsph.verification import exact, metrics

    ch = run.case.channel
    p = run.probe.particles
    s = np.arange(0.5, ch.length, 1.0)
    S, N = np.meshgrid(s, np.asarray(LINE_FRACTIONS) * ch.width)
    X, Y = ch.to_world(S.ravel(), N.ravel())
    x0, y0 = run.probe.origin
    level = p.get("level")  # as the maps see it: the level less the (flat, zero) bed
    d = interpolate(X - x0, Y - y0, p["x"], p["y"], p["u"], p["v"], p["m"], p["rho"],
                    p["h"], level=level,
                    bed=None if level is None else np.zeros_like(X))[0]
    d = np.nan_to_num(d).reshape(S.shape)
    d_exact, _ = exact.ritter(s, ch.t_end, ch.d0, x_dam=ch.x_dam)
    mean = d.mean(axis=0)
    front = (metrics.front_position(s, mean, FRONT_DEPTH_M)
             - metrics.front_position(s, d_exact, FRONT_DEPTH_M))
    return {"l1": metrics.l1_relative(mean, d_exact),
            "l1_wall_lines": metrics.l1_relative(d[[0, -1]].mean(axis=0), d_exact),
            "l1_middle_lines": metrics.l1_relative(d[[1, 2]].mean(axis=0), d_exact),
            "front_error_m": float(front),
            "outside": max(smp.outside for smp in run.samples)}


@dataclass(frozen=True)
class Check:
    """One target: a figure [SI] that must stay at or below ``limit`` (``two_sided``: within
    +/- ``limit``)."""

    name: str
    value: float
    limit: float
    two_sided: bool = False

    @property
    def met(self) -> bool:
        return bool((abs(self.value) if self.two_sided else self.value) <= self.limit)

    @property
    def limit_text(self) -> str:
        return f"{'+/- ' if self.two_sided else '<= '}{self.limit:g}"


def still_checks(run: CaseRun) -> list[Check]:
    """The still-water case's targets against its worst figures after t = 0."""
    lim = run.case.limits
    out = []
    for name, figure, limit in (("max speed", "max_speed", lim.max_speed),
                                ("p95 speed", "p95_speed", lim.p95_speed),
                                ("level", "level_error", lim.level),
                                ("shore", "shore_error", lim.shore)):
        if limit is not None:
            out.append(Check(name, run.worst(figure), limit))
    if lim.outside_cells is not None:
        out.append(Check("cells outside", run.figures["cells_outside_wet"], lim.outside_cells))
    return out


def dam_break_checks(runs: list[CaseRun]) -> list[Check]:
    """The orientation targets over the dam-break runs (the first: along x)."""
    base = runs[0].figures["l1"]
    out = [Check(f"L1 {r.case.label} / L1 along x - 1", r.figures["l1"] / base - 1.0,
                 ORIENTATION_TOLERANCE, two_sided=True) for r in runs[1:]]
    out += [Check(f"L1 wall / middle lines - 1, {r.case.label}",
                  r.figures["l1_wall_lines"] / r.figures["l1_middle_lines"] - 1.0,
                  ORIENTATION_TOLERANCE) for r in runs]
    out += [Check(f"outside {r.case.label}", r.figures["outside"], 0) for r in runs]
    return out


def verdict(checks: list[Check]) -> str:
    """"pass", or "miss: " and the targets missed."""
    missed = [c.name for c in checks if not c.met]
    return "pass" if not missed else "miss: " + ", ".join(missed)


def target_text(limits: cases.Limits) -> str:
    """The issue's targets of a case, as the table shows them."""
    parts = []
    if limits.max_speed is not None:
        parts.append(f"max < {100 * limits.max_speed:g} cm/s")
    if limits.p95_speed is not None:
        parts.append(f"p95 < {100 * limits.p95_speed:g} cm/s")
    if limits.level is not None:
        parts.append(f"level within {100 * limits.level:g} cm")
    if limits.shore is not None:
        parts.append(f"shore within {limits.shore:g} m")
    if limits.outside_cells is not None:
        parts.append("no cell outside wet")
    return ", ".join(parts)


def still_row(run: CaseRun) -> dict:
    """The main table's row of a still-water run (speeds in cm/s, level error in cm)."""
    other = ""
    if run.case.shore is not None:
        other = (f"shore {run.worst('shore_error'):.2f} m "
                 f"({run.samples[0].shore_error:.2f} m at 0 s)")
    if run.case.reservoir is not None:
        f = run.figures
        other = (f"cells outside wet {f['cells_outside_wet']} "
                 f"({f['cells_outside_wet_at_0']} at 0 s)")
    return {"case": run.case.label, "particles": run.samples[0].particles,
            "end s": run.manifest["sim_time_s"],
            "max speed cm/s": 100 * run.worst("max_speed"),
            "p95 speed cm/s": 100 * run.worst("p95_speed"),
            "level error cm": 100 * run.worst("level_error"),
            "level error at 0 s cm": 100 * run.samples[0].level_error,
            "level p95 cm": 100 * run.worst("level_p95"),
            "splits / merges": f"{run.manifest['splits']} / {run.manifest['merges']}",
            "other": other, "target": target_text(run.case.limits),
            "result": verdict(still_checks(run)), "wall s": run.manifest["wall_time_s"]}


def dam_break_rows(runs: list[CaseRun]) -> list[dict]:
    return [{"case": r.case.label, "particles": r.samples[0].particles,
             "end s": r.manifest["sim_time_s"], "L1 %": 100 * r.figures["l1"],
             "L1 wall lines %": 100 * r.figures["l1_wall_lines"],
             "L1 middle lines %": 100 * r.figures["l1_middle_lines"],
             "front error m": r.figures["front_error_m"],
             "particles outside": r.figures["outside"],
             "max speed m/s": r.worst("max_speed"), "wall s": r.manifest["wall_time_s"]}
            for r in runs]


def sample_rows(runs: list[CaseRun]) -> list[dict]:
    return [{"case": r.case.label, "t_s": s.t, "particles": s.particles,
             "max_speed_ms": s.max_speed, "p95_speed_ms": s.p95_speed,
             "level_error_m": s.level_error, "level_p95_m": s.level_p95,
             "shore_error_m": s.shore_error,
             "outside": s.outside} for r in runs for s in r.samples]


def over_time_rows(runs: list[CaseRun], columns: int = 5) -> list[dict]:
    """max / p95 speed [cm/s] of each still-water run at ``columns`` of its report times."""
    rows = []
    for r in runs:
        later = r.later
        picks = later[len(later) // columns - 1::len(later) // columns] if later else []
        row = {"case": r.case.label}
        for k, s in enumerate(picks[:columns]):
            row[f"t{k + 1}"] = (f"{s.t:g} s: {readable_number(100 * s.max_speed)} / "
                                f"{readable_number(100 * s.p95_speed)}")
        rows.append(row)
    return rows


def build_cases(kinds, folder: Path, quick: bool, end_times: dict) -> list[cases.Case]:
    """The cases of ``kinds`` as scenario folders under ``folder``."""
    out = []
    for kind in kinds:
        t = end_times[kind]
        if kind == "rectangle":
            out += [cases.rectangle(folder / f"rectangle-{a:g}", a, t, quick)
                    for a in cases.RECTANGLE_ANGLES]
        elif kind == "staircase":
            out.append(cases.staircase(folder / "staircase", t, quick))
        elif kind == "bowl":
            out.append(cases.bowl(folder / "bowl", t, quick))
        elif kind == "building":
            out.append(cases.building(folder / "building", t, quick))
        elif kind == "dam-break":
            out += [cases.dam_break(folder / f"dam-break-{a:g}", a, t, quick)
                    for a in cases.DAM_BREAK_ANGLES]
        else:
            data = cases.mp_setup.data_folder()
            if data is None:
                print("malpasset: the benchmark data is not there ($FLOODSPH_BENCHMARKS or "
                      "<repo>/../shared/benchmarks/malpasset); skipped", flush=True)
                continue
            out.append(cases.malpasset(folder / "malpasset", t, data))
    return out


def set_numerics(case: cases.Case, keys: dict) -> None:
    """Write ``keys`` into the ``[numerics]`` table of the case's scenario file."""
    import tomllib

    import tomli_w

    data = tomllib.loads(case.scenario.read_text(encoding="utf-8"))
    data.setdefault("numerics", {}).update(keys)
    case.scenario.write_text(tomli_w.dumps(data), encoding="utf-8")


def end_times(args) -> dict:
    """Each kind's end time [s]: the default (or quick) one times ``--time-scale``, unless
    ``--end-time KIND=SECONDS`` sets it."""
    base = QUICK_END_TIME_S if args.quick else END_TIME_S
    out = {k: v * args.time_scale for k, v in base.items()}
    for item in args.end_time or []:
        kind, _, value = item.partition("=")
        if kind not in KINDS:
            raise SystemExit(f"--end-time {item}: {kind!r} is not one of {', '.join(KINDS)}")
        try:
            out[kind] = float(value)
        except ValueError:
            raise SystemExit(f"--end-time {item}: {value!r} is not a number of seconds") from None
        if not out[kind] > 0:
            raise SystemExit(f"--end-time {item}: the end time must be > 0 s")
    return out


@dataclass
class Benchmark:
    """Every run of one benchmark invocation, and the machine's state around it."""

    still: list[CaseRun]
    dam_break: list[CaseRun]
    command: str
    load: tuple[float, float]
    """1-minute load average at the start and at the end"""
    wall_s: float


def run_benchmark(args) -> Benchmark:
    t0 = time.perf_counter()
    load0 = os.getloadavg()[0]
    kinds = args.cases or [k for k in KINDS if not (args.quick and k == "malpasset")]
    runs = []
    numerics = {k: getattr(args, k) for k in ("wall_model", "stabilisation", "momentum")
                if getattr(args, k)}
    for case in build_cases(kinds, args.out / "scenarios", args.quick, end_times(args)):
        if numerics:
            set_numerics(case, numerics)
        runs.append(run_case(case, args.out / "runs" / case.scenario.parent.name))
        print(f"{case.label}: done, {runs[-1].manifest['wall_time_s']:.1f} s", flush=True)
    command = " ".join(["NUMBA_NUM_THREADS=" + os.environ.get("NUMBA_NUM_THREADS", "(all)"),
                        "python benchmarks/still_water.py", *args.argv])
    return Benchmark([r for r in runs if r.case.channel is None],
                     [r for r in runs if r.case.channel is not None], command,
                     (load0, os.getloadavg()[0]), time.perf_counter() - t0)


def readable_number(x) -> str:
    """Three significant digits without an exponent from 0.001 up (integers as they are)."""
    if not isinstance(x, float):
        return str(x)
    if x == 0.0 or not math.isfinite(x):
        return f"{x:g}"
    if abs(x) >= 100.0:
        return f"{x:.0f}"
    return f"{x:.3g}" if abs(x) >= 1e-3 else f"{x:.1e}"


def readable(rows: list[dict]) -> list[dict]:
    return [{k: readable_number(v) for k, v in row.items()} for row in rows]


def tables(bench: Benchmark) -> list[str]:
    """The report's tables (markdown), each with its heading."""
    from floodsph.output.tables import markdown

    out = []
    if bench.still:
        out += ["## Still water", "",
                "Worst value over the report times after 0 s; `level error at 0 s` is the "
                "seeded state's.", "",
                markdown(readable([still_row(r) for r in bench.still])), "",
                "## Speeds over time", "",
                "max / p95 particle speed [cm/s] at five of the report times.", "",
                markdown(over_time_rows(bench.still)), ""]
        for r in bench.still:
            if r.case.reservoir is not None:
                f = r.figures
                out += ["## Malpasset at rest: the maps", "", markdown(readable([{
                    "cells outside wet": f["cells_outside_wet"],
                    "of them at 0 s": f["cells_outside_wet_at_0"],
                    "max_level over the reservoir m": f["max_level_m"],
                    "max_speed median m/s": f["max_speed_median"],
                    "max_speed p95 m/s": f["max_speed_p95"],
                    "max_speed max m/s": f["max_speed_max"]}])), ""]
    if bench.dam_break:
        checks = dam_break_checks(bench.dam_break)
        out += ["## Dam break along x and turned", "",
                markdown(readable(dam_break_rows(bench.dam_break))), "",
                markdown([{"figure": c.name, "value": readable_number(c.value),
                           "target value": c.limit_text,
                           "result": "pass" if c.met else "miss"} for c in checks]), ""]
    return out


def machine_note(bench: Benchmark) -> str:
    return provenance.machine_note(bench.load, bench.wall_s,
                                   "Wall times are of this machine and this run.")


MEASURES = (
    "* Speeds are the particles' |v|; the level error is max |d + b - L| over the particles "
    "(d the SPH depth, b the bed under the particle, L the lake's level; under the balanced "
    "momentum the particle's level eta = d + b + o), `level p95` its "
    "95th percentile.",
    "* Bowl: the shore error is the largest |r_out - r_s| over 36 sectors, r_out the "
    "outermost particle of a sector, r_s the exact shoreline.",
    "* Malpasset: cells outside the reservoir (the initial depth raster's cells at 100 m) "
    "wet in `max_depth.tif` (> the wet threshold, 1 cm); `at 0 s` those the map of the "
    "particles at t = 0 already wets (the kernel smoothing of the maps alone); the "
    "`max_level.tif` and `max_speed.tif` figures are over the reservoir's cells.",
    "* Dam break: L1 of the depth on four lines along the channel against Ritter; the lines "
    "next to the walls (12.5 and 87.5 m from them) against the two middle ones measure "
    "wall-hugging jets (target: no more than 25 % worse); particles outside the channel at "
    "any report time; the turned channel's L1 within 25 % of the one along x, either way.",
)


def report(bench: Benchmark, picture: Path | None) -> str:
    lines = ["# Still water at walls, nodata borders, shores and buildings", "",
             f"Made by `{bench.command}` on {time.strftime('%Y-%m-%d')} at commit "
             f"`{provenance.commit(REPO)}`; {machine_note(bench)}", "",
             "Each case is a scenario (DEM GeoTIFF, `[[initial_water]]`, `[[walls]]`, closed "
             "edges, default numerics) run with `floodsph.run.pipeline.run_scenario`; "
             "`benchmarks/still_water.py` and `benchmarks/still_water_cases.py` say how each is "
             "built and measured. The synthetic beds are frictionless in effect "
             f"(n = {cases.FRICTIONLESS_N:g}), 5 m DEM cells and spacing (the dam break 10 m).",
             "", *MEASURES, "", *tables(bench)]
    if picture is not None:
        lines += [f"![particle speeds over time]({picture.name})", ""]
    return "\n".join(lines)


def plot(path: Path, runs: list[CaseRun]) -> Path | None:
    """Largest and 95th-percentile particle speed over time, one line per still-water run."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    for r in runs:
        t = [s.t for s in r.later]
        for ax, name in zip(axes, ("max_speed", "p95_speed"), strict=True):
            ax.semilogy(t, np.maximum([getattr(s, name) for s in r.later], PLOT_FLOOR_MS),
                        label=r.case.label)
    for ax, title in zip(axes, ("largest particle speed", "95th percentile"), strict=True):
        ax.set_title(title)
        ax.set_ylim(bottom=0.5 * PLOT_FLOOR_MS)
        ax.set_xlabel("t [s]")
        ax.axhline(0.01, color="grey", lw=0.8, ls="--")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel(f"speed [m/s] (below {PLOT_FLOOR_MS:g}: drawn at it)")
    fig.tight_layout(rect=(0.0, 0.12, 1.0, 1.0))
    fig.legend(*axes[0].get_legend_handles_labels(), loc="lower center", ncol=5, fontsize=8)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def write_outputs(bench: Benchmark, out: Path, doc: Path) -> None:
    from floodsph.output.tables import write_csv

    runs = bench.still + bench.dam_break
    write_csv(out / "still_water_samples.csv", sample_rows(runs))
    if bench.still:
        write_csv(out / "still_water.csv", [still_row(r) for r in bench.still])
    doc.parent.mkdir(parents=True, exist_ok=True)
    picture = plot(doc.with_suffix(".png"), bench.still) if bench.still else None
    doc.write_text(report(bench, picture), encoding="utf-8")


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", choices=KINDS, help="default: all (--quick: all "
                    "but malpasset)")
    ap.add_argument("--time-scale", type=float, default=1.0,
                    help="multiplies every case's end time")
    ap.add_argument("--end-time", nargs="+", metavar="CASE=SECONDS",
                    help="end times of single cases (over --time-scale)")
    ap.add_argument("--quick", action="store_true", help="tiny, short synthetic cases")
    ap.add_argument("--wall-model", choices=("mirror", "integral"),
                    help="[numerics] wall_model of every case (default: the scenario default)")
    ap.add_argument("--stabilisation", choices=("lax-friedrichs", "riemann", "muscl"),
                    help="[numerics] stabilisation of every case (default: the scenario "
                    "default)")
    ap.add_argument("--momentum", choices=("variational", "balanced"),
                    help="[numerics] momentum of every case (default: the scenario default)")
    ap.add_argument("--out", type=Path, default=Path("results/still_water"))
    ap.add_argument("--doc", type=Path, help="the report (default docs/still-water.md; with "
                    "--quick <out>/still-water.md)")
    args = ap.parse_args(argv)
    if not args.time_scale > 0:
        ap.error(f"--time-scale must be > 0, got {args.time_scale:g}")
    args.argv = list(sys.argv[1:] if argv is None else argv)
    if args.doc is None:
        args.doc = args.out / "still-water.md" if args.quick else REPO / "docs" / "still-water.md"
    return args


def main(argv=None) -> Benchmark:
    args = parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    bench = run_benchmark(args)
    print("\n".join(tables(bench)), flush=True)
    write_outputs(bench, args.out, args.doc)
    print(f"wrote {args.doc}", flush=True)
    return bench


if __name__ == "__main__":
    main()
