"""The balanced momentum (``numerics.momentum = "balanced"``, ``floodsph.sph.level_momentum``):
a lake at rest stays exactly at rest by walls turned off the lattice, by nodata banks and on a
shore; mass is exact; still water is not refined; the settings it refuses."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from sph_cases import run_until

from floodsph.inputs.initial_water import seed_particles
from floodsph.model.builder import set_up_model
from floodsph.model.refinement import Refiner
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import (
    Momentum,
    Numerics,
    NumericsError,
    Refinement,
    Stabilisation,
    TimeStepping,
    WallModel,
)
from floodsph.sph import level_offsets
from floodsph.verification import cases

LEVEL_M = 2.0
SPACING_M = 5.0


def lake(bed, size, level, momentum, walls=(), valid=None, refinement=Refinement.NONE,
         time_stepping=TimeStepping.GLOBAL):
    """A model of still water at ``level`` [m] over ``bed`` on a square of side ``size`` [m]
    (2 m cells), seeded as a scenario's initial water is."""
    terrain = Terrain.from_function(bed, (0.0, size), (0.0, size), 2.0)
    if valid is not None:
        terrain = Terrain(terrain.elevation, terrain.dx, terrain.dy, valid=valid(terrain))
    depth = np.maximum(level - terrain.elevation, 0.0)
    if valid is not None:
        depth = np.where(terrain.valid, depth, 0.0)
    inside = np.ones(terrain.shape, dtype=bool)
    if walls:
        xc, yc = np.meshgrid(*terrain.cell_centres())
        inside = shapely.contains_xy(shapely.Polygon(walls[0]), xc, yc)
    particles = seed_particles(terrain, np.where(inside, depth, 0.0), SPACING_M,
                               Numerics.kappa, wet=terrain.valid)
    numerics = Numerics(particle_spacing_m=SPACING_M, momentum=momentum,
                        refinement=refinement, time_stepping=time_stepping)
    return set_up_model(terrain, particles, numerics, walls=walls, refiner=Refiner.of(numerics))


def turned_box(cx, cy, half, degrees):
    """A closed square polyline of half-side ``half`` [m] about (cx, cy), turned."""
    a = math.radians(degrees)
    corners = [(-half, -half), (half, -half), (half, half), (-half, half), (-half, -half)]
    return np.array([(cx + x * math.cos(a) - y * math.sin(a),
                      cy + x * math.sin(a) + y * math.cos(a)) for x, y in corners])


def max_speed(model) -> float:
    p = model.particles
    return float(np.hypot(p.u, p.v).max())


def test_a_lake_walled_off_the_lattice_stays_exactly_at_rest():
    """Walls turned 15 degrees from the lattice: today's variational force stirs this lake to
    centimetres per second; the level differences hold it at rest to round-off."""
    walls = [turned_box(60.0, 60.0, 40.0, 15.0)]
    flat = lambda x, y: 0.0 * x  # noqa: E731
    balanced = run_until(lake(flat, 120.0, LEVEL_M, Momentum.BALANCED, walls=walls), 30.0)
    variational = run_until(lake(flat, 120.0, LEVEL_M, Momentum.VARIATIONAL, walls=walls),
                            30.0)
    assert max_speed(balanced) < 1e-9
    assert max_speed(variational) > 1e-3


def test_a_lake_against_a_nodata_staircase_stays_exactly_at_rest():
    """The DEM's nodata cells cut a staircase into the lake; its banks are walls."""
    def stairs(terrain):
        xc, yc = np.meshgrid(*terrain.cell_centres())
        return ~((xc > 40.0) & (yc > 120.0 - xc))

    model = run_until(lake(lambda x, y: 0.0 * x, 100.0, LEVEL_M, Momentum.BALANCED,
                           valid=stairs), 30.0)
    assert model.particles.n > 100
    assert max_speed(model) < 1e-9


