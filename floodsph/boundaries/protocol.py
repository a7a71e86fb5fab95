"""The contract every open boundary keeps with ``floodsph.model.flood_model.FloodModel``.

A boundary takes part in a step through three calls, in this order:

1. ``apply(model, dt)`` after the drift: inject or remove water, adding what it injects to
   ``model.volume_in`` and what it removes to ``model.volume_out`` [m3];
2. ``add_ghosts(model)`` before the neighbour search: append the step's ghost particles
   (inflow buffer layers, mirror images beyond open edges) behind the water;
3. ``impose(model)`` after the density solve: set the ghosts' density, smoothing length and
   velocity to the boundary state, so that the forces on the water see it.

The model drops the ghosts after the forces, so between steps the particle set holds water
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

from typing import Protocol

import numpy as np


class Boundary(Protocol):
    """An open boundary of the model (module docstring)."""

    @property
    def STATE(self) -> tuple[str, ...]: ...  # noqa: N802  # a class-level tuple in each boundary

    @property
    def opening(self) -> np.ndarray | None: ...

    def apply(self, model, dt: float) -> None: ...

    def add_ghosts(self, model) -> None: ...

    def impose(self, model) -> None: ...

    def protected(self, x: np.ndarray, y: np.ndarray) -> np.ndarray: ...

    def max_dt(self, cfl: float) -> float: ...
