"""Small builders of SPH test cases on analytic beds (shared by the core tests)."""

from __future__ import annotations

import numpy as np

from floodsph.boundaries.open_edges import SIDES
from floodsph.inputs.initial_water import particles_at
from floodsph.model.builder import set_up_model
from floodsph.model.particles import ParticleSet
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Numerics, TimeStepping


def lattice(x0, x1, y0, y1, dx):
    """Cell-centred square lattice covering [x0, x1] x [y0, y1]."""
    X, Y = np.meshgrid(np.arange(x0 + dx / 2, x1, dx), np.arange(y0 + dx / 2, y1, dx))
    return X.ravel(), Y.ravel()


def particles_with_depth(x, y, d, dx, kappa, u=0.0, v=0.0) -> ParticleSet:
    """Particles of volume d dx^2 at (x, y) where d > 0
    (``floodsph.inputs.initial_water.particles_at``)."""
    return particles_at(x, y, d, dx, kappa, u=u, v=v)


def model_on(bed, xlim, ylim, cell, level_or_depth, dx, kappa=Numerics.kappa, manning=0.0,
             walls=(), closed_sides=SIDES, **numerics):
    """A FloodModel with water given as a level (float) or a depth function d(x, y), seeded at
    rest at its level d + b (its ``eta_seed``), as a scenario's ``[[initial_water]]`` seeds it.

    ``numerics``: fields of its ``Numerics``; ``time_stepping`` defaults to the global step,
    whose facts (exact momentum, one step per call) these cases assert; a test of local
    steps asks for them."""
    terrain = Terrain.from_function(bed, xlim, ylim, cell, manning=manning)
    x, y = lattice(0.0, terrain.width, 0.0, terrain.height, dx)
    xw, yw = x + terrain.x0, y + terrain.y0
    b = bed(xw, yw)
    if callable(level_or_depth):
        d = np.asarray(level_or_depth(xw, yw), dtype=float)
    else:
        d = np.maximum(level_or_depth - b, 0.0)
    p = particles_at(x, y, d, dx, kappa, eta_seed=d + b)
    num = Numerics(particle_spacing_m=dx, kappa=kappa,
                   **{"time_stepping": TimeStepping.GLOBAL, **numerics})
    return set_up_model(terrain, p, num, walls=walls, closed_sides=closed_sides)


def run_until(model, t_end):
    while model.t < t_end - 1e-9:
        model.step(t_end - model.t)
    return model
