"""Particle splitting and coalescing (floodsph.model.refinement, floodsph.sph.refine).

Facts checked: every split and every merge conserves mass and momentum to round-off; the
depth field survives a split and a merge; the merged smoothing length satisfies its kernel
identity; daughters never land across a wall; splitting a coarse dam break improves it.
"""

import math

import numpy as np
import pytest

from floodsph.constants import RHO_WATER
from floodsph.errors import InputError
from floodsph.model.builder import set_up_model
from floodsph.model.refinement import Refiner
from floodsph.model.refinement_site import protected
from floodsph.model.terrain import Terrain
from floodsph.output.rasterise import interpolate
from floodsph.scenario.numerics import (
    SMOOTHING_EXCESS,
    Momentum,
    Numerics,
    NumericsError,
    Refinement,
)
from floodsph.sph import refine
from floodsph.sph.kernels import SIGMA_2D, w_cubic
from floodsph.verification import cases
from tests.sph_cases import lattice, model_on, particles_with_depth


def flat(x, y):
    return 0.0 * x


def jittered_pond(depth, size=30.0, dx=1.0, jitter=0.15, seed=1, u=0.0, v=0.0):
    """A closed flat box of water on a jittered lattice (no exact nearest-neighbour ties)."""
    rng = np.random.default_rng(seed)
    terrain = Terrain.from_function(flat, (0, size), (0, size), 1.0)
    x, y = lattice(0.0, size, 0.0, size, dx)
    x = x + rng.uniform(-jitter, jitter, x.size)
    y = y + rng.uniform(-jitter, jitter, y.size)
    d = depth(x, y) if callable(depth) else np.full(x.size, depth)
    uu = u(x, y) if callable(u) else u
    vv = v(x, y) if callable(v) else v
    p = particles_with_depth(x, y, d, dx, 1.3, u=uu, v=vv)
    return set_up_model(terrain, p, Numerics(particle_spacing_m=dx, kappa=1.3))


def make_refiner(spacing: float, **settings) -> Refiner:
    """The Refiner of ``Numerics(particle_spacing_m=spacing, **settings)``."""
    return Refiner(Numerics(particle_spacing_m=spacing, **settings))


def split_only(**settings) -> Refiner:
    """A split-only Refiner at 1 m spacing that splits particles above half the lattice area
    (``settings`` override)."""
    return make_refiner(1.0, **{"refinement": Refinement.SPLIT, "refine_area_max": 0.5,
                                "refine_area_min": 0.05, **settings})


def totals(p):
    """Mass [kg], momentum (2,) [kg m/s] and the momentum scale sum m |v| of a particle set."""
    mom = np.array([np.sum(p.m * p.u), np.sum(p.m * p.v)])
    return p.m.sum(), mom, np.sum(p.m * np.hypot(p.u, p.v))


def on(model):
    """The refiner's arguments for ``model``: its state, and what the refiner sees of it."""
    return model.state, model.parts().refinement_site


def shepard_depth(model, x, y):
    p = model.particles
    return interpolate(np.asarray(x), np.asarray(y), p.x, p.y, p.u, p.v, p.m, p.rho, p.h)[0]


def solve_in_place(model):
    """Let the model solve density and h without moving anything (a 1e-9 s step)."""
    model.step(dt_max=1e-9)


# -- settings ------------------------------------------------------------------------------------
def test_settings_reject_thresholds_without_hysteresis():
    with pytest.raises(InputError, match=r"numerics.refine_area_min: must be below "
                                         r"refine_area_max / 2 = 1 .*got 1\.5"):
        Numerics(refine_area_max=2.0, refine_area_min=1.5)
    with pytest.raises(NumericsError, match=r"numerics.refinement: expected a "
                                            r"floodsph.scenario.numerics.Refinement "
                                            r".*got 'coarsen'"):
        Numerics(refinement="coarsen")
    assert Refiner.of(Numerics(particle_spacing_m=10.0, refinement=Refinement.NONE)) is None
    r = Refiner.of(Numerics(particle_spacing_m=10.0, refinement=Refinement.SPLIT))
    assert r.area_max == pytest.approx(2.0 * 100.0) and not r.numerics.refinement.coalesces


