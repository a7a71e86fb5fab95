"""Open boundaries: inflow sections, open DEM edges, sinks, weirs over crest walls and
imposed levels.

Each keeps the contract of ``floodsph.boundaries.protocol.Boundary`` with the model.
"""

from floodsph.boundaries.inflow import Inflow
from floodsph.boundaries.level import LevelBoundary
from floodsph.boundaries.open_edges import OpenEdges
from floodsph.boundaries.sink import Sink
from floodsph.boundaries.weir import Weir

__all__ = ["Inflow", "LevelBoundary", "OpenEdges", "Sink", "Weir"]
