"""``benchmarks/profile_stages.py``: exclusive stage times that add up to the wall time."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import load_script
from sph_cases import model_on

from floodsph.model.refinement import Refiner
from floodsph.scenario.numerics import Numerics

pytestmark = pytest.mark.benchmark

REPO = Path(__file__).resolve().parents[2]
prof = load_script("profile_stages", REPO / "benchmarks" / "profile_stages.py")


def test_stage_times_are_exclusive_and_add_up_to_the_wall_time():
    """A dam break on a flat bed that splits at once: the stages of the model's timer do not
    overlap, so none is negative and the rows sum to the wall time; the timer is removed
    afterwards, and the model counted its list builds."""
    model = model_on(lambda x, y: 0 * x, (0, 40), (0, 24), 1.0,
                     lambda x, y: np.where(x < 12.0, 1.0, 0.0), 1.0)
    model.refiner = Refiner(Numerics(particle_spacing_m=1.0, refine_area_max=2.0,
                                     refine_area_min=0.9))
    rows, totals = prof.profile(model, steps=40, warmup=1)
    assert model.stage_timer is None
    seconds = {r["stage"]: r["seconds"] for r in rows}
    assert {"neighbours", "density", "forces", "refinement", "other"} <= set(seconds)
    assert totals["list_builds_per_step"] > 0.5
    assert min(seconds.values()) >= 0.0
    assert sum(seconds.values()) == pytest.approx(totals["wall_s"], rel=1e-9)
    assert sum(r["percent"] for r in rows) == pytest.approx(100.0, rel=1e-9)
    assert totals["steps"] == 40
    assert model.state.counters["splits"] > 0


def test_the_function_profile_counts_each_kernel_call_of_the_steps():
    """Profiled by function, 25 global steps call the drift's kernel (``walls.sight.drift``)
    once each, and the rows' own times stay within the profiled wall time."""
    model = model_on(lambda x, y: 0 * x, (0, 40), (0, 24), 1.0,
                     lambda x, y: np.where(x < 12.0, 1.0, 0.0), 1.0)
    model.step()
    rows = prof.function_profile(model, steps=25, top=400)
    calls = {r["function"]: r["calls"] for r in rows}
    assert calls["walls.sight.drift"] == 25
    assert 0.0 < sum(r["percent"] for r in rows) <= 100.0


def test_map_update_timing_compares_the_band_and_point_gathers_on_the_same_cells():
    """After a dam break has spread (h from 1.3 to several times that), the two ways of
    interpolating onto the map grid map the same cells with the same depths."""
    from floodsph.output.grid import OutputGrid

    model = model_on(lambda x, y: 0 * x, (0, 60), (0, 30), 0.5,
                     lambda x, y: np.where(x < 15.0, 1.0, 0.0), 1.0)
    prof.profile(model, steps=30, warmup=0)
    grid = OutputGrid.from_terrain(model.terrain)
    out = prof.map_update_times(model, grid, repeats=1)
    assert out["cells"] == grid.nx * grid.ny and out["particles"] == model.particles.n
    assert out["wet_mask_equal"] and out["max_depth_diff_m"] < 1e-12


def test_a_bad_scenario_path_is_one_clear_error(tmp_path, capsys):
    missing = tmp_path / "nope.toml"
    assert prof.main([str(missing), "--steps", "1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("Error:") and "nope.toml" in err and "Traceback" not in err
