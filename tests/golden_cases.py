"""The golden regression cases: small runs whose numbers are stored in ``tests/golden/``.

The cases run with the default numerics (the balanced momentum), and the three analytic ones
also with the variational momentum. Each case returns plain data (lists of floats, ints):
depth profiles, step and refinement counters, mass, gauge values.
``python tests/golden_cases.py`` regenerates the stored files; do that only for a change that
is meant to move the numbers, and say why in its commit.
Cases run with 2 numba threads, the CI machine's count.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from floodsph.scenario.numerics import Momentum, Refinement, TimeStepping

GOLDEN = Path(__file__).resolve().parent / "golden"
THREADS = 2


def _analytic(name: str, dx: float, **options) -> dict:
    """One ``floodsph.verification.cases`` case, with its depth profile along the channel."""
    from floodsph.verification import cases as verification

    result = verification.CASES[name](dx, **options)
    return {"particles": result.particles, "steps": result.steps,
            "particles_max": result.particles_max, "splits": result.splits,
            "merges": result.merges, "l1": result.l1, "front_error_m": result.front_error_m,
            "mass_error_rel": result.mass_error_rel}


def _scenario_run(tmp: Path) -> dict:
    """The dam break with an inflow, open edges, refinement and local steps of
    ``tests/run/test_checkpoint_resume.py``, through ``run_scenario``."""
    import csv

    import rasterio
    from conftest import valley_elevation, write_geotiff
    from run_cases import write_dam_break

    from floodsph.run.pipeline import run_scenario
    from floodsph.scenario.reader import load_scenario

    write_geotiff(tmp / "dem.tif", valley_elevation())
    m = run_scenario(load_scenario(write_dam_break(tmp, "local")), tmp / "run", progress=False)
    with rasterio.open(tmp / "run" / "max_depth.tif") as src:
        max_depth = src.read(1)
    with open(tmp / "run" / "gauges.csv", newline="") as f:
        gauges = [float(r["depth_m"]) for r in csv.DictReader(f)]
    return {key: m[key] for key in ("steps", "particles_max", "particles_final", "splits",
                                    "merges", "volume_domain_m3", "volume_in_m3",
                                    "volume_out_m3", "particle_updates")} | {
        "max_depth_sum": float(np.nansum(max_depth)),
        "max_depth_max": float(np.nanmax(max_depth)),
        "gauge_depths": gauges}


CASES = {
    "ritter_20m": lambda tmp: _analytic("ritter", 20.0),
    "stoker_20m": lambda tmp: _analytic("stoker", 20.0),
    "thacker_250m": lambda tmp: _analytic("thacker", 250.0),
    "ritter_20m_split_coalesce": lambda tmp: _analytic("ritter", 20.0,
                                                       refinement=Refinement.SPLIT_COALESCE),
    "ritter_20m_local_steps": lambda tmp: _analytic("ritter", 20.0,
                                                    time_stepping=TimeStepping.LOCAL),
    "inflow_open_edges_refined_local": _scenario_run,
    "ritter_20m_variational": lambda tmp: _analytic("ritter", 20.0,
                                                    momentum=Momentum.VARIATIONAL),
    "stoker_20m_variational": lambda tmp: _analytic("stoker", 20.0,
                                                    momentum=Momentum.VARIATIONAL),
    "thacker_250m_variational": lambda tmp: _analytic("thacker", 250.0,
                                                      momentum=Momentum.VARIATIONAL),
}


def compute(name: str, tmp: Path) -> dict:
    import numba

    numba.set_num_threads(THREADS)
    return CASES[name](tmp)


def main() -> int:
    import tempfile

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    for name in CASES:
        with tempfile.TemporaryDirectory() as tmp:
            values = compute(name, Path(tmp))
        (GOLDEN / f"{name}.json").write_text(json.dumps(values, indent=1) + "\n")
        print(name, {k: v for k, v in values.items() if not isinstance(v, list)})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