# -- splitting -----------------------------------------------------------------------------------
def test_each_split_conserves_mass_and_momentum():
    model = jittered_pond(lambda x, y: 0.5 + 0.02 * x, u=lambda x, y: 1.0 + 0.1 * y,
                          v=lambda x, y: -0.5 + 0.05 * x)
    p = model.particles
    refiner = split_only()
    parents = refiner.split_candidates(*on(model))
    interior = parents[(p.x[parents] > 3) & (p.x[parents] < 27)]
    m_p, mu_p, mv_p = p.m[interior].copy(), (p.m * p.u)[interior], (p.m * p.v)[interior]
    x_p, y_p, h_p = p.x[interior].copy(), p.y[interior].copy(), p.h[interior].copy()
    heading = np.arctan2(p.v[interior], p.u[interior])
    mass0, mom0, scale = totals(p)
    assert refiner.execute(*on(model), interior, [], []) == (interior.size, 0)
    daughters = slice(p.n - 7 * interior.size, p.n)
    m_k = p.m[daughters].reshape(-1, 7)
    assert np.allclose(m_k.sum(axis=1), m_p, rtol=1e-14, atol=0.0)
    assert np.allclose((p.m * p.u)[daughters].reshape(-1, 7).sum(axis=1), mu_p, rtol=1e-13)
    assert np.allclose((p.m * p.v)[daughters].reshape(-1, 7).sum(axis=1), mv_p, rtol=1e-13)
    mass1, mom1, _ = totals(p)
    assert abs(mass1 - mass0) <= 1e-12 * mass0
    assert np.all(np.abs(mom1 - mom0) <= 1e-12 * scale)
    # the pattern: centre at the parent, six at 0.4 h_p, the first along the velocity
    dx = p.x[daughters].reshape(-1, 7) - x_p[:, None]
    dy = p.y[daughters].reshape(-1, 7) - y_p[:, None]
    assert np.allclose(dx[:, 0], 0.0) and np.allclose(dy[:, 0], 0.0)
    assert np.allclose(np.hypot(dx[:, 1:], dy[:, 1:]), 0.4 * h_p[:, None], rtol=1e-12)
    assert np.allclose(np.arctan2(dy[:, 1], dx[:, 1]), heading, atol=1e-12)
    assert np.allclose(p.h[daughters].reshape(-1, 7), 0.9 * h_p[:, None], rtol=1e-14)
    assert np.all(p.level[daughters] == 1)


def test_split_keeps_the_depth_of_uniform_water():
    """A split patch and a single split particle: SPH depth at the daughters within 2 %. The
    split is forced on water at rest, which the balanced momentum holds and never splits; so
    the variational momentum, whose depth is the summation's everywhere."""
    for centre, radius in ((20.5, 0.1), (20.0, 6.0)):
        model = model_on(flat, (0, 40), (0, 40), 1.0, 1.0, 1.0, momentum=Momentum.VARIATIONAL)
        p = model.particles
        parents = np.flatnonzero(np.hypot(p.x - centre, p.y - centre) < radius)
        split_only().execute(*on(model), parents, [], [])
        solve_in_place(model)
        born = p.level > 0
        assert born.sum() == 7 * parents.size
        d = shepard_depth(model, p.x[born], p.y[born])
        assert np.all(np.abs(d - 1.0) < 0.02), (radius, d.min(), d.max())


def test_no_split_across_a_wall_or_below_d_min_or_beyond_max_level():
    terrain = Terrain.from_function(flat, (0, 20), (0, 20), 1.0)
    x, y = lattice(0.0, 20.0, 0.0, 20.0, 1.0)
    wall_x = 10.3  # particles at x = 9.5 and 10.5 sit 0.8 and 0.2 m from the wall
    d = np.where(y < 10.0, 1.0, 0.005)  # the north half is thinner than d_min = 0.01 m
    p = particles_with_depth(x, y, d, 1.0, 1.3)
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=1.0, kappa=1.3),
                       walls=[np.array([[wall_x, 0.0], [wall_x, 20.0]])])
    p = model.particles
    refiner = split_only(refine_max_level=1)
    parents = refiner.split_candidates(*on(model))
    hexagon = refine.EPS * p.h[parents]
    assert np.all(np.abs(p.x[parents] - wall_x) > hexagon)
    assert np.any((np.abs(p.x - wall_x) < 0.3) & (p.y < 10.0))  # left whole by the wall
    assert np.all(p.rho[parents] >= RHO_WATER * 0.01)
    refiner.execute(*on(model), parents, [], [])
    p = model.particles
    on_west = p.x[p.level > 0] < wall_x
    parent_west = np.repeat(np.asarray(on_west[::7]), 7)
    assert np.array_equal(on_west, parent_west)  # every family on its parent's side
    assert refiner.split_candidates(*on(model)).size == 0  # daughters are at max_level


