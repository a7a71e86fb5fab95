"""The output map grid: the DEM grid, or a coarser/finer grid aligned to the DEM origin.

Maps are held south-up like :class:`floodsph.model.terrain.Terrain` (row 0 = southern row; cell
(i, j) centred at local ``x = (j + 0.5) dx, y = (i + 0.5) dy``). The local origin is the
lower-left corner of the DEM, at world coordinates ``(x0, y0)``. Writers flip the rows to
north-up and use :meth:`OutputGrid.north_up_transform`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from floodsph.errors import InputError


@dataclass(frozen=True)
class OutputGrid:
    """A regular map grid in the terrain's local origin.

    Parameters
    ----------
    nx, ny : int
        Number of columns (east) and rows (north).
    dx, dy : float
        Cell size [m].
    x0, y0 : float
        World coordinates of the lower-left corner [m] (= the DEM's local origin).
    crs_wkt : str or None
        Projected CRS of the DEM as WKT (None for synthetic terrain).
    bed : (ny, nx) float64 array
        Bed elevation b [m] at the cell centres, row 0 = south.
    valid : (ny, nx) bool array or None
        The cells whose centre lies in a DEM cell with data; the maps hold no water in the
        others (None: every cell). Where a walled nodata border cuts across nodata cells,
        the water reaches into them (``floodsph.walls.nodata``), but a map cell there has no
        ground to hold a depth over.
    """

    nx: int
    ny: int
    dx: float
    dy: float
    x0: float
    y0: float
    crs_wkt: str | None
    bed: np.ndarray | None
    valid: np.ndarray | None = None

    @classmethod
    def from_terrain(cls, terrain, resolution_m: float | None = None) -> OutputGrid:
        """The DEM grid itself, or a grid of ``resolution_m`` cells from the DEM origin.

        A resampled grid covers the whole DEM (its last row/column may overhang the DEM's
        north/east edge by less than one cell). Its bed is the bilinear interpolation of
        the DEM nodes at the new cell centres (clamped at the border); a cell is valid where
        its centre lies in a DEM cell with data.
        """
        if resolution_m is None:
            ny, nx = terrain.shape
            return cls(nx, ny, float(terrain.dx), float(terrain.dy), float(terrain.x0),
                       float(terrain.y0), terrain.crs_wkt, terrain.elevation.copy(),
                       terrain.valid.copy())
        if not (resolution_m > 0 and math.isfinite(resolution_m)):
            raise InputError(f"output.resolution_m must be a positive number of metres, "
                             f"got {resolution_m!r}")
        r = float(resolution_m)
        nx = max(1, math.ceil(terrain.width / r - 1e-9))
        ny = max(1, math.ceil(terrain.height / r - 1e-9))
        xc = (np.arange(nx) + 0.5) * r
        yc = (np.arange(ny) + 0.5) * r
        X, Y = np.meshgrid(xc, yc)
        bed = bilinear(terrain.elevation, terrain.dx, terrain.dy, X, Y)
        valid = terrain.covers(X.ravel(), Y.ravel(), valid_only=True).reshape(X.shape)
        return cls(nx, ny, r, r, float(terrain.x0), float(terrain.y0), terrain.crs_wkt, bed,
                   valid)

    @property
    def shape(self) -> tuple[int, int]:
        return (self.ny, self.nx)

    def cell_centres(self) -> tuple[np.ndarray, np.ndarray]:
        """Local x of the columns and local y of the rows (south to north) [m]."""
        return (np.arange(self.nx) + 0.5) * self.dx, (np.arange(self.ny) + 0.5) * self.dy

    def world_centres(self) -> tuple[np.ndarray, np.ndarray]:
        """World x of the columns (west to east) and world y of the rows (NORTH to south)."""
        xc, yc = self.cell_centres()
        return xc + self.x0, (yc + self.y0)[::-1]

    def north_up_transform(self):
        """The rasterio ``Affine`` of the north-up raster of this grid (world coordinates)."""
        from affine import Affine

        return Affine(self.dx, 0.0, self.x0, 0.0, -self.dy, self.y0 + self.ny * self.dy)


def bilinear(grid: np.ndarray, dx: float, dy: float, x, y) -> np.ndarray:
    """Bilinear interpolation of a south-up node grid (nodes at cell centres) at local (x, y).

    Points beyond the outermost nodes take the nearest edge value (clamped).
    """
    ny, nx = grid.shape
    fx = np.clip(np.asarray(x, dtype=np.float64) / dx - 0.5, 0.0, nx - 1.0)
    fy = np.clip(np.asarray(y, dtype=np.float64) / dy - 0.5, 0.0, ny - 1.0)
    j = np.minimum(np.floor(fx).astype(np.int64), max(nx - 2, 0))
    i = np.minimum(np.floor(fy).astype(np.int64), max(ny - 2, 0))
    tx = fx - j
    ty = fy - i
    j1 = np.minimum(j + 1, nx - 1)
    i1 = np.minimum(i + 1, ny - 1)
    return ((1 - tx) * (1 - ty) * grid[i, j] + tx * (1 - ty) * grid[i, j1]
            + (1 - tx) * ty * grid[i1, j] + tx * ty * grid[i1, j1])
