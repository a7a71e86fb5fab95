"""Crest walls that water overtops, and breaches that open in them (``floodsph.boundaries.weir``,
``floodsph.boundaries.crest``).

Physical facts asserted: water below the crest stays where it is, to the last bit; in steady
free flow the upstream level stands at the head the broad-crested weir law gives for the
discharge passing; the weir moves water without creating or losing any; a submerged weir
passes what Villemonte's reduction says; a breach passes nothing before it starts, then more
and more; its crest follows the linear and sine growth; bad crest and breach inputs are
refused with a message naming the key.
"""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from sph_cases import lattice, particles_with_depth, run_until

from floodsph.boundaries import Inflow
from floodsph.boundaries.crest import Breach, Crest
from floodsph.boundaries.weir import IDEAL_COEFFICIENT, Weir, unit_discharge
from floodsph.constants import GRAVITY
from floodsph.errors import InputError
from floodsph.io.hydrograph import Hydrograph
from floodsph.model.builder import set_up_model
from floodsph.model.from_scenario import weirs
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Momentum, Numerics, TimeStepping
from floodsph.scenario.reader import scenario_from_dict

DX = 0.25
WIDTH = 5.0
RESERVOIR = 10.0
CREST = 1.0
WALL = np.array([[RESERVOIR, 0.0], [RESERVOIR, WIDTH]])


def _channel(level: float, crest: Crest, closed=("south", "north"), inflow_q: float = 0.0,
             **numerics):
    """A flat 5 m wide channel, 20 m long, with the crest wall across it at x = 10 m and still
    water at ``level`` upstream of it; the east end open (unless closed), an inflow of
    ``inflow_q`` [m3/s] at the west end (closed when zero)."""
    terrain = Terrain.from_function(lambda x, y: 0.0 * x, (0.0, 2 * RESERVOIR), (0.0, WIDTH),
                                    0.5)
    x, y = lattice(0.0, RESERVOIR, 0.0, WIDTH, DX)
    p = particles_with_depth(x, y, np.full(x.shape, level), DX, Numerics.kappa)
    num = Numerics(particle_spacing_m=DX, **{"time_stepping": TimeStepping.GLOBAL, **numerics})
    weir = Weir(crest, DX, num.kappa, name="walls[0]")
    boundaries: list = [weir]
    if inflow_q > 0.0:
        boundaries.insert(0, Inflow([[0.0, 0.0], [0.0, WIDTH]], Hydrograph([0.0, 1e4],
                                    [inflow_q, inflow_q]), DX, num.kappa, terrain,
                                    direction=[1.0, 0.0]))
    else:
        closed = (*closed, "west")
    model = set_up_model(terrain, p, num, walls=[WALL], closed_sides=closed,
                         boundaries=boundaries)
    return model, weir


# -- the weir law -------------------------------------------------------------------------------
def test_free_weir_law_and_villemonte_submergence():
    h = 0.3
    free = IDEAL_COEFFICIENT * math.sqrt(GRAVITY) * h ** 1.5
    assert IDEAL_COEFFICIENT * math.sqrt(GRAVITY) == pytest.approx(1.705, abs=1e-3)
    assert unit_discharge(h) == pytest.approx(free, rel=1e-14)
    assert unit_discharge(h, -0.2) == pytest.approx(free, rel=1e-14)  # tailwater below crest
    for ratio in (0.2, 0.5, 0.8, 0.95):
        expected = free * (1.0 - ratio ** 1.5) ** 0.385
        assert unit_discharge(h, ratio * h) == pytest.approx(expected, rel=1e-14)
    assert unit_discharge(h, h) == 0.0  # equal levels: no flow
    assert unit_discharge(-0.1) == 0.0 and unit_discharge(-np.inf) == 0.0
    # a tailwater half the head up cuts the flow by 15 %, nine tenths up by more than half
    assert unit_discharge(h, 0.5 * h) / free == pytest.approx(0.8454, abs=1e-4)
    assert unit_discharge(h, 0.9 * h) / free == pytest.approx(0.4770, abs=1e-4)