# -- coalescing ----------------------------------------------------------------------------------
def test_merged_h_satisfies_the_kernel_identity():
    """m_M W(0, h_M) = m_a W(r_a, h_a) + m_b W(r_b, h_b) with the model's own kernel."""
    rng = np.random.default_rng(3)
    for _ in range(50):
        m_a, m_b = rng.uniform(10.0, 1000.0, 2)
        h_a, h_b = rng.uniform(0.5, 3.0, 2)
        r = rng.uniform(0.0, min(h_a, h_b))
        r_a, r_b = r * m_b / (m_a + m_b), r * m_a / (m_a + m_b)
        h_m = refine.merged_h(m_a, m_b, r_a, r_b, h_a, h_b)
        s = m_a * w_cubic(r_a, h_a) + m_b * w_cubic(r_b, h_b)
        assert (m_a + m_b) * w_cubic(0.0, h_m) == pytest.approx(s, rel=1e-12)
        # PySPH's FindMergeable constant (7 pi / 10 in place of 10 / (7 pi)) misses it
        h_pysph = math.sqrt(7.0 * math.pi / 10.0 * (m_a + m_b) / s)
        assert h_pysph / h_m == pytest.approx(7.0 * math.pi / 10.0, rel=1e-12)
    assert SIGMA_2D == pytest.approx(10.0 / (7.0 * math.pi))
    # two coincident equal particles merge into one with the same density
    assert refine.merged_h(5.0, 5.0, 0.0, 0.0, 1.5, 1.5) == pytest.approx(1.5, rel=1e-14)


def test_each_merge_conserves_mass_and_momentum():
    model = jittered_pond(1.0, u=lambda x, y: 0.3 + 0.01 * y, v=lambda x, y: 0.1 - 0.01 * x)
    p = model.particles
    refiner = make_refiner(1.0, refine_area_max=20.0, refine_area_min=2.0, refine_no_merge_steps=0,
                           refine_depth_jump=0.2)
    a, b = refiner.merge_pairs(*on(model))
    assert a.size > 50
    assert len(set(a) | set(b)) == 2 * a.size  # each particle in one pair at most
    pair_m = p.m[a] + p.m[b]
    pair_mu = (p.m * p.u)[a] + (p.m * p.u)[b]
    pair_mv = (p.m * p.v)[a] + (p.m * p.v)[b]
    mass0, mom0, scale = totals(p)
    assert refiner.execute(*on(model), [], a, b) == (0, a.size)
    merged = slice(p.n - a.size, p.n)
    assert np.allclose(p.m[merged], pair_m, rtol=1e-15, atol=0.0)
    assert np.allclose((p.m * p.u)[merged], pair_mu, rtol=1e-13)
    assert np.allclose((p.m * p.v)[merged], pair_mv, rtol=1e-13)
    mass1, mom1, _ = totals(p)
    assert abs(mass1 - mass0) <= 1e-12 * mass0
    assert np.all(np.abs(mom1 - mom0) <= 1e-12 * scale)


def test_merge_keeps_the_depth_at_the_merged_position():
    """One merge at a time in water with a depth gradient: depth within 5 % of before."""
    def depth(x, y):
        return 1.0 + 0.002 * x

    refiner = make_refiner(1.0, refine_area_max=20.0, refine_area_min=2.0, refine_no_merge_steps=0)
    model = jittered_pond(depth)
    a, b = refiner.merge_pairs(*on(model))
    p = model.particles
    w = p.m[a] / (p.m[a] + p.m[b])
    xm, ym = w * p.x[a] + (1 - w) * p.x[b], w * p.y[a] + (1 - w) * p.y[b]
    inner = np.flatnonzero((np.abs(xm - 15.0) < 9.0) & (np.abs(ym - 15.0) < 9.0))[:8]
    for k in inner:
        model = jittered_pond(depth)
        before = shepard_depth(model, xm[k:k + 1], ym[k:k + 1])[0]
        refiner.execute(*on(model), [], a[k:k + 1], b[k:k + 1])
        solve_in_place(model)
        p = model.particles
        merged = np.argmax(p.m)
        assert (p.x[merged], p.y[merged]) == pytest.approx((xm[k], ym[k]), abs=1e-9)
        assert abs(p.rho[merged] / RHO_WATER / before - 1.0) < 0.05
        assert abs(shepard_depth(model, xm[k:k + 1], ym[k:k + 1])[0] / before - 1.0) < 0.05


