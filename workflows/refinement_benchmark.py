"""Cost and agreement of the refinement modes on the sample valley and on Malpasset.

Runs each scenario with ``numerics.refinement`` = "none", "split" and "split+coalesce"
through the real run chain (``floodsph.run.run_scenario``: run folder, maps, run.json) and
reports, per run: wall time, steps, peak and final particle counts, particle-steps (the sum
over steps of the particle count, the solver's work measure), splits, merges and the mass
error; and, for each pair of modes, the agreement of their ``max_depth.tif`` maps
(``floodsph.compare``: CSI with wet = depth > 0.1 m, and RMSE / bias over cells wet in both).

Scenarios: ``data_samples/valley/scenario.toml`` (its own end time, 600 s) and
``workflows/malpasset/scenario.toml`` cut to 1000 s. Malpasset's DEM is third-party data read
from ``$FLOODSPH_BENCHMARKS/malpasset`` or ``<repo>/../shared/benchmarks/malpasset``; the case
is skipped with a message when it is absent.

Writes ``refinement_benchmark.csv`` and ``agreement.csv`` into ``--out`` and prints both as
markdown tables. Wall times depend on the machine's load: compare the ratios within one run.

    python workflows/refinement_benchmark.py [--out results/refinement_benchmark]
        [--cases valley malpasset] [--modes none split split+coalesce] [--max-steps N]
        [--malpasset-spacing 40] [--malpasset-end-time 1000] [--set refine_area_min=0.5 ...]
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import os
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
MODES = ("none", "split", "split+coalesce")
CASES = {
    "valley": (REPO / "data_samples" / "valley" / "scenario.toml", None),
    "malpasset": (REPO / "workflows" / "malpasset" / "scenario.toml", 1000.0),
}
WET_M = 0.1
REFINE_KEYS = ("refine_area_max", "refine_area_min", "refine_d_min_m", "refine_max_level")


class StepCounter:
    """Simulation callback adding up the particle count of every step (particle-steps)."""

    def __init__(self):
        self.particle_steps = 0
        self.last_step = 0

    def __call__(self, sim) -> None:
        steps = sim.model.steps
        if steps > self.last_step:
            self.particle_steps += (steps - self.last_step) * sim.n
            self.last_step = steps


def scenario_for(case: str, mode: str, out: Path, spacing: float | None = None,
                 end_time: float | None = None, settings: dict | None = None):
    """The case's scenario with ``mode``, its end time and ``out`` as the run folder.

    ``spacing`` [m] and ``end_time`` [s] override the scenario's particle spacing and the
    case's end time. Returns None (after printing why) when the case's data is missing.
    """
    from floodsph.scenario import Refinement, load_scenario

    path, case_end = CASES[case]
    end_time = end_time or case_end
    scenario = load_scenario(path)
    dem = scenario.terrain.dem
    if case == "malpasset" and os.environ.get("FLOODSPH_BENCHMARKS"):
        dem = Path(os.environ["FLOODSPH_BENCHMARKS"]) / "malpasset" / dem.name
    if not dem.is_file():
        print(f"{case}: skipped, {dem} not found (set FLOODSPH_BENCHMARKS)")
        return None
    info = scenario.scenario
    if end_time is not None:
        info = dataclasses.replace(info, end_time_s=end_time)
    return dataclasses.replace(
        scenario,
        scenario=info,
        terrain=dataclasses.replace(scenario.terrain, dem=dem),
        numerics=dataclasses.replace(
            scenario.numerics, refinement=Refinement(mode),
            particle_spacing_m=spacing or scenario.numerics.particle_spacing_m,
            **(settings or {})),
        output=dataclasses.replace(scenario.output, directory=out),
    )


def run(case: str, mode: str, out: Path, max_steps: int | None,
        spacing: float | None = None, end_time: float | None = None,
        settings: dict | None = None) -> dict | None:
    """Run one case in one mode; return its row of the results table.

    ``settings`` are ``[numerics]`` refinement keys (``refine_area_max``, ...) to override.
    """
    import floodsph.run as runner
    from floodsph.schedules import IterationInterval

    scenario = scenario_for(case, mode, out, spacing, end_time, settings)
    if scenario is None:
        return None
    counter = StepCounter()
    t0 = time.perf_counter()
    manifest = runner.run_scenario(scenario, out, max_steps=max_steps, progress=False,
                                   overwrite=True, callbacks=[(counter, IterationInterval(1))])
    wall = time.perf_counter() - t0
    row = {"case": case, "mode": mode, "spacing_m": manifest["particle_spacing_m"],
           "wall_s": round(wall, 1),
           "sim_time_s": manifest["sim_time_s"], "steps": manifest["steps"],
           "particles_initial": manifest["particles_initial"],
           "particles_max": manifest["particles_max"],
           "particles_final": manifest["particles_final"],
           "particle_steps": counter.particle_steps,
           "splits": manifest["splits"], "merges": manifest["merges"],
           "mass_error_rel": manifest.get("mass_error_rel")}
    print(row, flush=True)
    return row


def agreement(case: str, a: str, b: str, out: Path) -> dict:
    """CSI (wet = depth > 0.1 m) and depth errors of mode a's max depth map against b's."""
    from floodsph.compare import compare

    s = compare(out / case / a / "max_depth.tif", out / case / b / "max_depth.tif",
                threshold=WET_M).summary
    return {"case": case, "mode": a, "against": b, "csi": round(s["csi"], 4),
            "hit_rate": round(s["hit_rate"], 4),
            "false_alarm_ratio": round(s["false_alarm_ratio"], 4),
            "rmse_m": round(s["depth"]["rmse"], 4), "bias_m": round(s["depth"]["bias"], 4),
            "cells_wet_both": s["depth"]["n"]}


def markdown(rows: list[dict]) -> str:
    keys = list(rows[0])
    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    lines += ["| " + " | ".join(str(r[k]) for k in keys) + " |" for r in rows]
    return "\n".join(lines)


def write_csv(path: Path, rows: list[dict]) -> None:
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("results/refinement_benchmark"))
    ap.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES))
    ap.add_argument("--modes", nargs="+", choices=MODES, default=list(MODES))
    ap.add_argument("--max-steps", type=int, default=None, help="trial runs: stop early")
    ap.add_argument("--malpasset-spacing", type=float, default=None,
                    help="particle spacing [m] for Malpasset (default: the scenario's 20 m)")
    ap.add_argument("--malpasset-end-time", type=float, default=None,
                    help="simulated time [s] for Malpasset (default 1000 s)")
    ap.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE",
                    help="[numerics] refinement keys, e.g. refine_area_min=0.5")
    args = ap.parse_args()
    out = args.out.resolve()
    settings = {}
    for item in args.set:
        key, _, value = item.partition("=")
        if key not in REFINE_KEYS:
            ap.error(f"--set {item}: key must be one of {REFINE_KEYS}")
        settings[key] = int(value) if key == "refine_max_level" else float(value)
    rows, pairs = [], []
    for case in args.cases:
        done = []
        for mode in args.modes:
            mp = case == "malpasset"
            row = run(case, mode, out / case / mode, args.max_steps,
                      args.malpasset_spacing if mp else None,
                      args.malpasset_end_time if mp else None, settings)
            if row is not None:
                rows.append(row)
                done.append(mode)
        for i, a in enumerate(done):
            for b in done[i + 1:]:
                pairs.append(agreement(case, b, a, out))
    if not rows:
        return
    out.mkdir(parents=True, exist_ok=True)
    write_csv(out / "refinement_benchmark.csv", rows)
    print("\n" + markdown(rows))
    if pairs:
        write_csv(out / "agreement.csv", pairs)
        print("\n" + markdown(pairs))


if __name__ == "__main__":
    main()
