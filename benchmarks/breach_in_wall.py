"""A breach opening in a crest-wall dam, against the level-pool routed hydrograph of the same
breach (``data_samples/valley_dam``, ``docs/structures.md`` §3, ``docs/breach.md`` §2).

The sample holds the valley's reservoir as water behind a crest wall across the gorge; a
``[walls.breach]`` opens in the wall and the model computes the water through it. This script

1. tabulates the reservoir's storage from the DEM: V(L) = sum over the cells whose centre lies
   in the ``[[initial_water]]`` polygon and whose bed z is below L of (L - z) dx dy [m3], every
   ``STORAGE_STEP_M`` from the lowest bed to the crest (``reservoir_storage``);
2. routes the same breach through that storage with ``floodsph.breach`` (level pool, free
   trapezoidal weir, ``docs/breach.md`` §2), mapped as :func:`level_pool_params` says: the
   level-pool breach starts at the water level, so it is the part of the wall's breach below
   the lake, started when the wall's notch reaches the water;
3. runs the sample (``--spacing`` may coarsen it) and reads the outflow hydrograph through the
   flux line just below the dam from ``flux.csv``, smoothed by a centred running mean over
   ``--smooth`` seconds (a particle carries its whole volume across at once, so single rows
   scatter, ``docs/outputs.md``);
4. compares the peak discharge, its time and the volume released by the end of the run
   (targets: 10 %, 10 %, 1 %), and checks the flux-line volume against the change of the
   water volume downstream of the line, counted from the particles every ``--interval`` s,
   plus what left the model there (target 0.1 %), and the wall's passed volume against the
   reservoir's loss.
5. ``--still S`` also runs the reservoir at rest behind the intact wall for S seconds with
   each momentum (``docs/balanced-momentum.md``) and reports how far the level strays.

The sample's spacing, 10 m, is the coarsest that runs: at 20 m the balanced momentum stops
within the first seconds with a negative depth at the reservoir's shore, with or without the
wall. ``--reuse`` writes the page again from the results of the runs kept in ``--runs``.

Usage: ``python benchmarks/breach_in_wall.py [--scenario data_samples/valley_dam/scenario.toml]
[--spacing 10] [--end 7200] [--smooth 60] [--still 600] [--runs DIR] [--reuse] [--out
docs/breach-in-wall.md]``
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import json
import math
import tempfile
import time
from pathlib import Path

import numpy as np

from floodsph.api import run_scenario
from floodsph.boundaries.crest import Crest, resolve_breach
from floodsph.boundaries.weir import IDEAL_COEFFICIENT, Weir, unit_discharge
from floodsph.breach import BreachParams, breach_hydrograph
from floodsph.breach.formulas import progression, trapezoid_weir_discharge
from floodsph.breach.params import resolve
from floodsph.breach.storage import read_storage_table
from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.io.hydrograph import Hydrograph
from floodsph.io.polygons import points_in_polygon
from floodsph.io.raster import read_grid
from floodsph.scenario.numerics import Momentum
from floodsph.scenario.reader import load_scenario
from floodsph.simulation.schedules import TimeInterval

SCENARIO = Path(__file__).resolve().parent.parent / "data_samples" / "valley_dam" / "scenario.toml"
STORAGE_STEP_M = 0.1
START_DISCHARGE = 1.0
"""The outflow starts when the discharge first exceeds this [m3/s]."""
TARGETS = {"peak": 0.10, "time": 0.10, "volume": 0.01, "balance": 0.001}


def reservoir_storage(scenario, step: float = STORAGE_STEP_M):
    """Elevations [m] and the volume V(L) [m3] stored below each within the reservoir polygon
    (the first ``[[initial_water]]`` body), from the lowest bed there to the highest crest."""
    grid = read_grid(scenario.terrain.dem, what="DEM")
    t = grid.transform
    rows, cols = grid.shape
    x = t.c + (np.arange(cols) + 0.5) * t.a
    y = t.f + (np.arange(rows) + 0.5) * t.e
    X, Y = np.meshgrid(x, y)
    inside = points_in_polygon(X.ravel(), Y.ravel(), np.asarray(scenario.initial_water[0].polygon))
    z = grid.values.ravel()[inside & np.isfinite(grid.values.ravel())]
    top = max(float(np.max(np.atleast_1d(w.crest_m))) for w in scenario.walls)
    levels = np.arange(math.floor(z.min() / step) * step, top + step, step)
    cell = grid.dx * grid.dy
    volume = np.array([np.sum(np.maximum(level - z, 0.0)) * cell for level in levels])
    return levels, volume


def write_storage_csv(path: Path, levels, volume) -> Path:
    """The storage table as ``floodsph breach`` reads it (``elevation_m,volume_m3``), from the
    first elevation with water; volumes strictly increasing."""
    keep = volume > 0.0
    keep[np.argmax(keep) - 1] = True  # the empty level just below, where the storage starts
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["elevation_m", "volume_m3"])
        for level, v in zip(levels[keep], volume[keep], strict=True):
            w.writerow([f"{level:.3f}", f"{v:.3f}"])
    return path


def wall_breach(scenario):
    """The crest (with its breach) and the resolved breach of the scenario's first wall."""
    wall = scenario.walls[0]
    intact = Crest(np.asarray(wall.polyline), wall.crest_m)
    breach = resolve_breach(wall.breach, intact, "walls[0].breach")
    return Crest(intact.polyline, wall.crest_m, breach), breach


