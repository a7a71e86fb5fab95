"""Depth from density: uniform lattices, walls and corners, Newton-Raphson convergence."""

import numpy as np
import pytest
from sph_cases import lattice, model_on, particles_with_depth

from floodsph.model import list_stages
from floodsph.model.builder import set_up_model
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Numerics
from floodsph.sph import density


def solve(model, **kwargs):
    """``density.solve_density`` on the model's particles, lists and walls."""
    return density.solve_density(model.particles, model.work.nl, model.state.blocked,
                                 list_stages.wall_lists(model.domain, model.state, model.work),
                                 **kwargs)


def summation(model, i):
    """(rho_i, alpha_i) of the density summation at particle i's current h."""
    p = model.particles
    return density.summation(i, p.h[i], p.x, p.y, p.m, model.work.nl.start, model.work.nl.nbr,
                             model.state.blocked,
                             list_stages.wall_lists(model.domain, model.state, model.work))


def test_uniform_lattice_in_closed_box_gives_exact_depth_everywhere():
    """Mirror images (walls and corners) complete the kernel: exact depth up to the walls."""
    model = model_on(lambda x, y: 0 * x, (0, 200), (0, 150), 10.0, 2.0, 5.0)
    d = model.depth()
    assert np.abs(d - 2.0).max() < 2e-3  # Newton tolerance 1e-3 on rho
    p = model.particles
    assert np.allclose(p.alpha, 2.0 * p.rho, rtol=2e-2)  # alpha = d_m rho, up to the lattice sum


def test_newton_converges_in_few_iterations_from_a_perturbed_guess():
    terrain = Terrain.from_function(lambda x, y: 0 * x, (0, 100), (0, 100), 10.0)
    x, y = lattice(0, 100, 0, 100, 2.0)
    p = particles_with_depth(x, y, np.full(x.size, 3.0), 2.0, 1.3)
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=2.0, kappa=1.3))
    p.rho[:] *= 1.05  # a guess 5 % off, as after a long step
    p.h[:] = p.h0 * np.sqrt(p.rho0 / p.rho)
    iters, bad, _, _ = solve(model, tol=1e-6)
    assert bad == 0
    assert iters <= 5
    # the self-consistent lattice depth differs from 3 m only by the lattice-sum error
    assert np.abs(p.rho / 3000.0 - 1).max() < 1e-4


def test_isolated_particle_has_bounded_h():
    terrain = Terrain.from_function(lambda x, y: 0 * x, (0, 1000), (0, 1000), 10.0)
    p = particles_with_depth(np.array([500.0]), np.array([500.0]), np.array([1.0]), 5.0, 1.3)
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=5.0, kappa=1.3, h_ratio=4.0))
    assert model.particles.h[0] == pytest.approx(4.0 * 6.5)
    assert np.isfinite(model.particles.rho[0]) and model.particles.rho[0] > 0
    # no neighbour in its support (alpha = 0): the uncorrected force, no NaN in div v
    assert model.particles.alpha[0] == 0.0
    model.step()
    p = model.particles
    assert p.ax[0] == p.ay[0] == p.divv[0] == 0.0 and p.u[0] == p.v[0] == 0.0


def test_isolated_particle_left_compressed_spreads_again():
    """A lone particle thrown out of the water with h at its lower bound h0 / h_ratio and the
    self-term density there (the state a plain summation leaves): its solve starts from the h
    of its density, so h grows back (to the upper bound: a lone particle is a spreading film)
    instead of keeping the tenfold-short h, and with it a tenfold-short time step."""
    from floodsph.sph.kernels import SIGMA_2D

    terrain = Terrain.from_function(lambda x, y: 0 * x, (0, 1000), (0, 1000), 10.0)
    p = particles_with_depth(np.array([500.0]), np.array([500.0]), np.array([1.0]), 5.0, 1.3)
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=5.0, kappa=1.3, h_ratio=10.0))
    p.h[0] = p.h0[0] / 10.0
    p.rho[0] = p.m[0] * SIGMA_2D / p.h[0] ** 2
    dt0 = model.stable_dt()
    for _ in range(10):
        model.step()
    assert p.h[0] == pytest.approx(10.0 * p.h0[0])
    assert p.rho[0] == pytest.approx(p.m[0] * SIGMA_2D / p.h[0] ** 2, rel=1e-12)
    assert model.stable_dt() > 20.0 * dt0


