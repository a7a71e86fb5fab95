"""``floodsph.scenario.numerics.Numerics``: one set of solver settings from the scenario's
[numerics]
to the model, with the scenario keys (docs/scenario-reference.md) as its field names."""

from __future__ import annotations

import pytest
from conftest import BASE_SCENARIO

from floodsph.errors import InputError
from floodsph.scenario.numerics import SCENARIO_KEYS, Numerics, NumericsError, Stabilisation
from floodsph.scenario.reader import load_scenario

CONTRACT_KEYS = {"particle_spacing_m", "cfl", "refinement", "threads"}
"""The [numerics] keys of a scenario's example (docs/scenario-reference.md)."""


def test_the_scenario_keys_are_the_contracts_and_the_inner_tunables_are_none_of_them():
    assert CONTRACT_KEYS <= set(SCENARIO_KEYS)
    assert not {"h_ratio", "density_max_iter", "neighbour_skin", "reorder_interval",
                "refine_smoothing_excess"} & set(SCENARIO_KEYS)


def test_an_inner_tunable_in_a_scenario_is_an_unknown_key(write_scenario):
    text = BASE_SCENARIO.replace("cfl = 0.3", "cfl = 0.3\nh_ratio = 4.0")
    with pytest.raises(InputError, match=r"scenario.toml: numerics.h_ratio: unknown key; "
                                         r"allowed keys: cfl, density_tol, "):
        load_scenario(write_scenario(text))


def test_the_resolved_scenario_writes_every_numerics_key_given_or_defaulted_and_no_other(
        write_scenario):
    numerics = load_scenario(write_scenario()).to_dict()["numerics"]
    assert set(numerics) == set(SCENARIO_KEYS)
    assert numerics["refinement"] == "none" and numerics["time_stepping"] == "global"
    assert numerics["friction_depth_floor_m"] == 0.01 and numerics["step_levels"] == 3


def test_the_scenarios_values_reach_the_model_under_their_own_names(write_scenario):
    """What the user writes is what the solver uses: no second set of defaults on the way."""
    from floodsph.inputs.prepare import prepare_inputs
    from floodsph.model.from_scenario import build_model
    from floodsph.sph import forces

    text = BASE_SCENARIO.replace(
        "cfl = 0.3", 'cfl = 0.25\nfriction_depth_floor_m = 0.05\nstabilisation = "riemann"\n'
                     'momentum = "variational"\n'
                     "kappa = 1.3\nmax_slope = 0.5\ndensity_tol = 1e-4")
    scenario = load_scenario(write_scenario(text))
    model = build_model(scenario, prepare_inputs(scenario))
    num = model.numerics
    assert (num.cfl, num.friction_depth_floor_m, num.kappa, num.max_slope,
            num.density_tol) == (0.25, 0.05, 1.3, 0.5, 1e-4)
    assert num.stabilisation is Stabilisation.RIEMANN and model.domain.scheme == forces.RIEMANN
    assert num.particle_spacing_m == 10.0


def test_the_dem_cell_size_fills_in_a_missing_particle_spacing(write_scenario):
    from floodsph.inputs.prepare import prepare_inputs
    from floodsph.model.from_scenario import build_model

    scenario = load_scenario(write_scenario(BASE_SCENARIO.replace(
        "particle_spacing_m = 10.0\n", "")))
    inputs = prepare_inputs(scenario)
    assert scenario.numerics.particle_spacing_m is None
    model = build_model(scenario, inputs)
    assert model.numerics.particle_spacing_m == min(inputs.terrain.dx, inputs.terrain.dy)


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"cfl": 1.5}, "numerics.cfl: must be <= 1, got 1.5"),
        ({"step_levels": 7}, "numerics.step_levels: must be <= 6, got 7"),
        ({"threads": 2.0}, "numerics.threads: expected an integer, got 2.0"),
        ({"h_ratio": 0.5}, "numerics.h_ratio: must be >= 1, got 0.5"),
        ({"particle_spacing_m": 0.0}, "numerics.particle_spacing_m: must be > 0, got 0"),
        ({"stabilisation": "riemann"}, "numerics.stabilisation: expected a "
                                       "floodsph.scenario.numerics.Stabilisation "
                                       "('lax-friedrichs', 'riemann', 'muscl'), got 'riemann'"),
    ],
)
def test_numerics_built_in_code_are_checked_as_a_scenario_is(settings, message):
    with pytest.raises(NumericsError) as err:
        Numerics(**settings)
    assert str(err.value) == message