def pond_with_small_particles(fraction, at):
    """The jittered 1 m pond with extra particles of ``fraction`` of a lattice particle's mass
    (and h0 = kappa sqrt(fraction) m, the lattice value of their area) at the points ``at``
    ((k, 2) [m]), moving at (0.2, -0.1) m/s; returns the model and their indices."""
    base = jittered_pond(1.0)
    q = base.particles
    x = np.concatenate([q.x, at[:, 0]])
    y = np.concatenate([q.y, at[:, 1]])
    p = particles_with_depth(x, y, np.ones(x.size), 1.0, 1.3)
    p.m[q.n:] *= fraction
    p.h[q.n:] = p.h0[q.n:] = 1.3 * math.sqrt(fraction)  # the lattice h of their area
    p.u[q.n:], p.v[q.n:] = 0.2, -0.1
    model = set_up_model(base.terrain, p, Numerics(particle_spacing_m=1.0, kappa=1.3))
    small = np.flatnonzero(np.isin(model.particles.pid, np.arange(q.n, p.n)))
    return model, small


def test_a_small_particle_among_large_ones_is_absorbed_by_its_nearest():
    """A particle of a tenth of its neighbours' mass (h about a third of theirs) finds no fellow
    candidate; it merges into its nearest particle, mass and momentum exact. The depth
    interpolated at the merged position, 19 % above the pond's before (the small particle's
    own summed depth is 2.9 m), is then the pond's to 5 %, and the stable step, which the
    small particles set, grows eightfold."""
    at = np.array([[10.3, 12.6], [20.4, 8.2]])
    model, small = pond_with_small_particles(0.1, at)
    p = model.particles
    refiner = make_refiner(1.0, refine_area_max=2.0, refine_area_min=0.8, refine_no_merge_steps=0)
    a, b = refiner.merge_pairs(*on(model))  # the lattice's areas are 0.85-1.15: no candidates
    assert sorted(a) == sorted(small)
    for t, partner in zip(a, b, strict=True):
        r = np.hypot(p.x - p.x[t], p.y - p.y[t])
        r[t] = np.inf
        assert partner == np.argmin(r)
    w = p.m[a] / (p.m[a] + p.m[b])
    xm, ym = w * p.x[a] + (1 - w) * p.x[b], w * p.y[a] + (1 - w) * p.y[b]
    before = shepard_depth(model, xm, ym)
    dt0 = model.stable_dt()
    mass0, mom0, scale = totals(p)
    assert refiner.execute(*on(model), [], a, b) == (0, 2)
    mass1, mom1, _ = totals(p)
    assert abs(mass1 - mass0) <= 1e-12 * mass0
    assert np.all(np.abs(mom1 - mom0) <= 1e-12 * scale)
    solve_in_place(model)
    mean = p.m.sum() / RHO_WATER / 30.0**2  # the pond's volume over its area [m]
    assert np.all(np.abs(shepard_depth(model, xm, ym) / mean - 1.0) < 0.05)
    assert np.abs(before / mean - 1.0).max() > 0.15  # the small particle's own depth, 2.9 m
    assert model.stable_dt() > 4.0 * dt0


def test_a_small_particle_is_not_absorbed_where_the_merged_one_would_split():
    """Absorption keeps the hysteresis: no absorber whose merged area would reach
    2 area_min (here 0.1 + 1.0 against 2 x 0.5), and none across a velocity jump."""
    model, small = pond_with_small_particles(0.1, np.array([[10.3, 12.6]]))
    tight = make_refiner(1.0, refine_area_max=2.0, refine_area_min=0.5, refine_no_merge_steps=0)
    assert tight.merge_pairs(*on(model))[0].size == 0
    loose = make_refiner(1.0, refine_area_max=2.0, refine_area_min=0.8, refine_no_merge_steps=0)
    assert loose.merge_pairs(*on(model))[0].tolist() == small.tolist()
    model.particles.u[small] = 1.6  # against 0.5 sqrt(g d) = 1.57 m/s in 1 m of still water
    assert loose.merge_pairs(*on(model))[0].size == 0