def level_pool_params(scenario, storage_csv: Path, duration_s: float) -> BreachParams:
    """The ``floodsph breach`` parameters of the wall's breach below the lake level H0.

    The wall's breach (linear growth) lowers its bottom from the crest z_top at the centre to
    the invert z_i over t_f, z_b = z_top - (z_top - z_i) tau, and widens its bottom to B. The
    level-pool breach starts at the water level, so it is given the part below the lake:
    height H0 - z_i, start t_s + t_f (z_top - H0) / (z_top - z_i) (when the notch reaches the
    water), formation time t_f (H0 - z_i) / (z_top - z_i), and the average width B + m (H0 -
    z_i) (bottom width B, side slopes m). The bottom elevation is then the wall's at every
    time; the bottom width lags the wall's by B (z_top - H0) / (z_top - z_i) at the start of
    the level-pool breach, by nothing at the end. The weir coefficient is the wall's,
    C sqrt(g) with C the ideal broad crest's (2/3)^1.5.
    """
    crest, breach = wall_breach(scenario)
    if breach.growth != "linear":
        raise SystemExit("the mapping onto the level-pool breach needs growth = \"linear\"")
    top = float(crest.base(breach.centre_m))
    level = scenario.initial_water[0].level_m
    drop = top - breach.invert_m
    below = level - breach.invert_m
    coefficient = scenario.walls[0].discharge_coefficient or IDEAL_COEFFICIENT
    return BreachParams.from_mapping({
        "breach_height_m": below, "initial_level_m": level, "breach_invert_m": breach.invert_m,
        "storage_table": str(storage_csv), "progression": "linear",
        "weir_coefficient": coefficient * math.sqrt(GRAVITY),
        "average_width_m": breach.bottom_width_m + breach.side_slope * below,
        "formation_time_s": breach.formation_s * below / drop,
        "start_time_s": breach.start_s + breach.formation_s * (top - level) / drop,
        "duration_s": duration_s, "dt_s": 5.0})


