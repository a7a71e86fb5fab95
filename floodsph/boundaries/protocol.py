"""The contract every open boundary keeps with the model's stages (``floodsph.model.stages``).

A boundary does not see the model. It takes part in a step through three calls, in this
order, each given what it may read and change:

1. ``apply(water, site, dt)`` after the drift: inject or remove water, changing
   ``water.particles`` and adding what it injects to ``water.volume_in`` and what it
   removes to ``water.volume_out`` [m3]. ``water`` is the run's state (:class:`Water`, kept
   by ``floodsph.model.state.State``: the particles, the clock ``t`` [s] at the start of the
   step, the step count ``steps``, the volumes); ``site`` (:class:`Site`) the terrain, the
   settings it reads and the flux lines' counter of moved water;
2. ``add_ghosts(particles)`` before the neighbour search: append the step's ghost particles
   (inflow buffer layers, mirror images beyond open edges) behind the water;
3. ``impose(particles, lists)`` after the density solve: set the ghosts' density, smoothing
   length and velocity to the boundary state, so that the forces on the water see it
   (``lists``: the neighbour lists of water and ghosts, ``floodsph.sph.neighbours``).

The stages drop the ghosts after the forces, so between steps the particle set holds water
only. Besides:

* ``protected(x, y)``: True for points in the boundary's zone of influence (no coalescing and
  no wall-seed settling there; local time stepping gives them the finest step);
* ``max_dt(cfl)``: the longest stable step [s] the boundary allows (``math.inf`` if none);
* ``opening``: the (2, 2) section [m, local] that walls along it are cut open for, or None;
* ``STATE``: a class-level tuple naming the attributes that change during a run.

State and checkpoints. A checkpoint (``floodsph.simulation.checkpoint``) does not store the
boundary object: on resume the boundaries are made again from the scenario, in the same order,
and each one's ``STATE`` attributes are set from the checkpoint
(``floodsph.simulation.state_arrays``). A new boundary therefore only declares them, e.g.

    class Gate:
        STATE = ("opening_fraction", "volume_out")

Their values are numpy arrays, numbers, dicts of these (stored under ``name.key``), or small
JSON-able values (str, None, lists). Everything else about the boundary -- its geometry, its
hydrograph, the settings -- must follow from its constructor's arguments. List every
attribute that ``apply``, ``add_ghosts`` or ``impose`` changes and a later step reads; the
ghosts' slice, rebuilt by ``add_ghosts`` each step, is not state. A boundary whose attributes
never change declares ``STATE = ()``. The checkpoint names a value
``model.boundaries.<i>.<attribute>``, ``i`` its place in ``model.boundaries``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np


class Water(Protocol):
    """What a boundary reads and changes of the run's state (``floodsph.model.state.State``)."""

    particles: Any
    """The particle set (``floodsph.model.particles.ParticleSet``)."""
    t: float
    """The time [s] at the start of the step."""
    steps: int
    """The finest steps taken (a new particle's ``born``)."""
    volume_in: float
    """Water that entered the domain [m3]."""
    volume_out: float
    """Water that left the domain [m3]."""


@dataclass(frozen=True)
class Site:
    """What a boundary reads of the model besides the water: the terrain
    (``floodsph.model.terrain.Terrain``), the neighbour lists' skin (a fraction of 2 h), the
    momentum (``balanced``: depth is d + the level offset, ``floodsph.sph.level_offsets``),
    and ``count_moves(x0, y0, x1, y1, m)``, to be called for water of mass m [kg] that a
    boundary moves from (x0, y0) to (x1, y1) [m] (the flux lines', None without them)."""

    terrain: Any
    neighbour_skin: float
    balanced: bool
    count_moves: Callable[..., None] | None = None


class Boundary(Protocol):
    """An open boundary of the model (module docstring)."""

    @property
    def STATE(self) -> tuple[str, ...]: ...  # noqa: N802  # a class-level tuple in each boundary

    @property
    def opening(self) -> np.ndarray | None: ...

    def apply(self, water: Water, site: Site, dt: float) -> None: ...

    def add_ghosts(self, particles) -> None: ...

    def impose(self, particles, lists) -> None: ...

    def protected(self, x: np.ndarray, y: np.ndarray) -> np.ndarray: ...

    def max_dt(self, cfl: float) -> float: ...
