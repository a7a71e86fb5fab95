"""Open boundaries: inflow sections, open DEM edges and sinks.

Each keeps the contract of ``floodsph.boundaries.protocol.Boundary`` with the model.
"""

from floodsph.boundaries.inflow import Inflow
from floodsph.boundaries.open_edges import OpenEdges
from floodsph.boundaries.sink import Sink

__all__ = ["Inflow", "OpenEdges", "Sink"]