class Probe:
    """A callback: at each call, a row of the time [s], the water volume on the right of a
    straight flux line (the half-plane downstream of it) from the particles, the net volume
    through the line so far, the model's outflow so far, the volume upstream of the wall
    (x below it) [m3], and the mean level [m] of the wet particles (deeper than 1 cm) in a
    box 40 m by 40 m upstream and downstream of the breach centre ``(xc, yc)`` (local)."""

    BOX = 40.0
    COLUMNS = ("time_s", "downstream_m3", "through_m3", "out_m3", "reservoir_m3",
               "level_up_m", "level_down_m")

    def __init__(self, line: int, wall_x: float, centre: tuple[float, float]):
        self.line, self.wall_x, self.centre = line, wall_x, centre
        self.rows: list[dict[str, float]] = []

    def __call__(self, sim) -> None:
        model = sim.model
        p = model.particles
        lines = model.flux_lines
        ax, ay, bx, by = lines.seg[lines.owner == self.line][0]
        right = (bx - ax) * (p.y - ay) - (by - ay) * (p.x - ax) < 0.0
        volume = p.m / RHO_WATER
        depth = model.depth()
        level = depth + model.state.bed[: p.n, 0]
        xc, yc = self.centre
        near = (np.abs(p.y - yc) < 0.5 * self.BOX) & (depth > 0.01)
        up = near & (p.x < xc) & (p.x > xc - self.BOX)
        down = near & (p.x > xc) & (p.x < xc + self.BOX)
        values = (float(model.t), float(np.sum(volume[right])),
                  float(lines.forward[self.line] - lines.backward[self.line]),
                  float(model.state.volume_out), float(np.sum(volume[p.x < self.wall_x])),
                  float(np.mean(level[up])) if up.any() else math.nan,
                  float(np.mean(level[down])) if down.any() else math.nan)
        self.rows.append(dict(zip(self.COLUMNS, values, strict=True)))


def run_sample(scenario, folder: Path, interval: float):
    """Run the scenario into ``folder``; return its run.json and the :class:`Probe` rows of
    the first flux line."""
    names = [line.name for line in scenario.flux_lines]
    crest, breach = wall_breach(scenario)
    grid = read_grid(scenario.terrain.dem, what="DEM")
    x0, y0 = grid.transform.c, grid.transform.f - grid.shape[0] * grid.dy  # the local origin
    xs, ys = np.asarray(scenario.walls[0].polyline).T
    centre = (float(np.interp(breach.centre_m, crest.s, xs)) - x0,
              float(np.interp(breach.centre_m, crest.s, ys)) - y0)
    probe = Probe(names.index(scenario.flux_lines[0].name), float(np.mean(xs)) - x0, centre)
    started = time.monotonic()
    result = run_scenario(scenario, folder, progress=False, overwrite=True,
                          callbacks=[(probe, TimeInterval(interval))])
    manifest = json.loads((result.folder / "run.json").read_text())
    manifest["wall_clock_s"] = time.monotonic() - started
    return manifest, probe.rows


def read_flux(folder: Path, name: str):
    """Times [s] and mean discharges [m3/s] of one line of ``flux.csv``."""
    with open(folder / "flux.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return (np.array([float(r["time_s"]) for r in rows]),
            np.array([float(r[name + "_m3s"]) for r in rows]))


def running_mean(q, width: int):
    """Centred running mean over ``width`` samples (shorter windows at the ends)."""
    kernel = np.ones(width)
    return np.convolve(q, kernel, "same") / np.convolve(np.ones_like(q), kernel, "same")


def compare(t_model, q_model, t_pool, q_pool, end: float, smooth_s: float) -> dict:
    """Peak, time to peak and volume by ``end`` of the model (smoothed) and the level pool."""
    step = float(t_model[1] - t_model[0])
    smooth = running_mean(q_model, max(1, round(smooth_s / step)))
    k = int(np.argmax(smooth))
    j = int(np.argmax(q_pool))
    volume_model = float(np.sum(q_model) * step)  # each row: the mean over its interval
    volume_pool = float(Hydrograph(t_pool, q_pool).volume(0.0, end))
    t_peak_model = float(t_model[k]) - 0.5 * step  # the row's interval midpoint
    return {
        "peak_model": float(smooth[k]), "peak_pool": float(q_pool[j]),
        "time_model": t_peak_model, "time_pool": float(t_pool[j]),
        "volume_model": volume_model, "volume_pool": volume_pool,
        "peak_err": float(smooth[k] / q_pool[j] - 1.0),
        "time_err": t_peak_model / float(t_pool[j]) - 1.0,
        "volume_err": volume_model / volume_pool - 1.0,
        "smooth": smooth, "t_model": t_model, "t_pool": t_pool, "q_pool": q_pool,
        "start_model": float(t_model[np.argmax(q_model > START_DISCHARGE)]),
        "start_pool": float(t_pool[np.argmax(q_pool > START_DISCHARGE)]),
    }


