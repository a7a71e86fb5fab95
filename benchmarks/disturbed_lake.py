"""A lake at rest, disturbed: does it come back to rest? The Malpasset reservoir of
``benchmarks/still_water.py`` (20 m DEM, 100 m level, a wall along the dam line, closed edges),
its particles given random velocities, N(0, amplitude) in each direction, then stepped.

Prints, every ``--every`` seconds of simulated time, the largest and the 95th-percentile
particle speed [m/s] and the number of particles still held by their banks (the balanced
momentum's still water, ``floodsph.sph.level_offsets``); one line per disturbance.

    python benchmarks/disturbed_lake.py [--momentum balanced] [--amplitudes 1e-6 1e-4 1e-3]
        [--end 600] [--every 120] [--out results/disturbed_lake]

The Malpasset data is read from ``$FLOODSPH_BENCHMARKS/malpasset`` or
``<repo>/../shared/benchmarks/malpasset``; without it the script says so and stops.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import still_water_cases as cases  # noqa: E402

from floodsph.inputs.prepare import prepare_inputs  # noqa: E402
from floodsph.model.from_scenario import build_model  # noqa: E402
from floodsph.scenario.numerics import Momentum  # noqa: E402
from floodsph.scenario.reader import load_scenario  # noqa: E402
from floodsph.sph.level_offsets import HELD  # noqa: E402


def disturbed_run(scenario, amplitude: float, end: float, every: float, seed: int = 1):
    """(t, max speed, p95 speed, held particles) every ``every`` s of a run of the scenario's
    model whose particles were given random velocities of ``amplitude`` [m/s]."""
    model = build_model(scenario, prepare_inputs(scenario))
    p = model.particles
    rng = np.random.default_rng(seed)
    p.u += amplitude * rng.standard_normal(p.n)
    p.v += amplitude * rng.standard_normal(p.n)
    rows = []
    next_report = every
    while model.t < end - 1e-9:
        model.step(end - model.t)
        if model.t >= next_report - 1e-9:
            speed = np.hypot(p.u, p.v)
            rows.append((model.t, float(speed.max()), float(np.percentile(speed, 95)),
                         int(np.count_nonzero(p.bank_held == HELD))))
            next_report += every
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--momentum", choices=[m.value for m in Momentum], default="balanced")
    parser.add_argument("--amplitudes", type=float, nargs="+", default=[1e-6, 1e-4, 1e-3])
    parser.add_argument("--end", type=float, default=600.0)
    parser.add_argument("--every", type=float, default=120.0)
    parser.add_argument("--out", type=Path, default=Path("results/disturbed_lake"))
    args = parser.parse_args(argv)
    data = cases.mp_setup.data_folder()
    if data is None:
        print("the Malpasset data is not there ($FLOODSPH_BENCHMARKS or "
              "<repo>/../shared/benchmarks/malpasset)")
        return 1
    case = cases.malpasset(args.out / "malpasset", args.end, data)
    scenario = load_scenario(case.scenario)
    scenario = replace(scenario, numerics=replace(scenario.numerics,
                                                  momentum=Momentum(args.momentum)))
    print(f"Malpasset reservoir at rest, {args.momentum} momentum; max / p95 speed [m/s] "
          f"and held particles")
    for amplitude in args.amplitudes:
        cells = [f"{t:.0f} s: {top:.1e} / {p95:.1e}, {held} held"
                 for t, top, p95, held in disturbed_run(scenario, amplitude, args.end,
                                                        args.every)]
        print(f"{amplitude:g} m/s | " + " | ".join(cells), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
