"""Inline coordinates follow the DEM file: the CRS they are in, and their move into the model's.

The scenario's inline coordinates (``initial_water.polygon``, ``walls.polyline``,
``inflows.line`` and ``direction``, ``sinks.polygon``, ``terrain.extent``, the x and y of a
gauges CSV) are in the DEM file's own CRS, or in ``[scenario] crs`` when that is given. The
model runs in ground metres (``floodsph.inputs.dem``): the DEM file's CRS itself, or the UTM zone
a geographic or distorting DEM was reprojected to, or the metre version of a CRS in feet. The
inline coordinates are transformed into that CRS here (pyproj, longitude/easting first), once,
before any check; vector files are reprojected from their own CRS by ``floodsph.io.vector``.
Messages name the CRS the user's coordinates are in (:func:`coordinates_label`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pyproj

from floodsph.errors import InputError
from floodsph.io.raster import crs_label


def coordinates_wkt(terrain) -> str | None:
    """The CRS of the inline coordinates as WKT: ``[scenario] crs``, else the DEM file's."""
    return terrain.coordinates_crs_wkt or terrain.source_crs_wkt or terrain.crs_wkt


def coordinates_label(terrain) -> str:
    """``EPSG:4326 (WGS 84), the DEM file's CRS`` (or ``..., scenario.crs``), for messages."""
    wkt = coordinates_wkt(terrain)
    where = "scenario.crs" if terrain.coordinates_crs_wkt else "the DEM file's CRS"
    return f"{crs_label(wkt)}, {where}"


def moved(terrain) -> bool:
    """True when the inline coordinates are not in the model's CRS (they are transformed)."""
    wkt = coordinates_wkt(terrain)
    if wkt is None or terrain.crs_wkt is None or wkt == terrain.crs_wkt:
        return False
    return pyproj.CRS.from_wkt(wkt) != pyproj.CRS.from_wkt(terrain.crs_wkt)


def _transformer(terrain, inverse: bool = False) -> pyproj.Transformer:
    wkt = coordinates_wkt(terrain)
    assert wkt is not None  # only called where the coordinates are moved (:func:`moved`)
    user = pyproj.CRS.from_wkt(wkt)
    model = pyproj.CRS.from_wkt(terrain.crs_wkt)
    return pyproj.Transformer.from_crs(model, user, always_xy=True) if inverse else \
        pyproj.Transformer.from_crs(user, model, always_xy=True)


def to_model(terrain, points, where: str = "") -> np.ndarray:
    """Points [[x, y], ...] in the coordinates' CRS as a (k, 2) array in the model's CRS;
    a point the transformation cannot take (easting and northing given where degrees are
    expected) is one InputError naming ``where`` and both CRSs."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if not moved(terrain):
        return p
    x, y = _transformer(terrain).transform(p[:, 0], p[:, 1], errcheck=False)
    out = np.column_stack([x, y])
    bad = ~np.all(np.isfinite(out), axis=1)
    if bad.any():
        k = int(np.argmax(bad))
        raise InputError(
            f"{where}: the point [{p[k, 0]:.10g}, {p[k, 1]:.10g}] is not a place in "
            f"{coordinates_label(terrain)}, which inline coordinates are in; give "
            f"[scenario] crs for coordinates in another CRS (the model's is "
            f"{crs_label(terrain.crs_wkt)})")
    return out


def to_user(terrain, points) -> np.ndarray:
    """Points in the model's CRS back in the coordinates' CRS, a (k, 2) array."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if not moved(terrain):
        return p
    x, y = _transformer(terrain, inverse=True).transform(p[:, 0], p[:, 1], errcheck=False)
    return np.column_stack([x, y])


def _tuple(points: np.ndarray) -> tuple[tuple[float, float], ...]:
    return tuple((float(x), float(y)) for x, y in points)


def _direction(terrain, line, direction, where: str):
    """A flow direction [dx, dy] in the coordinates' CRS, turned into the model's: the
    difference of the images of the line's midpoint and a point a thousandth of the line's
    length along the direction."""
    if direction is None:
        return None
    a, b = np.asarray(line, dtype=np.float64)
    mid = 0.5 * (a + b)
    d = np.asarray(direction, dtype=np.float64)
    step = 1e-3 * float(np.hypot(*(b - a))) / float(np.hypot(*d))
    p0, p1 = to_model(terrain, [mid, mid + step * d], where)
    return (float(p1[0] - p0[0]), float(p1[1] - p0[1]))


def inline_to_model(scenario, terrain):
    """``scenario`` with every inline coordinate in the model's CRS (the same scenario when
    the coordinates are in it already). Entries drawn from vector files are left alone."""
    if not moved(terrain):
        return scenario
    source = scenario.path.name

    def move(entries, kind: str, field: str):
        out = []
        for i, entry in enumerate(entries):
            points = getattr(entry, field)
            if points is None:
                out.append(entry)
                continue
            where = f"{source}: {kind}[{i}].{field}"
            out.append(replace(entry, **{field: _tuple(to_model(terrain, points, where))}))
        return tuple(out)

    inflows = tuple(
        replace(inflow,
                line=_tuple(to_model(terrain, inflow.line, f"{source}: inflows[{i}].line")),
                direction=_direction(terrain, inflow.line, inflow.direction,
                                     f"{source}: inflows[{i}].direction"))
        for i, inflow in enumerate(scenario.inflows))
    levels = tuple(
        entry if entry.line is None else
        replace(entry,
                line=_tuple(to_model(terrain, entry.line,
                                     f"{source}: level_boundaries[{i}].line")),
                direction=_direction(terrain, entry.line, entry.direction,
                                     f"{source}: level_boundaries[{i}].direction"))
        for i, entry in enumerate(scenario.level_boundaries))
    return replace(
        scenario,
        initial_water=move(scenario.initial_water, "initial_water", "polygon"),
        walls=move(scenario.walls, "walls", "polyline"),
        sinks=move(scenario.sinks, "sinks", "polygon"),
        flux_lines=move(scenario.flux_lines, "flux_lines", "polyline"),
        inflows=inflows,
        level_boundaries=levels,
    )