def balance(rows) -> dict:
    """The volume through the line against the change downstream plus the outflow, and the
    reservoir's loss, from the first and the last :class:`Probe` rows."""
    first, last = rows[0], rows[-1]
    gained = (last["downstream_m3"] - first["downstream_m3"]) + (last["out_m3"]
                                                                  - first["out_m3"])
    through = last["through_m3"] - first["through_m3"]
    error = gained / through - 1.0 if through else math.nan
    return {"through": through, "gained": gained, "balance_err": error,
            "reservoir_loss": first["reservoir_m3"] - last["reservoir_m3"],
            "time": last["time_s"]}


def capacities(weir: Weir, breach, setup, level: float, t: float) -> tuple[float, ...]:
    """Free weir discharge [m3/s] at a reservoir level [m] and time t [s] of: the model's
    wall, its law on each piece at the crest of the piece's midpoint; the wall's trapezoid
    itself, q integrated exactly over the bottom and the sloping sides,
    C sqrt(g) (b y^1.5 + 0.8 m y^2.5) with y the head on the bottom; and the level pool's
    breach (``floodsph.breach.formulas.trapezoid_weir_discharge``, its own bottom and width
    at t, sides 2.45 / 3.1 of the bottom's coefficient)."""
    pieces = float(np.sum(weir.length * unit_discharge(level - weir.crest_now(t),
                                                       coefficient=weir.coefficient)))
    r = breach.fraction(t)
    top = float(weir.crest.base(breach.centre_m))
    y = max(level - (top - r * (top - breach.invert_m)), 0.0)
    wall = weir.coefficient * math.sqrt(GRAVITY) * (
        r * breach.bottom_width_m * y**1.5 + 0.8 * breach.side_slope * y**2.5)
    p = setup.params
    r_pool = progression((t - p.start_time_s) / setup.formation_time_s, p.progression)
    pool = trapezoid_weir_discharge(
        level, setup.top_m - r_pool * (setup.top_m - setup.invert_m),
        r_pool * setup.bottom_width_m, setup.side_slope, p.weir_coefficient)
    return pieces, wall, pool


def levels_at(rows, when: float, storage, t_pool, q_pool, weir, breach, setup) -> dict:
    """At the probe row nearest ``when`` [s]: the level pool's level, the level the model's
    reservoir volume would have if flat, the mean levels by the breach upstream and
    downstream, the breach bottom [m], and the :func:`capacities` at the level pool's level."""
    row = min(rows, key=lambda r: abs(r["time_s"] - when))
    t = row["time_s"]
    released = Hydrograph(t_pool, q_pool).volume(0.0, t)
    pool = storage.level(rows[0]["reservoir_m3"] - released)
    return {"time": t, "pool": pool, "flat": storage.level(row["reservoir_m3"]),
            "up": row["level_up_m"], "down": row["level_down_m"],
            "bottom": float(weir.crest.at([breach.centre_m], t)[0]),
            "capacity": capacities(weir, breach, setup, pool, t)}


