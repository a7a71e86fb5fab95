"""The model's parts (``floodsph.model.domain``, ``state``, ``workspace``) and the narrow
contract that boundaries keep with them (``floodsph.boundaries.protocol``)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from sph_cases import lattice, particles_with_depth

from floodsph.boundaries.open_edges import SIDES
from floodsph.constants import RHO_WATER
from floodsph.model.builder import set_up_model
from floodsph.model.state import State
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Numerics

DX = 5.0


class Drain:
    """A boundary written to the protocol alone: it removes the water east of ``x_drain`` [m]
    and counts it as outflow, through the water it is given (no model)."""

    STATE = ("volume_out",)
    opening = None

    def __init__(self, x_drain: float):
        self.x_drain = x_drain
        self.volume_out = 0.0
        self.cell_sizes: list[float] = []

    def apply(self, water, site, dt: float) -> None:
        self.cell_sizes.append(site.terrain.dx)
        p = water.particles
        gone = p.x > self.x_drain
        volume = float(p.m[gone].sum()) / RHO_WATER
        self.volume_out += volume
        water.volume_out += volume
        p.keep(~gone)

    def add_ghosts(self, particles) -> None:
        """No ghosts."""

    def impose(self, particles, lists) -> None:
        """No state to impose."""

    def protected(self, x, y) -> np.ndarray:
        return np.zeros(x.shape, dtype=bool)

    def max_dt(self, cfl: float) -> float:
        return math.inf


def _lake():
    """A 2 m lake on a flat 100 x 50 m bed."""
    terrain = Terrain.from_function(lambda x, y: 0.0 * x, (0.0, 100.0), (0.0, 50.0), DX)
    x, y = lattice(0.0, 100.0, 0.0, 50.0, DX)
    return terrain, particles_with_depth(x, y, np.full(x.shape, 2.0), DX, 1.3)


def test_a_boundary_of_the_protocol_alone_drains_water_and_the_volume_adds_up():
    """The drain takes the water east of x = 80 m at the set-up and in the steps; what it
    counts is the state's outflow, and what stays plus what left is what was seeded."""
    terrain, p = _lake()
    seeded = p.volume()
    drain = Drain(80.0)
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=DX), closed_sides=SIDES,
                         boundaries=[drain])
    at_set_up = drain.volume_out
    assert at_set_up == pytest.approx(4 * 10 * 2.0 * DX * DX, rel=1e-12)  # 4 columns of 10
    for _ in range(3):
        model.step()
    assert drain.volume_out > at_set_up  # the lake flows into the gap and drains on
    assert model.state.volume_out == drain.volume_out
    assert model.volume() + model.state.volume_out == pytest.approx(seeded, rel=1e-12)
    # the set-up's call and one per finest step (local steps: 2^K per big step), on this terrain
    assert drain.cell_sizes == [DX] * (1 + model.steps) and model.steps > 3


def test_a_checkpoint_keeps_every_field_of_the_state():
    """Every field of the State but the particles (which declare their own) is named in its
    ``STATE``, so a new field cannot be left out of the checkpoints."""
    names = {field.name for field in dataclasses.fields(State)}
    assert names - {"particles"} == set(State.STATE)


def test_the_domain_and_the_model_conveniences_cannot_be_changed():
    terrain, p = _lake()
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=DX))
    with pytest.raises(dataclasses.FrozenInstanceError):
        model.domain.seg = np.zeros((0, 4))  # type: ignore[misc]
    with pytest.raises(AttributeError):
        model.t = 1.0  # type: ignore[misc]
    assert model.domain.h0 == pytest.approx(model.numerics.kappa * DX)  # h0 = kappa dx
