"""Where the scenario's geometry lies: on the DEM, in its CRS, and large enough to work.

Checked once the DEM is read (:func:`check_geometry_on_dem`), each message naming the key
path: every polygon and wall overlaps the DEM rectangle (a part outside is allowed: a
reservoir outline drawn beyond a cropped DEM), every inflow line end lies on DEM data and the
line is at least half a particle spacing long. The geometry is in the model's CRS by then
(``floodsph.io.coordinates``); messages give the DEM's extent and the points in the CRS the
inline coordinates are in, naming it, and name geometry that looks like longitude/latitude
where that CRS is projected (:func:`lonlat_hint`).
"""

from __future__ import annotations

import numpy as np
import pyproj
import shapely

from floodsph.errors import InputError
from floodsph.io.coordinates import coordinates_label, coordinates_wkt, moved, to_user

INFLOW_MIN_SPACINGS = 0.5
"""An inflow line shorter than this many particle spacings is refused: its buffer rows hold
round(L / dx) = 0 particles, forced to one of width L, so the unit discharge Q / L and the
boundary depth grow without bound as L shrinks (``floodsph.boundaries.inflow``)."""

LONLAT_BOX = (-180.0, -90.0, 180.0, 90.0)
"""Coordinates inside this box, over a DEM that lies outside it, are taken for degrees."""


def dem_box(terrain) -> shapely.Polygon:
    """The DEM rectangle in world coordinates."""
    return shapely.box(terrain.x0, terrain.y0, terrain.x0 + terrain.width,
                       terrain.y0 + terrain.height)


def extent_text(terrain) -> str:
    """``[xmin, ymin, xmax, ymax]`` of the DEM in world coordinates, for messages."""
    x0, y0 = terrain.x0, terrain.y0
    values = (x0, y0, x0 + terrain.width, y0 + terrain.height)
    return "[" + ", ".join(f"{v:.10g}" for v in values) + "]"


def user_extent_text(terrain) -> str:
    """The DEM's extent in the CRS of the inline coordinates, naming that CRS, for messages:
    ``[xmin, ymin, xmax, ymax] in EPSG:4326 (WGS 84), the DEM file's CRS``."""
    if not terrain.crs_wkt:
        return extent_text(terrain)
    if not moved(terrain):
        return f"{extent_text(terrain)} in {coordinates_label(terrain)}"
    corners = shapely.get_coordinates(shapely.segmentize(dem_box(terrain),
                                                         max(terrain.width, terrain.height) / 20))
    user = to_user(terrain, corners)
    values = (*user.min(axis=0), *user.max(axis=0))
    return "[" + ", ".join(f"{v:.10g}" for v in values) + f"] in {coordinates_label(terrain)}"


def lonlat_hint(points, terrain) -> str:
    """A sentence for geometry (given in the model's CRS) that looks like longitude/latitude
    in degrees where the inline coordinates are in a projected CRS, or ''."""
    if not terrain.crs_wkt:
        return ""
    wkt = coordinates_wkt(terrain)
    if wkt is None or pyproj.CRS.from_wkt(wkt).is_geographic:
        return ""
    p = to_user(terrain, points)
    xmin, ymin, xmax, ymax = LONLAT_BOX

    def in_box(x, y):
        return bool(np.all((x >= xmin) & (x <= xmax) & (y >= ymin) & (y <= ymax)))

    corners = to_user(terrain, shapely.get_coordinates(dem_box(terrain)))
    if not np.all(np.isfinite(p)) or not in_box(p[:, 0], p[:, 1]) \
            or in_box(corners[:, 0], corners[:, 1]):
        return ""
    return ("; its coordinates look like longitude/latitude in degrees, but inline coordinates "
            f"are in {coordinates_label(terrain)}; for longitude/latitude give "
            '[scenario] crs = "EPSG:4326"')


def off_dem_error(where: str, what: str, points, terrain) -> InputError:
    """``<where>: <what> outside the DEM extent [...] in <CRS>`` with the longitude/latitude
    hint; ``points`` are in the model's CRS."""
    return InputError(f"{where}: {what} outside the DEM extent {user_extent_text(terrain)}"
                      f"{lonlat_hint(points, terrain)}")


def check_point_on_dem(terrain, point, where: str) -> None:
    """Refuse a world point (the model's CRS) off the DEM grid or on a nodata cell; the
    message gives it in the coordinates' CRS."""
    x, y = terrain.to_local(point[0], point[1])
    col, row = int(np.floor(x / terrain.dx)), int(np.floor(y / terrain.dy))
    ny, nx = terrain.shape
    ux, uy = to_user(terrain, [point])[0] if terrain.crs_wkt else point
    if not (0 <= col < nx and 0 <= row < ny):
        raise off_dem_error(where, f"point [{ux:.10g}, {uy:.10g}] is", [point], terrain)
    if not terrain.valid[row, col]:
        raise InputError(f"{where}: point [{ux:.10g}, {uy:.10g}] lies on DEM nodata")


def check_geometry_on_dem(scenario, terrain, spacing_m: float, source: str) -> None:
    """Refuse polygons, walls and flux lines wholly off the DEM, and inflow lines off it or
    too short.

    A polygon must share a non-zero area with the DEM rectangle and a wall a non-zero length;
    a part outside is allowed (a reservoir outline drawn beyond a cropped DEM). Geometry read
    from a vector file is named by its file and feature (``feature`` of the entry).
    """
    box = dem_box(terrain)
    polygons = [(body.feature or f"initial_water[{i}].polygon", body.polygon)
                for i, body in enumerate(scenario.initial_water) if body.polygon is not None]
    polygons += [(sink.feature or f"sinks[{i}].polygon", sink.polygon)
                 for i, sink in enumerate(scenario.sinks)]
    for key, points in polygons:
        # make_valid: a keyhole ring (allowed, floodsph.checks.shapes) is not valid for GEOS.
        area = shapely.make_valid(shapely.Polygon(points))
        if shapely.intersection(area, box).area <= 0.0:
            raise off_dem_error(f"{source}: {key}", "the polygon lies wholly", points, terrain)
    for i, wall in enumerate(scenario.walls):
        line = shapely.LineString(wall.polyline)
        if shapely.intersection(line, box).length <= 0.0:
            raise off_dem_error(f"{source}: {wall.feature or f'walls[{i}].polyline'}",
                                "the wall lies wholly",
                                wall.polyline, terrain)
    for i, flux in enumerate(scenario.flux_lines):
        line = shapely.LineString(flux.polyline)
        if shapely.intersection(line, box).length <= 0.0:
            raise off_dem_error(f"{source}: flux_lines[{i}].polyline",
                                f"the flux line {flux.name!r} lies wholly", flux.polyline,
                                terrain)
    for i, inflow in enumerate(scenario.inflows):
        where = f"{source}: inflows[{i}].line"
        for point in inflow.line:
            check_point_on_dem(terrain, point, where)
        length = float(np.hypot(inflow.line[1][0] - inflow.line[0][0],
                                inflow.line[1][1] - inflow.line[0][1]))
        if length < INFLOW_MIN_SPACINGS * spacing_m:
            raise InputError(
                f"{where}: the line is {length:.3g} m long, shorter than half the particle "
                f"spacing ({INFLOW_MIN_SPACINGS * spacing_m:g} m), so the section cannot hold "
                "one particle across; draw it across the whole breach width or lower "
                "numerics.particle_spacing_m")
