"""The bed: a DEM grid in a local origin, with its slope, curvature and Manning n.

``Terrain`` is the one object the solver knows the ground through. It holds

* ``elevation`` b [m] on a regular grid whose row 0 is the *southern* row (local y grows with
  the row index) and whose node (i, j) sits at the cell centre
  ``x = (j + 0.5) dx, y = (i + 0.5) dy`` in local coordinates;
* the bed gradient (b_x, b_y) and Hessian (b_xx, b_xy, b_yy), computed once from the grid by
  second-order finite differences (``numpy.gradient`` with ``edge_order=2``), so that a plane
  and a paraboloid are reproduced exactly;
* Manning's n [s m^-1/3] on the same grid, and a ``valid`` mask (False = nodata, outside the
  model);
* the georeference: the projected CRS (as WKT, or None for synthetic beds) and the world
  coordinates ``(x0, y0)`` of the lower-left corner of the grid, which is the local origin.

Particles sample these grids bilinearly (``floodsph.sph.bed``). Analytic test beds are built
through the same type with :meth:`Terrain.from_function`, so tests exercise the real path.
DEM files are read by ``floodsph.inputs.dem``, which returns a ``Terrain``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Terrain:
    """A DEM grid in local coordinates with precomputed bed derivatives.

    Parameters
    ----------
    elevation : (ny, nx) float64 array
        Bed elevation b [m], row 0 = south. Must be finite everywhere (fill nodata first and
        mark it in ``valid``).
    dx, dy : float
        Cell size [m] in x (east) and y (north).
    manning : float or (ny, nx) array
        Manning's n [s m^-1/3].
    x0, y0 : float
        World (projected CRS) coordinates of the lower-left corner of the grid [m].
    crs_wkt : str or None
        The projected CRS as WKT; None for synthetic beds.
    valid : (ny, nx) bool array, optional
        False where the DEM had no data (outside the model). Defaults to all True.
    source_crs_wkt : str or None
        The CRS of the DEM file (or ``terrain.crs``) before any reprojection to ground
        metres: the CRS inline coordinates are in by default. None: the same as ``crs_wkt``.
    source_scale : (float, float) or None
        The smallest and largest point scale factor of the DEM file's CRS over the domain
        (``floodsph.io.crs``); None for a geographic DEM or a synthetic bed.
    coordinates_crs_wkt : str or None
        The CRS of the scenario's inline coordinates when ``[scenario] crs`` names one; None:
        ``source_crs_wkt`` (``floodsph.io.coordinates``).
    """

    elevation: np.ndarray
    dx: float
    dy: float
    manning: np.ndarray | float = 0.0
    x0: float = 0.0
    y0: float = 0.0
    crs_wkt: str | None = None
    # None is taken as every cell valid: __post_init__ always leaves the mask here
    valid: np.ndarray = None  # type: ignore[assignment]
    source_crs_wkt: str | None = None
    source_scale: tuple[float, float] | None = None
    coordinates_crs_wkt: str | None = None
    slope_x: np.ndarray = field(init=False, repr=False)
    slope_y: np.ndarray = field(init=False, repr=False)
    curv_xx: np.ndarray = field(init=False, repr=False)
    curv_xy: np.ndarray = field(init=False, repr=False)
    curv_yy: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        b = np.ascontiguousarray(self.elevation, dtype=np.float64)
        if b.ndim != 2 or min(b.shape) < 3:
            raise ValueError(f"elevation must be a 2-D grid of at least 3x3 cells, got {b.shape}")
        if not np.all(np.isfinite(b)):
            raise ValueError("elevation must be finite everywhere (fill nodata, mark it in valid)")
        if not (self.dx > 0 and self.dy > 0):
            raise ValueError(f"cell size must be positive, got dx={self.dx}, dy={self.dy}")
        self.elevation = b
        n = np.broadcast_to(np.asarray(self.manning, dtype=np.float64), b.shape)
        self.manning = np.ascontiguousarray(n)
        if self.valid is None:
            self.valid = np.ones(b.shape, dtype=bool)
        self.valid = np.ascontiguousarray(self.valid, dtype=bool)
        self.slope_y, self.slope_x = bed_gradient(b, self.dx, self.dy)
        self.curv_xx, self.curv_xy, self.curv_yy = bed_hessian(
            self.slope_x, self.slope_y, self.dx, self.dy
        )

    @classmethod
    def from_function(cls, func, xlim, ylim, cell, manning=0.0) -> Terrain:
        """Sample an analytic bed ``b = func(x, y)`` (vectorised, local metres) on a grid.

        ``xlim = (xmin, xmax)`` and ``ylim`` bound the grid's outer cell edges; the local
        origin is then shifted so that ``(xmin, ymin)`` is the grid's lower-left corner and
        the function is evaluated in the caller's coordinates (``x0 = xmin``, ``y0 = ymin``).
        """
        nx = int(round((xlim[1] - xlim[0]) / cell))
        ny = int(round((ylim[1] - ylim[0]) / cell))
        xc = xlim[0] + (np.arange(nx) + 0.5) * cell
        yc = ylim[0] + (np.arange(ny) + 0.5) * cell
        X, Y = np.meshgrid(xc, yc)
        return cls(
            elevation=np.asarray(func(X, Y), dtype=np.float64) + np.zeros_like(X),
            dx=cell,
            dy=cell,
            manning=manning,
            x0=xlim[0],
            y0=ylim[0],
        )

    @property
    def shape(self) -> tuple[int, int]:
        return self.elevation.shape

    @property
    def width(self) -> float:
        """Extent of the grid in local x [m]."""
        return self.shape[1] * self.dx

    @property
    def height(self) -> float:
        """Extent of the grid in local y [m]."""
        return self.shape[0] * self.dy

    def to_local(self, X, Y):
        """World (CRS) coordinates to local coordinates [m]."""
        return np.asarray(X, dtype=np.float64) - self.x0, np.asarray(Y, dtype=np.float64) - self.y0

    def to_world(self, x, y):
        """Local coordinates to world (CRS) coordinates [m]."""
        return np.asarray(x, dtype=np.float64) + self.x0, np.asarray(y, dtype=np.float64) + self.y0

    def covers(self, x, y, valid_only: bool) -> np.ndarray:
        """True for the points (x, y) [m, local] on the grid, and, with ``valid_only``, in a
        cell that is not nodata."""
        ny, nx = self.shape
        col = np.floor(x / self.dx).astype(np.int64)
        row = np.floor(y / self.dy).astype(np.int64)
        inside = (col >= 0) & (col < nx) & (row >= 0) & (row < ny)
        if valid_only:
            inside[inside] = self.valid[row[inside], col[inside]]
        return inside

    def cell_centres(self) -> tuple[np.ndarray, np.ndarray]:
        """Local x of the columns and local y of the rows (south to north) [m]."""
        ny, nx = self.shape
        return (np.arange(nx) + 0.5) * self.dx, (np.arange(ny) + 0.5) * self.dy

    def north_up_transform(self):
        """The rasterio ``Affine`` of a north-up raster of this grid in world coordinates."""
        from rasterio.transform import from_origin

        return from_origin(self.x0, self.y0 + self.height, self.dx, self.dy)

    def bed_grids(self) -> tuple[np.ndarray, ...]:
        """The grids sampled by the solver, in the order ``floodsph.sph.bed`` expects."""
        return (
            self.elevation,
            self.slope_x,
            self.slope_y,
            self.curv_xx,
            self.curv_xy,
            self.curv_yy,
            np.asarray(self.manning),  # the grid __post_init__ made of it: no copy
        )


def bed_gradient(b: np.ndarray, dx: float, dy: float) -> tuple[np.ndarray, np.ndarray]:
    """(b_y, b_x) by second-order finite differences, exact for quadratic beds."""
    gy, gx = np.gradient(b, dy, dx, edge_order=2)
    return np.ascontiguousarray(gy), np.ascontiguousarray(gx)


def bed_hessian(bx: np.ndarray, by: np.ndarray, dx: float, dy: float):
    """(b_xx, b_xy, b_yy) from the gradient grids; b_xy is the symmetrised mixed derivative."""
    bxy_a, bxx = np.gradient(bx, dy, dx, edge_order=2)
    byy, bxy_b = np.gradient(by, dy, dx, edge_order=2)
    return (
        np.ascontiguousarray(bxx),
        np.ascontiguousarray(0.5 * (bxy_a + bxy_b)),
        np.ascontiguousarray(byy),
    )
