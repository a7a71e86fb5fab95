"""The model's wall segments: the user's walls, the closed sides of the DEM and the nodata
border, in one array.

Inflow sections are cut out of them (``floodsph.walls.openings``), and segments are split where
another's end lies on them (``floodsph.walls.junctions``), so that the mirror images and the
sight tests see each junction as a shared vertex.
"""

from __future__ import annotations

from collections.abc import Set as AbstractSet

import numpy as np

from floodsph.boundaries.open_edges import SIDES
from floodsph.model.terrain import Terrain
from floodsph.walls.geometry import segments_from_polylines
from floodsph.walls.junctions import split_at_junctions
from floodsph.walls.nodata import nodata_polylines
from floodsph.walls.openings import cut_openings

SIDE_EXTENSION_H = 6.0
"""How far [h0] a closed side runs on beyond an open side it meets (:func:`side_segments`)."""


def model_segments(terrain: Terrain, walls, closed: AbstractSet[str], nodata_walled: bool, openings,
                   h0: float, spacing: float) -> np.ndarray:
    """All wall segments (ns, 4) [m, local] of a model.

    ``walls``: the user's polylines; ``closed``: the closed DEM sides; ``nodata_walled``: the
    nodata border is a wall (edges not all open); ``openings``: the inflow sections ((2, 2)
    arrays) cut out of the walls; ``h0`` the seeded smoothing length and ``spacing`` the
    particle spacing [m] (the cut and junction tolerance is 1e-6 spacing).
    """
    segs = [segments_from_polylines(walls),
            side_segments(terrain, closed, extension=SIDE_EXTENSION_H * h0)]
    if nodata_walled:
        segs.append(segments_from_polylines(
            nodata_polylines(terrain.valid, terrain.dx, terrain.dy, openings)))
    tol = 1e-6 * spacing
    return split_at_junctions(cut_openings(np.concatenate(segs), openings, tol), tol)


def side_segments(terrain: Terrain, closed, extension: float) -> np.ndarray:
    """Wall segments (ns, 4) along the closed sides of the DEM rectangle.

    A closed side that meets an open side runs on for ``extension`` metres beyond it, like
    the banks of a channel that leaves the DEM: the water near that corner then sees the
    mirror images of the outflow buffer (``OpenEdges``) too, and keeps its full depth.
    """
    w, h = terrain.width, terrain.height
    e = {side: (0.0 if side in closed else extension) for side in SIDES}
    ends = {"south": (-e["west"], 0.0, w + e["east"], 0.0),
            "east": (w, -e["south"], w, h + e["north"]),
            "north": (w + e["east"], h, -e["west"], h),
            "west": (0.0, h + e["north"], 0.0, -e["south"])}
    return np.array([ends[side] for side in SIDES if side in closed],
                    dtype=np.float64).reshape(-1, 4)