def still_lake(scenario, seconds: float, root: Path) -> list[dict]:
    """The reservoir behind the intact wall (the breach moved past the end) for ``seconds``
    with each momentum: the largest speed, the volume passed over the wall, and the largest
    departure of the level from the initial one in the reservoir at the end."""
    wall = scenario.walls[0]
    intact = dataclasses.replace(wall, breach=dataclasses.replace(wall.breach,
                                                                  start_s=10.0 * seconds))
    out = []
    level0 = scenario.initial_water[0].level_m
    for momentum in (Momentum.VARIATIONAL, Momentum.BALANCED):
        case = dataclasses.replace(
            scenario, walls=(intact,), flux_lines=(), gauges=None,
            scenario=dataclasses.replace(scenario.scenario, end_time_s=seconds,
                                         name=f"still-{momentum.value}"),
            numerics=dataclasses.replace(scenario.numerics, momentum=momentum))
        final: dict[str, float] = {}

        def last(sim, final=final) -> None:
            model = sim.model
            p = model.particles
            level = model.depth() + model.state.bed[: p.n, 0]
            final.update(speed=float(np.max(np.hypot(p.u, p.v))),
                         stray=float(np.max(np.abs(level - level0))))

        result = run_scenario(case, root / f"still-{momentum.value}", progress=False,
                              overwrite=True, callbacks=[(last, TimeInterval(seconds))])
        manifest = json.loads((result.folder / "run.json").read_text())
        passed = manifest["walls_overtopped_m3"]["walls[0]"]
        out.append({"momentum": momentum.value, **final,
                    "passed": passed["left_to_right_m3"] + passed["right_to_left_m3"]})
    return out


def why(diag, cmp, spacing: float, breach) -> list[str]:
    """The paragraph that explains the differences, with the figures of ``diag`` at the
    model's peak: the pieces' capacity over the trapezoid's, the head by the breach over the
    flat reservoir's, and Villemonte's factor (``docs/structures.md`` §2) for the levels by
    the breach."""
    d = diag["peak"]
    pieces, trapezoid, pool = d["capacity"]
    head_up, head_flat = d["up"] - d["bottom"], d["flat"] - d["bottom"]
    ratio = max(d["down"] - d["bottom"], 0.0) / head_up
    factor = (1.0 - ratio**1.5) ** 0.385
    return [
        "**Why they differ.** The weir law and its coefficient are the same (C sqrt(g) per "
        "metre; the level pool's sides take Fread's 2.45 / 3.1 = 0.790 of it where the "
        "exact integral over a 1:1 side gives 0.8), and so is the breach's bottom at every "
        "time. What differs:",
        "",
        f"- *The wall's pieces.* At a {spacing:g} m spacing the wall is cut into pieces "
        f"{spacing:g} m long, each passing the law at the crest of its midpoint: the "
        f"{breach.bottom_width_m:.1f} m breach is a few pieces. At the peak they pass "
        f"{pieces / trapezoid:.2f} times what the trapezoid passes at the same level "
        f"({pieces:.0f} against {trapezoid:.0f} m3/s; the level pool's breach {pool:.0f}). "
        "The breach centre lies on the boundary between two pieces, so a notch narrower "
        "than a piece passes little until it has widened: the model's outflow exceeds "
        f"{START_DISCHARGE:g} m3/s at {cmp['start_model']:.0f} s, the level pool's at "
        f"{cmp['start_pool']:.0f} s, and by {cmp['time_pool']:.0f} s the model has released "
        f"{100 * (1 - diag['volume_by_peak'][0] / diag['volume_by_peak'][1]):.0f} % less.",
        "- *2-D drawdown.* The water accelerates towards the breach: at the peak the level "
        f"by the breach stands {d['flat'] - d['up']:.2f} m below the level the reservoir "
        f"would have at rest, a head on the bottom of {head_up:.2f} m instead of "
        f"{head_flat:.2f} m, which passes {(head_up / head_flat) ** 1.5:.2f} times as much "
        "by the law. The level pool takes the whole reservoir at one level; the wall reads "
        "the level of the approaching water, and its velocity head is not counted.",
        "- *Tailwater.* Below the breach the gorge stands "
        f"{max(d['down'] - d['bottom'], 0.0):.2f} m above the breach bottom at the peak, "
        f"{ratio:.2f} of the upstream head: Villemonte's factor for that is {factor:.2f}. "
        "The wall reduces its discharge by the tailwater it reads; the level pool is free "
        "flow always.",
        f"- Together, {pieces / trapezoid:.2f} x {(head_up / head_flat) ** 1.5:.2f} x "
        f"{factor:.2f} = {pieces / trapezoid * (head_up / head_flat) ** 1.5 * factor:.2f}, "
        f"against the peaks' ratio {1 + cmp['peak_err']:.2f}: roughly, since the levels "
        f"here are means over {Probe.BOX:g} m boxes, not the points the weir reads.",
        "- *After the peak* the model's reservoir stands higher than the level pool's (it "
        "has released less), so it releases more, and the volumes draw closer: "
        f"{100 * cmp['volume_err']:+.2f} % by the end of the run. The model's hydrograph "
        "also carries the particles' granularity (a particle crosses the line whole), "
        "smoothed here by the running mean.",
    ]


