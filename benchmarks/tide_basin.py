"""A tide in a flat basin open at one end: the far-end level against the forced standing wave
(``floodsph.boundaries.level``, ``docs/level-boundary.md``).

A flat rectangular basin, ``--length`` long (x) and ``--width`` wide, closed on three sides;
its east side is a level boundary whose level is the slow tide

    eta_B(t) = d_0 - A cos(omega t),   omega = 2 pi / T,

starting at low water, where the basin's water starts at rest. For a basin short against
the tide's wavelength the linear, frictionless response is the forced standing wave

    eta(x, t) = d_0 - A cos(k x) / cos(k L) cos(omega t),   k = omega / sqrt(g d_0),

(x from the closed west end; Dean and Dalrymple, Water wave mechanics for engineers and
scientists, 1991, section 4.7, with the mouth level imposed), which at the far end x = 0
exceeds the imposed tide by the factor 1 / cos(k L). The script measures the level at the
far end (the mean depth of the water within two spacings of the west wall) and reports, from
one period of spin-up to the end, the largest |error| against that standing wave and against
the imposed level, and the volume balance V_0 + V_in - V_out - V [m3] over the run.

Usage: ``python benchmarks/tide_basin.py [--length 100] [--width 10] [--spacing 2 [1 ...]]
[--periods 2] [--out docs/level-boundary-benchmark.md]``
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from floodsph.boundaries import LevelBoundary
from floodsph.checks.levels import SIDE_NORMALS, side_line
from floodsph.constants import GRAVITY
from floodsph.inputs.initial_water import particles_at
from floodsph.io.level_series import LevelSeries
from floodsph.model.builder import set_up_model
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Numerics

DEPTH = 2.0
"""Mean depth d_0 [m]."""
AMPLITUDE = 0.5
"""Tide amplitude A [m]."""
PERIOD = 600.0
"""Tide period T [s]."""
MANNING = 0.02
"""Bed roughness n [s m^-1/3]."""


def tide(period: float, end: float) -> LevelSeries:
    """The imposed level d_0 - A cos(2 pi t / T), sampled 100 times a period (the boundary
    interpolates linearly between samples, as it does a CSV file's rows)."""
    t = np.linspace(0.0, end, int(math.ceil(100 * end / period)) + 1)
    return LevelSeries(t, DEPTH - AMPLITUDE * np.cos(2.0 * math.pi * t / period))


def standing_wave(t, length: float, period: float):
    """The forced standing wave's level at the closed end [m] (module docstring)."""
    omega = 2.0 * math.pi / period
    k = omega / math.sqrt(GRAVITY * DEPTH)
    return DEPTH - AMPLITUDE * np.cos(omega * np.asarray(t)) / math.cos(k * length)


def far_level(model, spacing: float) -> float:
    """The mean level [m] (the depth, on the flat bed at 0) within two spacings of the west
    end."""
    p = model.particles
    band = p.x < 2.0 * spacing
    return float(model.depth()[band].mean())


def run_case(length: float, width: float, spacing: float, periods: float,
             period: float = PERIOD, sample_s: float = 5.0) -> dict:
    """Run the basin for ``periods`` tide periods; the far-end level every ``sample_s``."""
    started = time.perf_counter()
    end = periods * period
    terrain = Terrain.from_function(lambda x, y: 0.0 * x, (0.0, length), (0.0, width),
                                    spacing, manning=MANNING)
    x, y = np.meshgrid(np.arange(0.5 * spacing, length, spacing),
                       np.arange(0.5 * spacing, width, spacing))
    start = DEPTH - AMPLITUDE
    particles = particles_at(x.ravel(), y.ravel(), np.full(x.size, start), spacing,
                             Numerics.kappa)
    boundary = LevelBoundary(side_line("east", length, width), SIDE_NORMALS["east"],
                             tide(period, end), spacing, Numerics.kappa, terrain, name="sea")
    model = set_up_model(terrain, particles, Numerics(particle_spacing_m=spacing),
                         closed_sides=("west", "south", "north"), level_sides=("east",),
                         boundaries=[boundary])
    v0 = model.volume()
    times, levels, imbalance = [], [], 0.0
    for t in np.arange(sample_s, end + 0.5 * sample_s, sample_s):
        while model.t < t - 1e-9:
            model.step(t - model.t)
        times.append(model.t)
        levels.append(far_level(model, spacing))
        balance = v0 + model.state.volume_in - model.state.volume_out - model.volume()
        imbalance = max(imbalance, abs(balance))
    times_a, levels_a = np.array(times), np.array(levels)
    after = times_a >= period
    wave = standing_wave(times_a, length, period)
    imposed = np.array([boundary.series.at(t) for t in times_a])
    omega = 2.0 * math.pi / period
    return {
        "length": length, "width": width, "spacing": spacing, "periods": periods,
        "kL": omega / math.sqrt(GRAVITY * DEPTH) * length,
        "error_wave": float(np.abs(levels_a - wave)[after].max()),
        "error_imposed": float(np.abs(levels_a - imposed)[after].max()),
        "amplification": 1.0 / math.cos(omega / math.sqrt(GRAVITY * DEPTH) * length),
        "volume_initial": v0, "volume_in": model.state.volume_in,
        "volume_out": model.state.volume_out,
        "volume_final": model.volume(), "imbalance": imbalance,
        "particles": model.particles.n, "steps": model.steps,
        "wall_s": time.perf_counter() - started,
    }


def table(rows: list[dict], command: str) -> str:
    row = rows[0]
    lines = [
        "# Level boundary benchmark: a tide in a closed basin",
        "",
        f"Written by `{command}` (see its docstring for the set-up): a flat basin "
        f"{row['length']:g} m x {row['width']:g} m (Manning n = {MANNING:g}), mean depth "
        f"{DEPTH:g} m, closed but for its east side, where the level follows "
        f"{DEPTH:g} - {AMPLITUDE:g} cos(2 pi t / {PERIOD:g} s) m from low water at rest; "
        f"{row['periods']:g} periods simulated on one thread (NUMBA_NUM_THREADS=1). The "
        "far-end level is the mean depth within two spacings of the closed west wall, sampled "
        "every 5 s; the errors are the largest over the periods after the first (spin-up). "
        f"The basin is short against the tide (k L = {row['kL']:.3f}), so its level is almost "
        "flat: the frictionless standing wave raises the far-end amplitude by the factor "
        f"1 / cos(k L) = {row['amplification']:.4f} "
        f"({100 * (row['amplification'] - 1) * AMPLITUDE:.1f} cm) over the imposed tide. "
        "Balance: the largest |V_0 + V_in - V_out - V| over the samples.",
        "",
        "| spacing [m] | far-end error vs standing wave | vs imposed level | V_0 [m3] | "
        "V_in [m3] | V_out [m3] | V [m3] | balance [m3] | particles | steps | wall [s] |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        lines.append(
            f"| {r['spacing']:g} | {100 * r['error_wave']:.2f} cm | "
            f"{100 * r['error_imposed']:.2f} cm | {r['volume_initial']:.3f} | "
            f"{r['volume_in']:.3f} | {r['volume_out']:.3f} | {r['volume_final']:.3f} | "
            f"{r['imbalance']:.2e} | {r['particles']} | {r['steps']} | {r['wall_s']:.0f} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=float, default=100.0)
    parser.add_argument("--width", type=float, default=10.0)
    parser.add_argument("--spacing", type=float, nargs="+", default=[2.0])
    parser.add_argument("--periods", type=float, default=2.0)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args(argv)
    rows = []
    for spacing in args.spacing:
        row = run_case(args.length, args.width, spacing, args.periods)
        print(f"spacing {spacing:g} m: far-end level max |error| {100 * row['error_wave']:.2f} "
              f"cm against the standing wave, {100 * row['error_imposed']:.2f} cm against the "
              f"imposed level; volume imbalance {row['imbalance']:.2e} m3; "
              f"{row['wall_s']:.0f} s", flush=True)
        rows.append(row)
    if args.out is not None:
        spacings = " ".join(f"{s:g}" for s in args.spacing)
        command = (f"python benchmarks/tide_basin.py --spacing {spacings} --out "
                   f"{args.out.as_posix()}")
        args.out.write_text(table(rows, command), encoding="utf-8")
        print(f"wrote {args.out}")
    return rows


if __name__ == "__main__":
    main()