# -- the crest and its breach -------------------------------------------------------------------
def test_crest_is_linear_between_vertex_elevations():
    crest = Crest([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]], [2.0, 1.0, 3.0])
    assert crest.length == 20.0
    np.testing.assert_allclose(crest.at([0.0, 5.0, 10.0, 15.0, 20.0], 0.0),
                               [2.0, 1.5, 1.0, 2.0, 3.0])


@pytest.mark.parametrize("growth", ["linear", "sine"])
def test_breach_crest_follows_the_growth_curve(growth):
    """A 40 m wall with its crest at 10 m; the breach centred at 20 m, 8 m wide at the bottom,
    invert 4 m, sides 2:1, opens from t = 100 s over 600 s."""
    breach = Breach(centre_m=20.0, bottom_width_m=8.0, invert_m=4.0, side_slope=2.0,
                    start_s=100.0, formation_s=600.0, growth=growth)
    crest = Crest([[0.0, 0.0], [40.0, 0.0]], 10.0, breach)
    s = np.linspace(0.0, 40.0, 4001)
    np.testing.assert_array_equal(crest.at(s, 100.0), 10.0)  # not started yet
    for t in (250.0, 400.0, 550.0, 700.0, 1000.0):
        tau = min((t - 100.0) / 600.0, 1.0)
        r = tau if growth == "linear" else 0.5 * (1.0 - math.cos(math.pi * tau))
        bottom = 10.0 - r * 6.0
        z = crest.at(s, t)
        assert z.min() == pytest.approx(bottom, abs=1e-12)
        flat = s[np.isclose(z, bottom)]
        assert flat.max() - flat.min() == pytest.approx(r * 8.0, abs=0.02)  # 1 cm samples
        # the sides rise 1 m per 2 m from the bottom's edge to the crest
        edge = 20.0 + 0.5 * r * 8.0
        side = (s > edge) & (z < 10.0)
        np.testing.assert_allclose(z[side], bottom + (s[side] - edge) / 2.0, atol=1e-12)
    if growth == "sine":  # slow at the start: a quarter of the time gives 15 %, not 25 %
        assert crest.at([20.0], 250.0)[0] == pytest.approx(10.0 - 6.0 * 0.1464, abs=1e-3)


# -- the weir in the model ----------------------------------------------------------------------
SETTINGS = [{}, {"time_stepping": TimeStepping.LOCAL}, {"momentum": Momentum.BALANCED}]
SETTING_IDS = ["global", "local-steps", "balanced"]


@pytest.mark.parametrize("settings", SETTINGS, ids=SETTING_IDS)
def test_water_below_the_crest_stays_where_it_is(settings):
    model, weir = _channel(0.9, Crest(WALL, CREST), **settings)
    v0 = model.volume()
    run_until(model, 3.0)
    assert weir.volume_passed == 0.0
    assert model.volume() == v0  # not a bit lost
    assert model.particles.x.max() < RESERVOIR
    assert np.all(weir.head < 0.0)


def test_steady_free_flow_stands_at_the_weir_head():
    """0.5 m3/s enters a 5 m wide reservoir and leaves over the crest: once steady (t > 10 s),
    the upstream level 3-7 m from the wall stands at crest + (q / (C sqrt g))^(2/3) =
    crest + 0.151 m, and the volume passed per second is the weir discharge at that level,
    both within 10 %; the model's own head estimate gives the same."""
    q_in = 0.5
    head = (q_in / WIDTH / (IDEAL_COEFFICIENT * math.sqrt(GRAVITY))) ** (2.0 / 3.0)
    model, weir = _channel(CREST + head, Crest(WALL, CREST), inflow_q=q_in)
    run_until(model, 10.0)
    v_start, t_start = weir.volume_net, model.t
    levels, heads = [], []
    while model.t < 20.0 - 1e-9:
        model.step(20.0 - model.t)
        p = model.particles
        band = (p.x > 3.0) & (p.x < 7.0)
        levels.append(np.average(p.rho[band], weights=p.m[band] / p.rho[band]) / 1000.0)
        heads.append(np.mean(weir.head))
    passed = (weir.volume_net - v_start) / (model.t - t_start)
    h_up = float(np.mean(levels)) - CREST
    assert h_up == pytest.approx(head, rel=0.10)
    assert passed == pytest.approx(WIDTH * unit_discharge(h_up), rel=0.10)
    assert passed == pytest.approx(WIDTH * unit_discharge(float(np.mean(heads))), rel=0.10)
    assert passed == pytest.approx(q_in, rel=0.10)