def page(args, scenario, pool, summary, cmp, bal, manifest, still, diag) -> str:
    """The markdown page ``docs/breach-in-wall.md``."""
    crest, breach = wall_breach(scenario)
    top = float(crest.base(breach.centre_m))
    ok = {key: "yes" if abs(value) <= TARGETS[key.split("_")[0]] else "no"
          for key, value in (("peak_err", cmp["peak_err"]), ("time_err", cmp["time_err"]),
                             ("volume_err", cmp["volume_err"]),
                             ("balance_err", bal["balance_err"]))}
    spacing = scenario.numerics.particle_spacing_m
    lines = [
        "# A breach in a crest-wall dam against the level-pool hydrograph",
        "",
        "Written by `python benchmarks/breach_in_wall.py "
        f"--spacing {spacing:g} --end {args.end:g} --smooth {args.smooth:g} "
        f"--still {args.still:g} --out docs/breach-in-wall.md`"
        f" ({time.strftime('%Y-%m-%d')}). The sample `data_samples/valley_dam` "
        "(docs/structures.md §3): the valley's reservoir, level "
        f"{pool.initial_level_m:g} m, as water behind a crest wall at {top:g} m across "
        f"the gorge; the breach opens from {breach.start_s:g} s down to {breach.invert_m:g} m "
        f"over {breach.formation_s:.0f} s, {breach.bottom_width_m:.1f} m wide at the bottom, "
        f"sides {breach.side_slope:g}:1 (Froehlich 2008, overtopping). Particle spacing "
        f"{spacing:g} m, {manifest['sim_time_s']:.0f} s simulated in "
        f"{manifest['wall_clock_s']:.0f} s on {manifest.get('threads', 1)} thread(s).",
        "",
        "The level pool is `floodsph breach` (docs/breach.md §2) with the reservoir's storage "
        "tabulated from the DEM in the initial-water polygon (every "
        f"{STORAGE_STEP_M:g} m), and the part of the wall's breach below the lake: it starts "
        f"when the wall's notch reaches the water ({pool.start_time_s:.0f} s), forms over "
        f"{pool.formation_time_s:.0f} s with the same bottom elevation at every time, and "
        "the weir coefficient of the wall, C sqrt(g) = "
        f"{pool.weir_coefficient:.4f} m^0.5/s (`benchmarks/breach_in_wall.py`, "
        "`level_pool_params`).",
        "",
        "| quantity | model (flux line below the dam) | level pool | difference | target | met |",
        "| --- | --- | --- | --- | --- | --- |",
        f"| peak discharge (m3/s; model: {args.smooth:g} s running mean) | "
        f"{cmp['peak_model']:.1f} | {cmp['peak_pool']:.1f} | {100 * cmp['peak_err']:+.1f} % | "
        f"10 % | {ok['peak_err']} |",
        f"| time to peak (s) | {cmp['time_model']:.0f} | {cmp['time_pool']:.0f} | "
        f"{100 * cmp['time_err']:+.1f} % | 10 % | {ok['time_err']} |",
        f"| volume released by {args.end:g} s (m3) | {cmp['volume_model']:.4g} | "
        f"{cmp['volume_pool']:.4g} | {100 * cmp['volume_err']:+.2f} % | 1 % | "
        f"{ok['volume_err']} |",
        "",
        f"The level pool releases {summary.released_volume_m3:.4g} m3 in all (it leaves "
        f"{summary.remaining_storage_m3:.3g} m3 above the invert when its outflow has faded, "
        f"at {summary.duration_s:.0f} s); the reservoir stores "
        f"{summary.initial_storage_m3:.4g} m3 above the invert at the start.",
        "",
        "**Mass balance of the flux line.** Volume through the line below the dam over the run "
        f"{bal['through']:.6g} m3; water downstream of it at the end less at the start, plus "
        f"the outflow from the model, {bal['gained']:.6g} m3 (particles counted every "
        f"{args.interval:g} s): difference {100 * bal['balance_err']:+.2g} % (target 0.1 %, "
        f"met: {ok['balance_err']}). The wall passed "
        f"{manifest['walls_overtopped_m3']['walls[0]']['left_to_right_m3']:.6g} m3 "
        f"downstream; the reservoir (water west of the wall) lost {bal['reservoir_loss']:.6g} "
        "m3. Model mass error over the run "
        f"{manifest['mass_error_rel']:.1e}.",
    ]
    by_peak = diag["volume_by_peak"]
    lines += [
        "",
        "**Levels** (the model's from the particles counted every "
        f"{args.interval:g} s: flat, the level its reservoir volume would have at rest; by "
        f"the breach, the mean level of the water in {Probe.BOX:g} m x {Probe.BOX:g} m "
        "boxes upstream and downstream of the breach centre):",
        "",
        "| time (s) | breach bottom (m) | level pool (m) | model, flat (m) "
        "| model, by the breach upstream (m) | downstream (m) "
        "| weir at the level pool's level (m3/s): wall's pieces / wall's trapezoid "
        "/ level pool's breach |",
        "| --- | --- | --- | --- | --- | --- | --- |",
        *(f"| {d['time']:.0f} | {d['bottom']:.2f} | {d['pool']:.2f} | {d['flat']:.2f} | "
          f"{d['up']:.2f} | {d['down']:.2f} | "
          f"{' / '.join(f'{c:.0f}' for c in d['capacity'])} |"
          for d in (diag["half"], diag["peak"], diag["late"])),
        "",
        f"By the level pool's peak ({cmp['time_pool']:.0f} s) the model had released "
        f"{by_peak[0]:.4g} m3, the level pool {by_peak[1]:.4g} m3 "
        f"({100 * (by_peak[0] / by_peak[1] - 1):+.1f} %).",
        "",
        *why(diag, cmp, spacing, breach),
    ]
    if still:
        lines += [
            "",
            f"**The still reservoir behind the intact wall** ({args.still:g} s, no breach):",
            "",
            "| momentum | largest speed (m/s) | largest level departure (m) "
            "| passed over the wall (m3) |",
            "| --- | --- | --- | --- |",
            *(f"| {s['momentum']} | {s['speed']:.3g} | {s['stray']:.3g} | {s['passed']:.3g} |"
              for s in still),
            "",
            "The wall holds the water either way (nothing passes below its crest), but with "
            "the default (variational) momentum the lake does not stay at rest behind the "
            "straight wall in this valley: particles move at up to "
            f"{still[0]['speed']:.2g} m/s and their levels stray by up to "
            f"{still[0]['stray']:.2g} m. The balanced momentum holds it exactly "
            "(docs/balanced-momentum.md), so the sample takes it.",
        ]
    lines += ["", f"**Hydrographs** (m3/s; the model's {args.smooth:g} s running mean):", "",
              "| time (s) | model | level pool |", "| --- | --- | --- |"]
    for t in np.arange(600.0, args.end + 1.0, 600.0):
        k = int(np.argmin(np.abs(cmp["t_model"] - t)))
        lines.append(f"| {t:.0f} | {cmp['smooth'][k]:.0f} | "
                     f"{np.interp(t, cmp['t_pool'], cmp['q_pool']):.0f} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", type=Path, default=SCENARIO)
    ap.add_argument("--spacing", type=float, default=None, help="particle spacing [m]")
    ap.add_argument("--end", type=float, default=None, help="simulated time [s]")
    ap.add_argument("--smooth", type=float, default=60.0, help="running mean [s]")
    ap.add_argument("--interval", type=float, default=60.0,
                    help="particles counted downstream every this many s")
    ap.add_argument("--still", type=float, default=0.0, help="still-lake runs [s]; 0: none")
    ap.add_argument("--runs", type=Path, default=None, help="run folders (default: temporary)")
    ap.add_argument("--out", type=Path, default=None, help="write the markdown page here")
    ap.add_argument("--reuse", action="store_true",
                    help="take the runs' results from --runs (results.json) if there")
    args = ap.parse_args(argv)

    scenario = load_scenario(args.scenario)
    end = args.end if args.end is not None else scenario.end_time_s
    args.end = end
    numerics = scenario.numerics
    if args.spacing is not None:
        numerics = dataclasses.replace(numerics, particle_spacing_m=args.spacing)
    scenario = dataclasses.replace(
        scenario, numerics=dataclasses.replace(numerics, threads=1),
        scenario=dataclasses.replace(scenario.scenario, end_time_s=end))
    root = args.runs or Path(tempfile.mkdtemp(prefix="breach_in_wall_"))
    root.mkdir(parents=True, exist_ok=True)

    storage_csv = write_storage_csv(root / "storage.csv", *reservoir_storage(scenario))
    params = level_pool_params(scenario, storage_csv, end)
    t_pool, q_pool, summary = breach_hydrograph(params)
    full = breach_hydrograph(dataclasses.replace(params, duration_s=None))[2]

    saved = root / "results.json"
    if args.reuse and saved.exists():
        results = json.loads(saved.read_text())
    else:
        manifest, rows = run_sample(scenario, root / "sample", args.interval)
        still = still_lake(scenario, args.still, root) if args.still > 0 else []
        results = {"manifest": manifest, "rows": rows, "still": still}
        saved.write_text(json.dumps(results))
    t_model, q_model = read_flux(root / "sample", scenario.flux_lines[0].name)
    cmp = compare(t_model, q_model, t_pool, q_pool, end, args.smooth)
    bal = balance(results["rows"])
    crest, breach = wall_breach(scenario)
    storage = read_storage_table(storage_csv, "storage")
    weir = Weir(crest, scenario.numerics.particle_spacing_m, scenario.numerics.kappa,
                scenario.walls[0].discharge_coefficient or IDEAL_COEFFICIENT)
    setup = resolve(params)
    diag = {name: levels_at(results["rows"], when, storage, t_pool, q_pool, weir, breach,
                            setup)
            for name, when in (("half", 0.5 * cmp["time_pool"]), ("peak", cmp["time_model"]),
                               ("late", 0.5 * (cmp["time_model"] + end)))}
    step = float(t_model[1] - t_model[0])
    diag["volume_by_peak"] = (float(np.sum(q_model[t_model <= cmp["time_pool"]]) * step),
                              Hydrograph(t_pool, q_pool).volume(0.0, cmp["time_pool"]))
    manifest, still = results["manifest"], results["still"]

    text = page(args, scenario, params, full, cmp, bal, manifest, still, diag)
    print(text)
    with open(root / "hydrographs.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time_s", "model_m3s", "model_smoothed_m3s", "level_pool_m3s"])
        for t, q, s in zip(t_model, q_model, cmp["smooth"], strict=True):
            w.writerow([f"{t:.1f}", f"{q:.3f}", f"{s:.3f}", f"{np.interp(t, t_pool, q_pool):.3f}"])
    if args.out is not None:
        args.out.write_text(text)


if __name__ == "__main__":
    main()