def test_no_merge_near_walls_across_jumps_or_of_newborns():
    model = jittered_pond(lambda x, y: np.where(x < 15.0, 1.0, 0.7))
    p = model.particles
    refiner = make_refiner(1.0, refine_area_max=20.0, refine_area_min=2.0, refine_no_merge_steps=0,
                           refine_depth_jump=0.2)
    a, b = refiner.merge_pairs(*on(model))
    near_walls = protected(model.parts().refinement_site, p.x, p.y, p.h)
    assert not near_walls[a].any() and not near_walls[b].any()
    assert near_walls.any()
    d_a, d_b = p.rho[a], p.rho[b]
    assert np.all(np.abs(d_a - d_b) <= 0.2 * np.maximum(d_a, d_b))
    patient = make_refiner(1.0, refine_area_max=20.0, refine_area_min=2.0, refine_no_merge_steps=10)
    assert patient.merge_pairs(*on(model))[0].size == 0  # all born at step 0, now step 0


def kinetic_energy(p):
    return float(np.sum(0.5 * p.m * (p.u**2 + p.v**2)))


def test_split_then_merge_operators_create_no_spurious_velocity():
    """Splitting a patch of a uniformly moving sheet and merging its daughters back, with no
    time step between, leaves every particle with the sheet's velocity to round-off: the
    operators themselves create no velocity (the pressure response of the new arrangement is
    the next two tests' subject)."""
    model = model_on(flat, (0, 24), (0, 24), 1.0, 1.0, 1.0)
    p = model.particles
    p.u[:], p.v[:] = 1.3, -0.4
    n0, mass0 = p.n, p.m.sum()
    split_only().execute(*on(model), np.flatnonzero(np.hypot(p.x - 12.0, p.y - 12.0) < 3.5), [], [])
    assert p.n > n0
    merger = make_refiner(1.0, refine_area_max=3.0, refine_area_min=0.3, refine_no_merge_steps=0)
    merges = 0
    for _ in range(10):
        a, b = merger.merge_pairs(*on(model))
        if a.size == 0:
            break
        merges += merger.execute(*on(model), [], a, b)[1]
    assert merges > 40
    assert np.abs(p.u - 1.3).max() < 1e-12 and np.abs(p.v + 0.4).max() < 1e-12
    assert abs(p.m.sum() - mass0) < 1e-12 * mass0


@pytest.fixture(scope="module")
def pond_after_split_and_merge():
    """A 1 m deep still pond: a patch split, its daughters merged back over 30 steps, then
    150 more steps (20 s). Returns (model, merges, max speed and kinetic energy [J] at the
    end of the merging)."""
    model = model_on(flat, (0, 24), (0, 24), 1.0, 1.0, 1.0)
    p = model.particles
    split_only().execute(*on(model), np.flatnonzero(np.hypot(p.x - 12.0, p.y - 12.0) < 3.5), [], [])
    merger = make_refiner(1.0, refine_area_max=3.0, refine_area_min=0.3, refine_no_merge_steps=0)
    merges = 0
    for _ in range(30):
        model.step()
        merges += merger.execute(*on(model), [], *merger.merge_pairs(*on(model)))[1]
    speed0, energy0 = np.hypot(p.u, p.v).max(), kinetic_energy(p)
    for _ in range(150):
        model.step()
    return model, merges, speed0, energy0


def test_split_then_merge_in_still_water_stays_a_still_pond(pond_after_split_and_merge):
    """The disturbance of split + merge decays instead of growing; depth stays within 2.5 %
    (measured 1.7 %; 1.3-1.8 % over 400 s; at kappa 1.3, 1.5 % and 1.3-2.4 %)."""
    model, merges, speed0, energy0 = pond_after_split_and_merge
    p = model.particles
    assert merges > 40
    assert np.hypot(p.u, p.v).max() < speed0
    assert kinetic_energy(p) < 0.75 * energy0
    assert np.all(np.abs(model.depth() - 1.0) < 0.025)


