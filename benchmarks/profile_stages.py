"""Where a run's time goes: wall time per stage of the time step, and list builds per step.

Runs a scenario (the model of ``floodsph run``, without its outputs) for ``--steps`` steps or
up to ``--end-time`` and times the stages of ``floodsph.model.flood_model.FloodModel.step`` with the
model's stage timer (``floodsph.model.stage_timer``: kick and drift, boundaries, refinement,
neighbour lists, density, forces, closing kick). Times are exclusive; the time outside the
steps is ``other``. Prints a markdown
table and the neighbour-list builds per step. The first steps compile the numba kernels when
they are not cached yet: ``--warmup`` steps (default 3) run before the clock starts.

``--functions N`` profiles the same steps again by function instead (``cProfile``, which adds
its own cost to every Python call): the N functions of most own time, numba kernels each as
one call, so that a stage's time can be traced to its kernels and to the array work around
them.

The stages leave out the run's recorders. ``--maps N`` then also times one update of the map
envelopes' interpolation at the final state on the scenario's map grid, best of N: the band
gather the run uses (``floodsph.output.rasterise.rasterise``) and the point gather of
``interpolate`` at every cell centre, with the largest depth difference between the two.

    python benchmarks/profile_stages.py SCENARIO.toml [--steps 500 | --end-time 600]
        [--threads 2] [--warmup 3] [--maps 5] [--functions 25]
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from pathlib import Path

from floodsph.output.tables import markdown


def profile(model, steps: int | None = None, end_time: float | None = None,
            warmup: int = 3) -> tuple[list[dict], dict]:
    """Step ``model`` and time its stages; returns (rows, totals).

    ``rows`` has one dict per stage of ``floodsph.model.stage_timer`` (``stage``, ``seconds``,
    ``percent``), most costly first, and ``other`` for the time outside the steps; ``totals``
    the wall time, steps, particle-steps (the particles at each ``step()``, a big step under
    local time stepping), particle updates (the ``particle_updates`` counter: each particle's
    own steps) and neighbour-list builds per step (the ``neighbour_builds`` counter) of the
    timed steps. The timer is the model's public hook
    (``FloodModel.stage_timer``), removed again afterwards.
    """
    from floodsph.model.stage_timer import StageTimer

    for _ in range(warmup):
        model.step()
    timer = StageTimer()
    model.stage_timer = timer
    step0, builds0, particle_steps = model.steps, model.state.counters["neighbour_builds"], 0
    updates0 = model.state.counters["particle_updates"]
    t0 = time.perf_counter()
    try:
        while (steps is None or model.steps - step0 < steps) and (
                end_time is None or model.t < end_time):
            model.step()
            particle_steps += model.particles.n
    finally:
        model.stage_timer = None
    wall = time.perf_counter() - t0
    nsteps = model.steps - step0
    times = Counter(timer.seconds)
    times["other"] = wall - sum(timer.seconds.values())
    rows = [{"stage": k, "seconds": v, "percent": 100.0 * v / wall}
            for k, v in times.most_common()]
    totals = {"wall_s": wall, "steps": nsteps, "sim_time_s": model.t,
              "particle_steps": particle_steps,
              "particle_updates": model.state.counters["particle_updates"] - updates0,
              "list_builds_per_step": (model.state.counters["neighbour_builds"] - builds0)
              / max(nsteps, 1)}
    return rows, totals


def function_profile(model, steps: int | None = None, end_time: float | None = None,
                     top: int = 25) -> list[dict]:
    """Step ``model`` as :func:`profile` does (no warm-up) under ``cProfile``; the ``top``
    functions by own time: ``function`` (module path and name), ``calls``, ``seconds`` and
    ``percent`` of the profiled wall time."""
    import cProfile
    import pstats

    step0 = model.steps
    profiler = cProfile.Profile()
    t0 = time.perf_counter()
    profiler.enable()
    while (steps is None or model.steps - step0 < steps) and (
            end_time is None or model.t < end_time):
        model.step()
    profiler.disable()
    wall = time.perf_counter() - t0
    stats = pstats.Stats(profiler).stats  # type: ignore[attr-defined]  # its table
    rows = []
    for (path, _, name), (_, calls, own, _, _) in stats.items():
        where = Path(path)
        module = ".".join(where.with_suffix("").parts[-2:]) if path.endswith(".py") else path
        rows.append({"function": f"{module}.{name}" if path.endswith(".py") else name,
                     "calls": calls, "seconds": own, "percent": 100.0 * own / wall})
    rows.sort(key=lambda row: -row["seconds"])
    return rows[:top]


def map_update_times(model, grid, repeats: int = 3) -> dict:
    """Best-of-``repeats`` wall time [ms] of one interpolation of the model's particles onto
    ``grid`` (an ``OutputGrid``): by row bands (``band_ms``, what the envelopes use) and by
    points at the cell centres (``points_ms``); ``max_depth_diff_m`` is the largest depth
    difference between the two, and ``wet_mask_equal`` whether the same cells are mapped."""
    import numpy as np

    from floodsph.output.rasterise import interpolate, rasterise

    p = model.particles
    fields = (p.x, p.y, p.u, p.v, p.m, p.rho, p.h)
    xc, yc = grid.cell_centres()
    px, py = np.meshgrid(xc, yc)
    best = {"band_ms": np.inf, "points_ms": np.inf}
    for _ in range(repeats):
        t0 = time.perf_counter()
        band = rasterise(grid, *fields)[0]
        t1 = time.perf_counter()
        points = interpolate(px, py, *fields)[0]
        t2 = time.perf_counter()
        best["band_ms"] = min(best["band_ms"], 1e3 * (t1 - t0))
        best["points_ms"] = min(best["points_ms"], 1e3 * (t2 - t1))
    mapped = ~np.isnan(band)
    diff = np.abs(band[mapped] - points[mapped])
    return best | {"cells": band.size, "particles": p.n,
                   "max_depth_diff_m": float(diff.max()) if diff.size else 0.0,
                   "wet_mask_equal": bool(np.array_equal(mapped, ~np.isnan(points)))}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario", type=Path)
    ap.add_argument("--steps", type=int, default=None, help="timed steps (default 500)")
    ap.add_argument("--end-time", type=float, default=None, help="or run up to this time [s]")
    ap.add_argument("--threads", type=int, default=0, help="numba threads (0 = all cores)")
    ap.add_argument("--warmup", type=int, default=3, help="untimed steps first")
    ap.add_argument("--functions", type=int, default=0, metavar="N",
                    help="then profile the same steps by function, the N of most own time")
    ap.add_argument("--maps", type=int, default=0, metavar="N",
                    help="also time a map update at the end, best of N")
    args = ap.parse_args(argv)
    from floodsph.errors import InputError
    from floodsph.inputs.prepare import prepare_inputs
    from floodsph.model.from_scenario import build_model
    from floodsph.run.pipeline import set_threads
    from floodsph.scenario.reader import load_scenario

    set_threads(args.threads)
    try:
        scenario = load_scenario(args.scenario)
        inputs = prepare_inputs(scenario)
        model = build_model(scenario, inputs)
    except InputError as exc:
        print(f"Error: {exc}", file=sys.stderr)
        return 2
    steps = args.steps if args.steps is not None or args.end_time is not None else 500
    rows, totals = profile(model, steps=steps, end_time=args.end_time, warmup=args.warmup)
    print(markdown(rows, spec=".3g"))
    print()
    print(markdown([totals], spec=".4g"))
    if args.functions > 0:
        again = build_model(scenario, inputs)
        for _ in range(args.warmup):
            again.step()
        print()
        print(markdown(function_profile(again, steps=steps, end_time=args.end_time,
                                        top=args.functions), spec=".3g"))
    if args.maps > 0:
        from floodsph.output.grid import OutputGrid

        grid = OutputGrid.from_terrain(inputs.terrain, scenario.output.resolution_m)
        print()
        print(markdown([map_update_times(model, grid, args.maps)], spec=".4g"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
