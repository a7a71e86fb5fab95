"""Sinks: polygons where water leaves the model (the sea, a far lake), counted as outflow.

A particle is absorbed when the DEM cell it stands in has its centre inside the sink polygon
(even-odd rule, ``floodsph.io.polygons.points_in_polygon``), so the sink edge follows the DEM
grid. Its volume m / rho_w is added to ``water.volume_out``. Water beyond the edge of the
model is not simulated: a sink is an absorbing boundary, which is what a receiving water body
far larger than the flood is: only the water that floods the scene is modelled
(``docs/method.md`` §8).
"""

from __future__ import annotations

import math

import numpy as np

from floodsph.boundaries.protocol import Site, Water
from floodsph.constants import RHO_WATER
from floodsph.io.polygons import points_in_polygon


class Sink:
    """An absorbing polygon on the terrain grid.

    Parameters
    ----------
    polygon : (k, 2) array
        Vertices in local coordinates [m] (open or closed).
    terrain : Terrain
    reach : float
        Width [m] of the protected band around the sink (no coalescing there).
    """

    STATE = ("volume_out",)
    """What changes during a run (``Boundary.STATE``): the volume absorbed [m3]."""

    def __init__(self, polygon, terrain, reach: float):
        from scipy.ndimage import binary_dilation

        poly = np.asarray(polygon, dtype=np.float64)
        ny, nx = terrain.shape
        xc = (np.arange(nx) + 0.5) * terrain.dx
        yc = (np.arange(ny) + 0.5) * terrain.dy
        gx, gy = np.meshgrid(xc, yc)
        self.dx, self.dy = terrain.dx, terrain.dy
        self.mask = points_in_polygon(gx, gy, poly)
        cells = int(math.ceil(reach / min(self.dx, self.dy)))
        self.near = binary_dilation(self.mask, iterations=max(cells, 1))
        self.volume_out = 0.0

    def _lookup(self, grid, x, y) -> np.ndarray:
        ny, nx = grid.shape
        col = np.clip(np.floor(x / self.dx).astype(np.int64), 0, nx - 1)
        row = np.clip(np.floor(y / self.dy).astype(np.int64), 0, ny - 1)
        return grid[row, col]

    def apply(self, water: Water, site: Site, dt: float) -> None:
        """Remove the particles inside the sink and count their volume as outflow."""
        p = water.particles
        inside = self._lookup(self.mask, p.x, p.y)
        if inside.any():
            volume = float(p.m[inside].sum()) / RHO_WATER
            self.volume_out += volume
            water.volume_out += volume
            p.keep(~inside)

    def add_ghosts(self, p) -> None:
        """A sink has no ghosts."""

    def impose(self, p, lists) -> None:
        """A sink imposes no state."""

    opening = None
    """No section: walls are not cut for this boundary (``Boundary.opening``)."""

    def max_dt(self, cfl: float) -> float:
        """No limit of its own on the step [s] (``Boundary.max_dt``)."""
        return math.inf

    def protected(self, x, y) -> np.ndarray:
        return self._lookup(self.near, x, y)

    def __repr__(self) -> str:
        return f"Sink({int(self.mask.sum())} cells, {self.volume_out:.6g} m3 absorbed)"