@pytest.mark.xfail(strict=True, reason="measured 7-10 cm/s just after split + merge in a 1 m "
                   "deep pond (1 m spacing), decaying slowly (3-5 cm/s after 20 s): the hexagon "
                   "pattern is not an SPH equilibrium and nothing but the stabilisation damps "
                   "the relaxation")
def test_split_then_merge_in_still_water_no_spurious_velocity_above_1mm_s(
        pond_after_split_and_merge):
    model = pond_after_split_and_merge[0]
    assert np.hypot(model.particles.u, model.particles.v).max() < 1e-3


# -- in a run ------------------------------------------------------------------------------------
def test_splitting_improves_a_coarse_dam_break():
    plain = cases.ritter(20.0)
    r = cases.ritter(20.0, refinement=Refinement.SPLIT_COALESCE)
    assert r.splits > 0
    assert r.particles_max >= 250 + 6 * r.splits - 7 * r.merges
    assert r.mass_error_rel < 1e-12
    assert r.l1 < 0.75 * plain.l1
    assert abs(r.front_error_m) < abs(plain.front_error_m)


def test_the_thin_front_of_a_refined_dam_break_keeps_below_the_riemann_bound():
    """Ritter at 5 m spacing with splitting and coalescing, 40 s: no particle may run much
    faster than the front's exact speed 2 sqrt(g d0) = 19.8 m/s (the Riemann invariant
    u + 2 sqrt(g d) is 2 sqrt(g d0) throughout the exact solution). Before edge particles
    were exempt from the smoothing relaxation and h was held in the density solve, the
    fastest particle reached 26 m/s (t = 22 s); with the exemption alone, a particle whose
    solve collapsed beside a heavy merged neighbour at a side wall reached 38 m/s."""
    from floodsph.constants import GRAVITY

    model = cases._lattice_model(flat, (0, 2000), (0, 100), 10.0,
                                 lambda x, y: np.where(x < 1000, 10.0, 0.0), 5.0, 1.3,
                                 refinement=Refinement.SPLIT_COALESCE)
    fastest = 0.0
    while model.t < 40.0 - 1e-9:
        model.step(40.0 - model.t)
        fastest = max(fastest, np.hypot(model.particles.u, model.particles.v).max())
    assert model.state.counters["splits"] > 0 and model.state.counters["merges"] > 0
    assert fastest < 1.12 * 2.0 * math.sqrt(GRAVITY * 10.0)


@pytest.mark.slow
def test_refined_dam_break_matches_the_fine_uniform_run_at_a_third_of_the_cost():
    """Coarse 10 m start with one level of splitting against a uniform run at the daughters'
    mass-equivalent spacing 10 / sqrt(7) m: L1 0.88 % against 0.66 %. At that spacing the
    channel's north wall lies 3.6 m beyond the last lattice row, not half a spacing; before its
    seeds were settled (``floodsph.walls.seeding``) the uniform run's L1 was 1.83 %."""
    fine = cases.ritter(10.0 / math.sqrt(7.0))
    r = cases.ritter(10.0, refinement=Refinement.SPLIT_COALESCE, refine_max_level=1)
    assert r.splits > 0 and r.mass_error_rel < 1e-12
    assert r.l1 <= 1.4 * fine.l1
    assert r.particle_steps <= fine.particle_steps / 3


def test_split_daughters_relax_to_sqrt3_lattice_smoothing_and_lattice_particles_stay():
    from floodsph.model.refinement import RELAX_RATE, relax_smoothing

    model = model_on(flat, (0, 24), (0, 24), 1.0, 1.0, 1.0)
    p = model.particles
    h0_lattice = p.h0[0]
    assert np.all(p.h0 == h0_lattice)
    kappa = model.numerics.kappa
    split_only().execute(*on(model), np.flatnonzero(np.hypot(p.x - 12.0, p.y - 12.0) < 3.0), [], [])
    daughters = p.level > 0
    c0 = p.h0**2 * p.rho0
    target = SMOOTHING_EXCESS * kappa**2 * p.m
    assert np.all(c0[daughters] > 1.5 * target[daughters])  # 0.9 h_p with a seventh of m_p
    relax_smoothing(p, kappa)
    c1 = p.h0**2 * p.rho0
    np.testing.assert_allclose(c1[daughters],
                               c0[daughters] * (target[daughters] / c0[daughters]) ** RELAX_RATE,
                               rtol=1e-12)
    assert np.all(p.h0[~daughters] == h0_lattice)
    edge = np.flatnonzero(daughters)[:3]  # as if their kernel support were short of water
    p.alpha[edge] = 0.7 * 2.0 * p.rho[edge]
    c_edge = p.h0[edge] ** 2 * p.rho0[edge]
    relax_smoothing(p, kappa)
    np.testing.assert_array_equal(p.h0[edge] ** 2 * p.rho0[edge], c_edge)
    p.alpha[edge] = 2.0 * p.rho[edge]
    for _ in range(60):
        relax_smoothing(p, kappa)
    np.testing.assert_allclose(p.h0**2 * p.rho0 / target, np.where(daughters, 1.0, 1 / 3),
                               rtol=1e-5)


