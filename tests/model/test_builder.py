"""The model's set-up (``floodsph.model.builder.set_up_model``): open sides, its checks, and
the water it removes before the first step, counted as outflow."""

from __future__ import annotations

import numpy as np
import pytest
from sph_cases import lattice, particles_with_depth

from floodsph.boundaries.open_edges import SIDES, OpenEdges
from floodsph.model.builder import set_up_model
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Numerics

DX = 5.0


def _lake(extra_x=()):
    """A 2 m lake on a flat 100 x 50 m bed, with extra seeds at x = ``extra_x`` (y = 25 m)."""
    terrain = Terrain.from_function(lambda x, y: 0.0 * x, (0.0, 100.0), (0.0, 50.0), DX)
    x, y = lattice(0.0, 100.0, 0.0, 50.0, DX)
    x = np.concatenate([x, np.asarray(extra_x, dtype=float)])
    y = np.concatenate([y, np.full(len(extra_x), 25.0)])
    return terrain, particles_with_depth(x, y, np.full(x.shape, 2.0), DX, 1.3)


def test_the_open_sides_get_transmissive_ghosts_ahead_of_the_other_boundaries():
    terrain, p = _lake()
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=DX), closed_sides=("west",))
    assert isinstance(model.boundaries[0], OpenEdges)
    assert sorted(model.boundaries[0].sides) == ["east", "north", "south"]
    closed = set_up_model(*_lake(), Numerics(particle_spacing_m=DX), closed_sides=SIDES)
    assert not any(isinstance(b, OpenEdges) for b in closed.boundaries)


def test_seeds_off_the_grid_leave_as_outflow_and_the_volume_adds_up():
    """Two seeds beyond the east border (x = 110, 130 m) are removed at the set-up; their
    volume is the model's ``volume_out``, and what stays plus what left is what was seeded."""
    terrain, p = _lake(extra_x=(110.0, 130.0))
    seeded = p.volume()
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=DX), closed_sides=())
    assert model.state.volume_out == pytest.approx(2 * 2.0 * DX * DX, rel=1e-12)
    assert model.volume() + model.state.volume_out == pytest.approx(seeded, rel=1e-12)
    assert model.particles.x.max() < terrain.width


def test_bad_set_up_arguments_are_refused_by_name():
    terrain, p = _lake()
    with pytest.raises(ValueError, match=r"closed_sides: unknown sides \['up'\]"):
        set_up_model(terrain, p, Numerics(particle_spacing_m=DX), closed_sides=("up",))
    with pytest.raises(ValueError, match="particle_spacing_m must be given"):
        set_up_model(terrain, p, Numerics())
