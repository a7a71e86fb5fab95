"""``benchmarks/breach_in_wall.py``: the reservoir storage it tabulates from the DEM, and the
level-pool breach it maps the wall's breach onto (no model run).

Facts that could fail: the storage at the lake level is the volume of water the sample seeds
(within 0.1 %), and above the breach invert it is the reservoir volume the sample gives
Froehlich's formulas (within 1 %); the level-pool breach has the wall breach's bottom
elevation at every time once the notch reaches the water, and the same final bottom width;
the level pool releases the storage above the invert (to the routing's tolerance); the weir
law summed over short pieces of the wall is the exact discharge of its breach.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import load_script

from floodsph.breach import breach_hydrograph
from floodsph.breach.formulas import progression
from floodsph.breach.params import resolve
from floodsph.inputs.prepare import prepare_inputs
from floodsph.scenario.reader import load_scenario

pytestmark = pytest.mark.benchmark

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
bw = load_script("breach_in_wall", BENCHMARKS / "breach_in_wall.py")


@pytest.fixture(scope="module")
def sample(tmp_path_factory):
    scenario = load_scenario(bw.SCENARIO)
    levels, volume = bw.reservoir_storage(scenario)
    path = bw.write_storage_csv(tmp_path_factory.mktemp("storage") / "storage.csv", levels,
                                volume)
    return scenario, levels, volume, path


def test_the_storage_table_holds_the_seeded_lake_and_the_stated_volume(sample):
    scenario, levels, volume, _ = sample
    level = scenario.initial_water[0].level_m
    invert = scenario.walls[0].breach.invert_m
    at = np.interp([level, invert], levels, volume)
    seeded = prepare_inputs(scenario).volume_initial_m3
    assert at[0] == pytest.approx(seeded, rel=1e-3)
    assert at[0] - at[1] == pytest.approx(scenario.walls[0].breach.reservoir_volume_m3, rel=0.01)


def test_the_level_pool_breach_is_the_wall_breach_below_the_lake(sample):
    scenario, _, _, path = sample
    params = bw.level_pool_params(scenario, path, 7200.0)
    setup = resolve(params)
    crest, breach = bw.wall_breach(scenario)
    assert setup.bottom_width_m == pytest.approx(breach.bottom_width_m, rel=1e-12)
    for t in np.linspace(params.start_time_s, breach.start_s + breach.formation_s, 9):
        r = progression((t - params.start_time_s) / setup.formation_time_s, params.progression)
        pool_bottom = setup.top_m - r * (setup.top_m - setup.invert_m)
        assert pool_bottom == pytest.approx(float(crest.at([breach.centre_m], t)[0]), abs=1e-9)
    _, _, summary = breach_hydrograph(dataclasses.replace(params, duration_s=None))
    assert abs(summary.volume_error_rel) < 1e-5
    assert summary.released_volume_m3 == pytest.approx(summary.initial_storage_m3, rel=2e-3)


def test_the_walls_pieces_pass_what_the_trapezoid_passes_when_fine(sample):
    """The weir law on pieces 0.5 m long, each at the crest of its midpoint, adds up to the
    exact integral over the formed breach's bottom and sides within 1 %."""
    from floodsph.boundaries.weir import Weir

    scenario, _, _, path = sample
    crest, breach = bw.wall_breach(scenario)
    setup = resolve(bw.level_pool_params(scenario, path, 7200.0))
    formed = breach.start_s + breach.formation_s
    fine = Weir(crest, 0.5, scenario.numerics.kappa)
    for level in (229.0, 231.0, 233.0):
        pieces, trapezoid, pool = bw.capacities(fine, breach, setup, level, formed)
        assert pieces == pytest.approx(trapezoid, rel=0.01)
        # once formed, the level pool's breach is the same trapezoid; Fread's side
        # coefficient 2.45 / 3.1 = 0.790 is the exact 0.8 within 1.3 %
        assert pool == pytest.approx(trapezoid, rel=0.013)
