"""Domain: what a run fixes at its set-up and never changes (terrain, settings, walls).

A :class:`Domain` is made once by ``floodsph.model.builder.set_up_model`` and read by every
stage (``floodsph.model.stages``); nothing in it changes while the run goes, so a checkpoint
stores none of it: a resumed run makes it again from the scenario. The open boundaries (the
open sides' edges, inflows, sinks, levels, weirs) change as the run goes and are kept beside
it by the model (``FloodModel.boundaries``); the domain holds the sides they leave closed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Momentum, Numerics, Stabilisation, WallModel
from floodsph.sph import forces, kernels
from floodsph.walls.index import MapWalls, WallIndex
from floodsph.walls.sight import SIGHT_SLACK


@dataclass(frozen=True, eq=False)
class Domain:
    """The fixed part of a model (module docstring).

    Attributes
    ----------
    terrain : Terrain
    numerics : Numerics
        The solver's settings (``floodsph.scenario.numerics``), with ``particle_spacing_m``
        given.
    seg : (k, 4) array
        Wall segments (x0, y0, x1, y1) [m] that water cannot cross
        (``floodsph.model.wall_layout.model_segments``).
    closed_sides : frozenset of str
        The closed sides of the DEM rectangle; with any closed, the nodata border is a wall
        too.
    held : (ny, nx) uint8 array
        The DEM cells that held water at seeding, and the nodata cells: the balanced
        momentum's still water does not take them for dry land beyond a free edge
        (``floodsph.sph.level_momentum``).
    h0 : float
        The seeded smoothing length h0 = kappa dx [m] (``floodsph.sph.kernels``).
    wall_index : WallIndex
        The near-wall index of ``seg``, in buckets of 2 h0.
    scheme : int
        The force kernel's shock capturing (``floodsph.sph.forces``: LAX_FRIEDRICHS, RIEMANN
        or MUSCL).
    shores : bool
        Whether the bed has relief (a flat bed has no shore to balance).
    balanced : bool
        The balanced momentum (``Momentum.BALANCED``) rather than the variational one.
    integral_walls : bool
        Walls by their boundary integral (``WallModel.INTEGRAL``) rather than by images.
    """

    terrain: Terrain
    numerics: Numerics
    seg: np.ndarray
    closed_sides: frozenset[str]
    held: np.ndarray
    h0: float
    wall_index: WallIndex
    scheme: int
    shores: bool
    balanced: bool
    integral_walls: bool

    @classmethod
    def build(cls, terrain: Terrain, numerics: Numerics, seg: np.ndarray,
              closed_sides: frozenset[str], held: np.ndarray | None = None) -> Domain:
        """The domain of these set-up results; ``held``: the DEM cells that held water at
        seeding (None: the nodata cells only)."""
        h0 = kernels.seeded_smoothing_length(numerics.kappa, numerics.particle_spacing_m)
        return cls(
            terrain=terrain,
            numerics=numerics,
            seg=seg,
            closed_sides=closed_sides,
            held=np.ascontiguousarray(~terrain.valid if held is None else held | ~terrain.valid,
                                      dtype=np.uint8),
            h0=h0,
            wall_index=WallIndex(seg, (0.0, 0.0, terrain.width, terrain.height),
                                 bucket=2.0 * h0),
            scheme={Stabilisation.LAX_FRIEDRICHS: forces.LAX_FRIEDRICHS,
                    Stabilisation.RIEMANN: forces.RIEMANN,
                    Stabilisation.MUSCL: forces.MUSCL}[numerics.stabilisation],
            shores=bool(np.ptp(terrain.elevation) > 0.0),
            balanced=numerics.momentum is Momentum.BALANCED,
            integral_walls=numerics.wall_model is WallModel.INTEGRAL,
        )

    def map_walls(self, x: np.ndarray, y: np.ndarray, h: np.ndarray) -> MapWalls:
        """The walls as the maps see them (``floodsph.output.rasterise``): each particle's
        segments within its support 2 h_i (and the sight test's slack)."""
        near = self.wall_index.near_lists(x, y, h + SIGHT_SLACK,
                                          np.zeros(x.shape[0] + 1, dtype=np.int64),
                                          np.zeros(0, dtype=np.int64), 2.0)
        return MapWalls(self.seg, near.wstart, near.wseg)