def test_capped_solve_keeps_the_lists_valid_and_catches_up_after_a_rebuild():
    """A guess far too dense (h 30 % short, as at a thin edge whose solve jumps): the capped
    solve stops that particle at the largest h its list holds, with the summation there, and
    the lists stay valid; lists rebuilt around it let the next solve reach the lattice depth."""
    terrain = Terrain.from_function(lambda x, y: 0 * x, (0, 100), (0, 100), 10.0)
    x, y = lattice(0, 100, 0, 100, 2.0)
    p = particles_with_depth(x, y, np.full(x.size, 3.0), 2.0, 1.3)
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=2.0, kappa=1.3))
    i = p.n // 2 + 25
    p.rho[i] *= 1.0 / 0.7**2
    p.h[i] *= 0.7
    list_stages.update_lists(model.domain, model.state, model.work, force=True)
    list_stages.block_pairs(model.domain, model.state, model.work)
    cap = model.work.nl.h_cap(p.x, p.y)[i]
    _, bad, capped, _ = solve(model, cap=True)
    assert capped == 1 and bad == 0
    assert p.h[i] == pytest.approx(cap) and p.h[i] < 0.8 * p.h0[i]
    assert model.work.nl.still_valid(p.x, p.y, p.h)
    rho_at_cap, _ = summation(model, i)
    assert p.rho[i] == pytest.approx(rho_at_cap, rel=1e-12)
    for _ in range(5):
        list_stages.update_lists(model.domain, model.state, model.work, force=True)
        list_stages.block_pairs(model.domain, model.state, model.work)
        solve(model, cap=True)
    assert p.rho[i] / 3000.0 == pytest.approx(1.0, abs=2e-3)


def test_a_heavy_neighbour_brought_close_does_not_collapse_h_in_a_time_step():
    """A particle ten times heavier (a merged one, say) lands 0.3 m from particle i of 0.5 m
    still water at 5 m spacing. Equations (1)-(2) then have a second root at a tiny h, where
    that neighbour's W(r, h) is near its peak (d_i about 110 m at h = h0 / 10). In a time step
    the solve holds h_i at H_SHRINK_MIN times its guess and takes the summation there: the
    depth of the root continuous with the old state (the neighbour adds about 2 m)."""
    terrain = Terrain.from_function(lambda x, y: 0 * x, (0, 100), (0, 100), 10.0)
    x, y = lattice(0, 100, 0, 100, 5.0)
    p = particles_with_depth(x, y, np.full(x.size, 0.5), 5.0, 1.3)
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=5.0, kappa=1.3))
    i = int(np.argmin(np.hypot(p.x - 52.5, p.y - 52.5)))
    j = int(np.argmin(np.hypot(p.x - 57.5, p.y - 52.5)))
    h_guess = p.h[i]
    p.x[j] = p.x[i] + 0.05 * h_guess
    p.y[j] = p.y[i]
    p.m[j] *= 10.0
    list_stages.update_lists(model.domain, model.state, model.work, force=True)
    list_stages.block_pairs(model.domain, model.state, model.work)
    _, bad, capped, held = solve(model, cap=True)
    assert bad == 0 and capped == 0 and held >= 1
    assert p.h[i] == pytest.approx(density.H_SHRINK_MIN * h_guess, rel=1e-12)
    rho_there, _ = summation(model, i)
    assert p.rho[i] == pytest.approx(rho_there, rel=1e-12)
    assert 2.0 < p.rho[i] / 1000.0 < 3.0
