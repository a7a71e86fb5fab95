"""Whether a projected CRS measures ground metres: its point scale factors and length unit.

A map projection stretches lengths by its point scale factor k (Snyder 1987, *Map
Projections: A Working Manual*, USGS PP 1395, §4): a distance d on the map is d / k on the
ground. The solver takes a DEM's coordinates for ground metres, so a CRS whose k departs
from 1 by more than :data:`SCALE_TOLERANCE` anywhere in the domain gives lengths, areas,
volumes and slopes that are wrong by k, k^2, k^2 and 1/k. Web Mercator (EPSG:3857) has
k = 1 / cos(latitude): 1.25 at 36.7 degrees. UTM stays within 0.9996-1.001 over its zone, the
national grids within a few 1e-4.

The factors come from PROJ (``pyproj.Proj.get_factors``: the meridional scale h and the
parallel scale k at a longitude/latitude), at the domain's centre and four corners.
"""

from __future__ import annotations

import math

import numpy as np
import pyproj
from rasterio.crs import CRS
from rasterio.transform import Affine

SCALE_TOLERANCE = 0.005
"""The largest departure of a point scale factor from 1 accepted as ground metres (0.5 %): a
0.5 % length error is 1 % in areas and volumes, within what a DEM's own error gives on a
flooded volume; Web Mercator passes it only within about 5.7 degrees of the equator."""


def domain_points(t: Affine, shape: tuple[int, int]) -> np.ndarray:
    """The centre and the four corners of a north-up grid, (5, 2) world coordinates."""
    rows, cols = shape
    xs = (t.c, t.c + t.a * cols)
    ys = (t.f + t.e * rows, t.f)
    corners = [(x, y) for x in xs for y in ys]
    return np.array([(0.5 * sum(xs), 0.5 * sum(ys)), *corners], dtype=np.float64)


def scale_factors(crs: CRS, points: np.ndarray) -> np.ndarray:
    """Meridional and parallel point scale factors (h, k) of a projected ``crs`` at world
    ``points`` (n, 2): an (n, 2) array."""
    proj_crs = pyproj.CRS.from_wkt(crs.to_wkt())
    to_lonlat = pyproj.Transformer.from_crs(proj_crs, proj_crs.geodetic_crs, always_xy=True)
    lon, lat = to_lonlat.transform(points[:, 0], points[:, 1])
    factors = pyproj.Proj(proj_crs).get_factors(lon, lat)
    return np.column_stack([factors.meridional_scale, factors.parallel_scale])


def scale_range(crs: CRS, t: Affine, shape: tuple[int, int]) -> tuple[float, float]:
    """The smallest and largest point scale factor of ``crs`` over a grid (centre, corners)."""
    hk = scale_factors(crs, domain_points(t, shape))
    return float(hk.min()), float(hk.max())


def centre_scale(crs: CRS, t: Affine, shape: tuple[int, int]) -> float:
    """The areal mean scale factor sqrt(h k) at the grid's centre: a cell of side s there
    is a ground square of side s / sqrt(h k)."""
    h, k = scale_factors(crs, domain_points(t, shape)[:1])[0]
    return float(math.sqrt(h * k))


def is_ground_metres(scales: tuple[float, float]) -> bool:
    """True when both factors lie within :data:`SCALE_TOLERANCE` of 1."""
    return max(abs(scales[0] - 1.0), abs(scales[1] - 1.0)) <= SCALE_TOLERANCE


def length_unit(crs: CRS) -> tuple[str, float]:
    """The name of a projected CRS's axis unit and its length in metres."""
    unit, factor = crs.linear_units_factor
    return unit, float(factor)


def in_metres(crs: CRS) -> CRS:
    """The same projection as a projected ``crs`` in feet (or any length unit), with axes in
    metres: the same conversion and datum, so that coordinates are only multiplied by the
    unit's length (the false easting and northing keep their meaning)."""
    from pyproj.crs import ProjectedCRS
    from pyproj.crs.coordinate_system import Cartesian2DCS

    full = pyproj.CRS.from_wkt(crs.to_wkt())
    metric = ProjectedCRS(conversion=full.coordinate_operation, geodetic_crs=full.geodetic_crs,
                          cartesian_cs=Cartesian2DCS(), name=f"{full.name} (in metres)")
    return CRS.from_wkt(metric.to_wkt())