@pytest.mark.parametrize("settings", SETTINGS, ids=SETTING_IDS)
def test_the_weir_moves_water_without_making_or_losing_any(settings):
    """A closed channel: the reservoir at crest + 0.2 m spills over the crest into the dry
    half; the water in the domain stays what it was to 1e-12 (with the global or local time
    steps, the variational or balanced momentum)."""
    model, weir = _channel(CREST + 0.2, Crest(WALL, CREST), closed=("south", "north", "east"),
                           **settings)
    v0 = model.volume()
    run_until(model, 4.0)
    assert weir.volume_passed > 1.0  # about a third of the water above the crest
    assert model.volume() == pytest.approx(v0, rel=1e-12)
    assert model.state.volume_out == 0.0
    downstream = model.particles.x > RESERVOIR
    assert model.particles.m[downstream].sum() / 1000.0 == pytest.approx(weir.volume_net,
                                                                         rel=1e-12)
    assert weir.volume_to_left == 0.0  # the wall runs north: the reservoir is on its left


def test_breach_opens_at_its_start_and_passes_more_and_more():
    """The reservoir stands 0.2 m below a 1.4 m crest; a breach 2 m wide, invert 0.5 m,
    opens at t = 1 s over 2 s: nothing passes before, then the outflow grows."""
    breach = Breach(centre_m=2.5, bottom_width_m=2.0, invert_m=0.5, side_slope=1.0,
                    start_s=1.0, formation_s=2.0, growth="linear")
    model, weir = _channel(1.2, Crest(WALL, 1.4, breach))
    run_until(model, 1.0)
    assert weir.volume_passed == 0.0
    passed = []
    for t in (2.0, 2.5, 3.0, 3.5):
        run_until(model, t)
        passed.append(weir.volume_net)
    assert passed[0] > 0.0
    assert np.all(np.diff(passed) > 0.0)
    increments = np.diff([0.0, *passed])
    assert increments[-1] > increments[0]  # the outflow grows with the breach


# -- inputs -----------------------------------------------------------------------------------
def _scenario(tmp_path: Path, wall: dict):
    dem = tmp_path / "dem.tif"
    dem.write_bytes(b"")
    data = {"scenario": {"name": "w", "end_time_s": 1.0}, "terrain": {"dem": str(dem)},
            "walls": [{"polyline": [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]], **wall}]}
    return scenario_from_dict(data, source="s.toml", base_dir=tmp_path)


BREACH = {"centre_m": 5.0, "invert_m": 0.5, "bottom_width_m": 2.0, "formation_s": 600.0}


def test_a_crest_wall_and_its_breach_are_read(tmp_path):
    wall = _scenario(tmp_path, {"crest_m": [2.0, 1.0, 3.0], "discharge_coefficient": 0.5,
                                "breach": {**BREACH, "growth": "sine"}}).walls[0]
    assert wall.crest_m == (2.0, 1.0, 3.0)
    assert wall.discharge_coefficient == 0.5
    assert wall.breach.growth.value == "sine" and wall.breach.start_s == 0.0
    plain = _scenario(tmp_path, {}).walls[0]
    assert plain.crest_m is None and plain.breach is None


