"""Run a scenario file with other numerics, and compare the max-depth maps of two runs.

Shared by ``refinement_benchmark.py`` and ``speed_vs_error.py``: a scenario is loaded, its
refinement mode, particle spacing, end time or refinement thresholds replaced, and run through
the real chain (``floodsph.run.pipeline.run_scenario``: run folder, maps, ``run.json``, whose
``particle_updates`` is the particle-steps, the solver's work measure).
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

WET_M = 0.1
"""Wet threshold [m] of the map comparisons (CSI)."""
REFINE_KEYS = ("refine_area_max", "refine_area_min", "refine_d_min_m", "refine_max_level")


def variant(path: Path, out: Path, mode: str | None = None, spacing: float | None = None,
            end_time: float | None = None, settings: dict | None = None,
            time_stepping: str | None = None):
    """The scenario at ``path`` with ``out`` as its run folder and the given replacements.

    ``mode``: ``numerics.refinement``; ``spacing`` [m]: ``particle_spacing_m``; ``end_time``
    [s]; ``settings``: ``[numerics]`` refinement keys (:data:`REFINE_KEYS`);
    ``time_stepping``: ``numerics.time_stepping`` (``"global"`` or ``"local"``).
    """
    from floodsph.scenario.numerics import Refinement, TimeStepping
    from floodsph.scenario.reader import load_scenario

    scenario = load_scenario(path)
    numerics = dict(settings or {})
    if mode is not None:
        numerics["refinement"] = Refinement(mode)
    if spacing is not None:
        numerics["particle_spacing_m"] = spacing
    if time_stepping is not None:
        numerics["time_stepping"] = TimeStepping(time_stepping)
    info = scenario.scenario
    if end_time is not None:
        info = dataclasses.replace(info, end_time_s=end_time)
    return dataclasses.replace(
        scenario, scenario=info,
        numerics=dataclasses.replace(scenario.numerics, **numerics),
        output=dataclasses.replace(scenario.output, directory=out))


def run(scenario, out: Path, max_steps: int | None = None, **labels) -> dict:
    """Run ``scenario`` into ``out``; return its row: ``labels``, then cost and counters."""
    import floodsph.run.pipeline as runner

    t0 = time.perf_counter()
    manifest = runner.run_scenario(scenario, out, max_steps=max_steps, progress=False,
                                   overwrite=True)
    wall = time.perf_counter() - t0
    row = {**labels, "mode": scenario.numerics.refinement.value,
           "time_stepping": scenario.numerics.time_stepping.value,
           "spacing_m": manifest["particle_spacing_m"], "wall_s": round(wall, 1),
           "sim_time_s": manifest["sim_time_s"], "steps": manifest["steps"],
           "particles_initial": manifest["particles_initial"],
           "particles_max": manifest["particles_max"],
           "particles_final": manifest["particles_final"],
           "particle_steps": manifest["particle_updates"],
           "splits": manifest["splits"], "merges": manifest["merges"],
           "mass_error_rel": manifest.get("mass_error_rel")}
    print(row, flush=True)
    return row


def agreement(run_a: Path, run_b: Path, threshold: float = WET_M) -> dict:
    """CSI (wet = depth > ``threshold``), hit rate, false-alarm ratio, and RMSE and bias of
    depth over cells wet in both, of run a's ``max_depth.tif`` against run b's."""
    from floodsph.output.compare import compare

    s = compare(run_a / "max_depth.tif", run_b / "max_depth.tif", threshold=threshold).summary
    return {"csi": round(s["csi"], 4), "hit_rate": round(s["hit_rate"], 4),
            "false_alarm_ratio": round(s["false_alarm_ratio"], 4),
            "rmse_m": round(s["depth"]["rmse"], 4), "bias_m": round(s["depth"]["bias"], 4),
            "cells_wet_both": s["depth"]["n"]}