def test_a_parent_passes_on_at_most_its_relaxed_smoothing():
    """Daughters take 0.9 h_p, with h_p at most the relaxed sqrt(3) kappa sqrt(m_p / rho_p):
    an unrelaxed edge parent does not hand its inflated h down a generation."""
    model = model_on(flat, (0, 24), (0, 24), 1.0, 1.0, 1.0)
    p = model.particles
    kappa = model.numerics.kappa
    centre = np.flatnonzero(np.hypot(p.x - 12.0, p.y - 12.0) < 1.0)
    inflated, plain = centre[:2], centre[2:4]
    p.h[inflated] *= 3.0
    relaxed = math.sqrt(SMOOTHING_EXCESS) * kappa * np.sqrt(p.m / p.rho)
    expect = refine.H_FACTOR * np.concatenate([relaxed[inflated], p.h[plain]])
    n0 = p.n - 4
    split_only().execute(*on(model), np.concatenate([inflated, plain]), [], [])
    born_h = p.h[n0:].reshape(4, refine.DAUGHTERS)
    np.testing.assert_allclose(born_h, np.repeat(expect[:, None], refine.DAUGHTERS, axis=1),
                               rtol=1e-12)


def test_the_refiner_relaxes_and_bounds_smoothing_to_its_own_smoothing_excess():
    """Numerics.refine_smoothing_excess (here 2, default 3) sets both the h a parent passes on,
    0.9 min(h_p, sqrt(2) kappa sqrt(m_p / rho_p)), and the daughters' relaxed h^2 rho."""
    model = model_on(flat, (0, 24), (0, 24), 1.0, 1.0, 1.0)
    p = model.particles
    kappa = model.numerics.kappa
    centre = np.flatnonzero(np.hypot(p.x - 12.0, p.y - 12.0) < 1.0)
    p.h[centre] *= 3.0
    bound = math.sqrt(2.0) * kappa * np.sqrt(p.m[centre] / p.rho[centre])
    n0 = p.n - centre.size
    refiner = split_only(refine_smoothing_excess=2.0)
    refiner.execute(*on(model), centre, [], [])
    np.testing.assert_allclose(p.h[n0:].reshape(-1, refine.DAUGHTERS),
                               np.repeat(refine.H_FACTOR * bound[:, None], refine.DAUGHTERS,
                                         axis=1), rtol=1e-12)
    daughters = p.level > 0
    relaxer = split_only(refine_area_max=1e9, refine_smoothing_excess=2.0)  # no further splits
    for step in range(1, 61):
        model.state.steps = step  # Refiner.apply relaxes once per model step
        assert relaxer.apply(*on(model)) == (0, 0)
    c = p.h0**2 * p.rho0 / (kappa**2 * p.m)
    np.testing.assert_allclose(c[daughters], 2.0, rtol=1e-5)


def test_a_smoothing_excess_below_the_lattice_value_is_refused():
    with pytest.raises(InputError, match="numerics.refine_smoothing_excess: must be >= 1, "
                                         "got 0.9"):
        Numerics(refine_smoothing_excess=0.9)


def test_a_small_particle_beside_a_large_one_still_finds_its_merge_partner():
    x = np.array([0.0, 1.0, 0.3])  # 0's nearest neighbour is 2, a large non-candidate
    y = np.zeros(3)
    nstart = np.array([0, 2, 4, 6])
    nbr = np.array([1, 2, 0, 2, 0, 1])
    out = np.full(3, -1, dtype=np.int64)
    refine.nearest_of(np.array([0, 1]), x, y, nstart, nbr, np.array([True, True, False]), out)
    assert out.tolist() == [1, 0, -1]