@pytest.mark.parametrize("wall, key, words", [
    ({"crest_m": [1.0, 2.0]}, "walls[0].crest_m", "has 2 elevations but the polyline has 3"),
    ({"crest_m": "high"}, "walls[0].crest_m", "expected a number"),
    ({"breach": BREACH}, "walls[0].breach", "needs crest_m"),
    ({"crest_m": 1.0, "breach": {**BREACH, "formation_s": 0.0}},
     "walls[0].breach.formation_s", "must be > 0"),
    ({"crest_m": 1.0, "breach": {**BREACH, "start_s": -5.0}}, "walls[0].breach.start_s",
     "must be >= 0"),
    ({"crest_m": 1.0, "breach": {**BREACH, "invert_m": 1.5}}, "walls[0].breach.invert_m",
     "not below the crest"),
    ({"crest_m": 1.0, "breach": {**BREACH, "growth": "cubic"}}, "walls[0].breach.growth",
     "expected one of"),
    ({"crest_m": 1.0, "breach": {**BREACH, "froehlich": True}}, "walls[0].breach.bottom_width_m",
     "not both"),
    ({"crest_m": 1.0, "breach": {"centre_m": 5.0, "invert_m": 0.0, "froehlich": True}},
     "walls[0].breach.reservoir_volume_m3", "required with froehlich"),
])
def test_bad_crest_and_breach_keys_are_refused(tmp_path, wall, key, words):
    with pytest.raises(InputError) as caught:
        _scenario(tmp_path, wall)
    message = str(caught.value)
    assert f"s.toml: {key}:" in message and words in message


def _weirs_of(tmp_path, wall: dict, bed: float = 0.0):
    scenario = _scenario(tmp_path, wall)
    terrain = Terrain.from_function(lambda x, y: bed + 0.0 * x, (-5.0, 15.0), (-5.0, 15.0), 1.0)
    line = np.array(scenario.walls[0].polyline) + 5.0  # local coordinates
    inputs = SimpleNamespace(terrain=terrain, walls=[line], wall_entries=scenario.walls)
    return weirs(inputs, Numerics(particle_spacing_m=0.5), "s.toml")


@pytest.mark.parametrize("wall, bed, key, words", [
    ({"crest_m": 1.0, "breach": {**BREACH, "centre_m": 25.0}}, 0.0,
     "walls[0].breach.centre_m", "beyond the end of the wall, which is 20 m long"),
    ({"crest_m": 1.0, "breach": {**BREACH, "bottom_width_m": 30.0}}, 0.0,
     "walls[0].breach.bottom_width_m", "only 20 m long"),
    ({"crest_m": [2.0, 1.0, 3.0], "breach": {**BREACH, "invert_m": 1.6}}, 0.0,
     "walls[0].breach.invert_m", "not below the crest at the breach centre (1.5 m)"),
    ({"crest_m": 1.0}, 2.0, "walls[0].crest_m", "below the DEM bed at every vertex"),
])
def test_crest_and_breach_off_the_wall_or_the_ground_are_refused(tmp_path, wall, bed, key,
                                                                  words):
    with pytest.raises(InputError) as caught:
        _weirs_of(tmp_path, wall, bed)
    message = str(caught.value)
    assert f"s.toml: {key}:" in message and words in message


def test_froehlich_breach_takes_its_size_and_time_from_the_regression(tmp_path):
    from floodsph.breach import formulas

    (weir,) = _weirs_of(tmp_path, {"crest_m": 10.0, "breach": {
        "centre_m": 10.0, "invert_m": 4.0, "froehlich": True, "reservoir_volume_m3": 2e5}})
    b = weir.crest.breach
    average = formulas.froehlich2008_average_width(2e5, 6.0, "overtopping")
    assert b.bottom_width_m == pytest.approx(average - 1.0 * 6.0, rel=1e-12)
    assert b.formation_s == pytest.approx(63.2 * math.sqrt(2e5 / (GRAVITY * 36.0)), rel=1e-12)