def test_a_lake_in_a_bowl_keeps_its_shore_and_is_not_refined():
    """A paraboloid bowl under a 2 m level, with splitting and coalescing on and local time
    steps: no particle moves, none is split or merged, the shore stays within one spacing
    of the exact one."""
    size, slope = 200.0, 0.03
    bowl = lambda x, y: slope * np.hypot(x - size / 2, y - size / 2) - 1.0  # noqa: E731
    model = lake(bowl, size, LEVEL_M, Momentum.BALANCED,
                 refinement=Refinement.SPLIT_COALESCE, time_stepping=TimeStepping.LOCAL)
    run_until(model, 30.0)
    p = model.particles
    assert max_speed(model) < 1e-9
    assert model.state.counters["splits"] == 0 and model.state.counters["merges"] == 0
    shore = (LEVEL_M + 1.0) / slope
    r = np.hypot(p.x - size / 2, p.y - size / 2)
    assert abs(r.max() - shore) < SPACING_M


def test_a_dam_break_keeps_its_mass_exactly():
    result = cases.ritter(20.0, momentum=Momentum.BALANCED)
    assert result.mass_error_rel < 1e-12


def test_the_dam_breaks_at_10_m_keep_the_variational_bounds():
    """Moving water takes the variational force (the blend of
    ``floodsph.sph.momentum_blend.variational_weight``): Ritter, Stoker and Thacker stay within
    the bounds the default meets (L1 2.0 %, 0.65 %, and 2.5 % at 200 m)."""
    assert cases.ritter(10.0, momentum=Momentum.BALANCED).l1 <= 0.020
    assert cases.stoker(10.0, momentum=Momentum.BALANCED).l1 <= 0.0065
    assert cases.thacker(200.0, momentum=Momentum.BALANCED).l1 <= 0.025


@pytest.mark.parametrize("change, named", [
    (dict(stabilisation=Stabilisation.MUSCL), "stabilisation"),
    (dict(wall_model=WallModel.INTEGRAL), "wall_model")])
def test_settings_the_balanced_momentum_does_not_take_are_refused_by_name(change, named):
    with pytest.raises(NumericsError, match=rf'numerics.{named}: .*momentum = "variational"'):
        Numerics(momentum=Momentum.BALANCED, **change)


def test_a_disturbed_lake_against_a_nodata_staircase_returns_to_rest():
    """Still water held by its banks (``floodsph.sph.level_offsets.HELD``) is damped: random
    velocities of 0.1 mm/s die out (to 4.8e-6 m/s in 40 s), no particle is released, and the
    level stays within a millimetre of the seeded one; a disturbance of 2 cm/s releases most
    of the water (the particles it leaves slower than 1 cm/s stay held)."""
    def stairs(terrain):
        xc, yc = np.meshgrid(*terrain.cell_centres())
        return ~((xc > 40.0) & (yc > 120.0 - xc))

    def disturbed(amplitude):
        model = lake(lambda x, y: 0.02 * x, 100.0, LEVEL_M, Momentum.BALANCED, valid=stairs)
        p = model.particles
        rng = np.random.default_rng(3)
        p.u += amplitude * rng.standard_normal(p.n)
        p.v += amplitude * rng.standard_normal(p.n)
        return model

    model = disturbed(1e-4)
    assert (model.particles.bank_held == level_offsets.HELD).mean() > 0.5
    run_until(model, 40.0)
    p = model.particles
    assert max_speed(model) < 1e-5
    assert (p.bank_held == level_offsets.HELD).mean() > 0.5
    assert np.abs(model.surface_levels() - LEVEL_M).max() < 1e-3
    released = run_until(disturbed(2e-2), 2.0)
    assert (released.particles.bank_held == level_offsets.HELD).mean() < 0.3


def test_particle_fields_assign_in_place():
    """``p.u += du`` writes into the particle arrays (an attribute would shadow the field and
    outlive the next reallocation)."""
    model = lake(lambda x, y: 0.0 * x, 60.0, LEVEL_M, Momentum.BALANCED)
    p = model.particles
    p.u += 1.0
    p.append(x=np.array([1.0]), y=np.array([1.0]), m=np.array([1.0]), rho=np.array([1.0]),
             h=np.array([1.0]))
    assert p.u.shape == (p.n,) and np.all(p.u[:-1] == 1.0) and p.u[-1] == 0.0
