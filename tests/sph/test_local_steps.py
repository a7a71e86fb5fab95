"""Local time stepping (``numerics.time_stepping = "local"``): strides, limiter and the solver."""

import math

import numpy as np
import pytest
from sph_cases import model_on, particles_with_depth, run_until

from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.model.builder import set_up_model
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Numerics, Refinement, TimeStepping
from floodsph.sph import local_steps
from floodsph.sph.neighbours import NeighbourList
from floodsph.verification import cases


def test_strides_are_the_largest_powers_of_two_within_each_particles_own_cfl_step():
    rng = np.random.default_rng(3)
    n = 2000
    u, v = rng.normal(0, 2, n), rng.normal(0, 2, n)
    d = rng.uniform(0.001, 10.0, n)
    h = rng.uniform(1.0, 30.0, n)
    cfl, dt_f, top = 0.3, 0.05, 8
    out = np.empty(n, dtype=np.int64)
    local_steps.strides(u, v, RHO_WATER * d, h, cfl, dt_f, top, out)
    dt_own = cfl * h / (np.hypot(u, v) + np.sqrt(GRAVITY * d))
    expected = np.clip(2 ** np.floor(np.log2(dt_own / dt_f)), 1, top).astype(np.int64)
    assert np.array_equal(out, expected)
    within = dt_own >= dt_f
    assert np.all(out[within] * dt_f <= dt_own[within])  # each particle's own CFL holds
    assert {1, 2, 4, 8} <= set(out.tolist())


def test_the_limiter_keeps_every_stride_within_twice_those_of_its_neighbours():
    rng = np.random.default_rng(4)
    n = 1500
    x, y = rng.uniform(0, 300, n), rng.uniform(0, 300, n)
    h = np.full(n, 8.0)
    nl = NeighbourList(x, y, h)
    stride = 2 ** rng.integers(0, 4, n)
    out = np.empty(n, dtype=np.int64)
    local_steps.limit_strides(stride, nl.start, nl.nbr, n, out)
    brute = stride.copy()
    for i in range(n):
        nbrs = nl.nbr[nl.start[i]:nl.start[i + 1]]
        if nbrs.size:
            brute[i] = min(stride[i], 2 * stride[nbrs].min())
    assert np.array_equal(out, brute)
    assert (out < stride).any()


def test_a_refined_dam_break_with_local_steps_matches_the_global_step_with_less_work():
    """Ritter at 10 m with splitting and coalescing: the split particles of the thin, fast
    front need short steps, the reservoir behind the rarefaction does not."""
    glob = cases.ritter(10.0, refinement=Refinement.SPLIT_COALESCE)
    loc = cases.ritter(10.0, refinement=Refinement.SPLIT_COALESCE,
                       time_stepping=TimeStepping.LOCAL)
    assert loc.mass_error_rel < 1e-12
    assert loc.l1 <= 1.05 * glob.l1  # measured 0.76 % against 0.86 %
    assert abs(loc.front_error_m) <= 2 * 10.0  # measured 16 m behind (global: 23 m)
    assert loc.particle_steps < 0.8 * glob.particle_steps  # measured 0.73


def test_a_column_collapsing_in_a_closed_box_keeps_its_mass_and_stays_inside_with_local_steps():
    """Particles between their own updates still drift every finest step, against the walls."""
    model = model_on(lambda x, y: 0 * x, (0, 300), (0, 200), 10.0,
                     lambda x, y: np.where(x < 100, 5.0, 0.0), 5.0,
                     time_stepping=TimeStepping.LOCAL)
    p = model.particles
    n0, m0 = p.n, p.m.sum()
    run_until(model, 40.0)
    assert model.state.counters["particle_updates"] < 0.99 * model.steps * p.n  # strides mixed
    assert model.state.counters["wall_reflections"] > 0
    assert p.n == n0 and model.state.volume_out == 0.0
    assert abs(p.m.sum() - m0) <= 1e-12 * m0
    assert p.x.min() >= 0 and p.x.max() <= 300 and p.y.min() >= 0 and p.y.max() <= 200


def test_local_steps_conserve_momentum_to_the_order_of_the_step():
    """Free flat frictionless bed, mixed depths and speeds: pairs act at their own times, so
    sum m v is not exact as with one step, but drifts by a small fraction of |sum m v|."""
    terrain = Terrain.from_function(lambda x, y: 0 * x, (0, 2000), (0, 2000), 20.0)
    rng = np.random.default_rng(0)
    x, y = np.meshgrid(np.arange(800, 1200, 8.0), np.arange(850, 1150, 8.0))
    x, y = x.ravel(), y.ravel()
    d = np.where(x < 1000, 4.0, 0.5) + 0.2 * rng.random(x.size)
    p = particles_with_depth(x, y, d, 8.0, 1.3, u=rng.normal(0, 1, x.size) + 2.0,
                             v=rng.normal(0, 1, x.size) - 1.0)
    numerics = Numerics(particle_spacing_m=8.0, kappa=1.3, time_stepping=TimeStepping.LOCAL)
    model = set_up_model(terrain, p, numerics, closed_sides=())
    mom0 = np.array([(p.m * p.u).sum(), (p.m * p.v).sum()])
    run_until(model, 20.0)
    assert model.state.volume_out == 0.0
    assert model.state.counters["particle_updates"] < 0.9 * model.steps * p.n  # measured 0.49
    mom = np.array([(p.m * p.u).sum(), (p.m * p.v).sum()])
    assert np.abs(mom - mom0).max() < 0.005 * math.hypot(*mom0)  # measured 0.11 %


def test_numerics_reject_a_time_stepping_that_is_no_time_stepping():
    with pytest.raises(ValueError, match=r"numerics.time_stepping: expected a "
                                         r"floodsph.scenario.numerics.TimeStepping \('global', "
                                         r"'local'\), got 'local'"):
        Numerics(time_stepping="local")  # the string, not TimeStepping.LOCAL
