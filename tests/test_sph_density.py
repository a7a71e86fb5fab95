"""Depth from density: uniform lattices, walls and corners, Newton-Raphson convergence."""

import numpy as np
import pytest
from sph_cases import lattice, model_on, particles_with_depth

from floodsph.model import FloodModel, Numerics
from floodsph.sph import density
from floodsph.terrain import Terrain


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
    model = FloodModel(terrain, p, Numerics(spacing=2.0, kappa=1.3))
    p.rho[:] *= 1.05  # a guess 5 % off, as after a long step
    p.h[:] = p.h0 * np.sqrt(p.rho0 / p.rho)
    iters, bad = density.solve_density(p, model.nl, model.blocked, model.walls_near, model.seg,
                                       tol=1e-6)
    assert bad == 0
    assert iters <= 5
    # the self-consistent lattice depth differs from 3 m only by the lattice-sum error
    assert np.abs(p.rho / 3000.0 - 1).max() < 1e-4


def test_isolated_particle_has_bounded_h():
    terrain = Terrain.from_function(lambda x, y: 0 * x, (0, 1000), (0, 1000), 10.0)
    p = particles_with_depth(np.array([500.0]), np.array([500.0]), np.array([1.0]), 5.0, 1.3)
    model = FloodModel(terrain, p, Numerics(spacing=5.0, kappa=1.3, h_ratio=4.0))
    assert model.particles.h[0] == pytest.approx(4.0 * 6.5)
    assert np.isfinite(model.particles.rho[0]) and model.particles.rho[0] > 0
