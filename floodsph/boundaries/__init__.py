"""Open boundaries: inflow sections, open DEM edges and sinks.

Each boundary takes part in ``FloodModel.step`` through three calls (see ``floodsph.model``):

- ``apply(model, dt)`` after the drift: inject or remove water, counting it in
  ``model.volume_in`` / ``model.volume_out``;
- ``add_ghosts(model)`` before the neighbour search: append the step's ghost particles
  (inflow buffer layers, mirror images beyond open edges) behind the fluid particles;
- ``impose(model)`` after the density solve: set the ghosts' density, smoothing length and
  velocity to the boundary state, so that the forces on the fluid see it.

The model drops the ghosts after the force evaluation, so between steps the particle set holds
water only. ``protected(x, y)`` marks particles in a boundary's zone of influence (no
coalescing there).
"""

from floodsph.boundaries.inflow import Inflow
from floodsph.boundaries.open_edges import OpenEdges
from floodsph.boundaries.sink import Sink

__all__ = ["Inflow", "OpenEdges", "Sink"]
