"""Scenario geometry from vector files, placed on the DEM (``floodsph.inputs.prepare``).

An entry with ``file`` (``[[walls]]``, ``[[initial_water]]``, ``[[sinks]]``) becomes one entry
per part of each feature, with its coordinates in the DEM's CRS, checked as inline ones
(:mod:`floodsph.checks.shapes`) and labelled ``walls[0].file walls.gpkg, feature 3`` for
messages:

* walls: each line (LineString, and each part of a MultiLineString) is a wall, each polygon's
  outline a closed wall (a solid footprint), and each of its holes another (a courtyard);
* initial water and sinks: each polygon (and each part of a MultiPolygon) is one area; its
  holes (islands in a reservoir) stay outside it: the polygon becomes one ring with a bridge
  to each hole (:func:`keyhole_ring`).

A feature of another geometry type, or a file without features, is refused naming the file.
``[gauges]`` points come from :func:`vector_gauges`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from floodsph.checks.shapes import polygon_problem, polyline_problem
from floodsph.errors import InputError
from floodsph.io.vector import read_vector

POLYGONS = ("Polygon", "MultiPolygon")
LINES = ("LineString", "MultiLineString")


def with_vector_geometry(scenario, terrain):
    """``scenario`` with every vector-file entry replaced by inline entries in the DEM's CRS
    (the same scenario when it has none)."""
    if not any(e.file is not None for e in (*scenario.walls, *scenario.initial_water,
                                            *scenario.sinks)):
        return scenario
    source = scenario.path.name

    def expand(entries, kind: str, field: str, types: tuple[str, ...]):
        out = []
        for i, entry in enumerate(entries):
            if entry.file is None:
                out.append(entry)
                continue
            where = f"{source}: {kind}[{i}].file {entry.file.name}"
            for label, points in _parts(entry, where, terrain, types):
                out.append(replace(entry, file=None, layer=None, crs=None, feature=label,
                                   **{field: points}))
        return tuple(out)

    return replace(
        scenario,
        walls=expand(scenario.walls, "walls", "polyline", LINES + POLYGONS),
        initial_water=expand(scenario.initial_water, "initial_water", "polygon", POLYGONS),
        sinks=expand(scenario.sinks, "sinks", "polygon", POLYGONS),
    )


def _parts(entry, where: str, terrain, types: tuple[str, ...]):
    """``(label, points)`` of each part of each feature of ``entry.file``."""
    import shapely

    features = read_vector(entry.file, where, terrain.crs_wkt, layer=entry.layer,
                           crs=entry.crs)
    out = []
    for k, geometry in enumerate(features.geometries, start=1):
        label = f"{where.split(': ', 1)[1]}, feature {k}"
        kind = None if geometry is None else geometry.geom_type
        if kind not in types:
            raise InputError(f"{where}: feature {k} is {kind or 'empty'}; expected "
                             f"{' or '.join(types)} here")
        for part in shapely.get_parts(geometry):
            if part.geom_type == "Polygon" and "LineString" in types:  # walls round each ring
                rings = [_points(r.coords) for r in (part.exterior, *part.interiors)]
                checks = [polyline_problem(r) for r in rings]
            elif part.geom_type == "Polygon":
                rings = [keyhole_ring(part)]
                checks = [polygon_problem(rings[0])]
            else:
                rings = [_points(part.coords)]
                checks = [polyline_problem(rings[0])]
            for points, problem in zip(rings, checks, strict=True):
                if problem is not None:
                    raise InputError(f"{where}: feature {k}: {problem}")
                out.append((label, points))
    if not out:
        raise InputError(f"{where}: holds no features")
    return out


def keyhole_ring(polygon) -> tuple[tuple[float, float], ...]:
    """One ring of a shapely polygon with holes: the outline, and at the outline's vertex
    nearest to each hole a bridge in to the hole's nearest vertex, round the hole and back.

    By the even-odd rule the holes are outside the ring (the bridge edges, run twice, cancel),
    which is how the initial water and the sinks fill a polygon
    (:func:`floodsph.io.polygons.points_in_polygon`). A bridge that crosses another hole
    makes the ring cross itself, which :func:`floodsph.checks.shapes.polygon_problem` refuses.
    """
    outline = list(_points(polygon.exterior.coords))[:-1]
    detours: dict[int, list] = {}
    for hole in polygon.interiors:
        ring = np.asarray(_points(hole.coords)[:-1])
        edge = np.asarray(outline)
        gaps = np.hypot(edge[:, None, 0] - ring[None, :, 0], edge[:, None, 1] - ring[None, :, 1])
        at, into = np.unravel_index(int(np.argmin(gaps)), gaps.shape)
        loop = [tuple(p) for p in np.roll(ring, -into, axis=0)]
        detours.setdefault(int(at), []).append([*loop, loop[0], outline[at]])
    points = []
    for i, vertex in enumerate(outline):
        points.append(vertex)
        for detour in detours.get(i, []):
            points.extend(detour)
    points.append(outline[0])
    return tuple((float(x), float(y)) for x, y in points)


def _points(coords) -> tuple[tuple[float, float], ...]:
    return tuple((float(x), float(y)) for x, y in np.asarray(coords, dtype=np.float64)[:, :2])


def vector_gauges(gauges, terrain, source: str):
    """The gauge points of a vector ``[gauges] file`` (Point or MultiPoint features) in LOCAL
    coordinates, named by the ``id_field`` attribute (default ``id`` when the layer has it,
    else the feature number from 1)."""
    from floodsph.checks.placement import extent_text, lonlat_hint
    from floodsph.output.gauges import GaugePoints
    from floodsph.output.grid import bilinear

    where = f"{source}: gauges.file {gauges.file.name}"
    features = read_vector(gauges.file, where, terrain.crs_wkt, layer=gauges.layer,
                           crs=gauges.crs)
    field = gauges.id_field
    if field is None and features.properties and "id" in features.properties[0]:
        field = "id"
    ids, xs, ys = [], [], []
    for k, (geometry, props) in enumerate(zip(features.geometries, features.properties,
                                              strict=True), start=1):
        if geometry is None or geometry.geom_type not in ("Point", "MultiPoint"):
            kind = "empty" if geometry is None else geometry.geom_type
            raise InputError(f"{where}: feature {k} is {kind}; gauges are Point features")
        if field is not None and field not in props:
            raise InputError(f"{where}: gauges.id_field: the features have no attribute "
                             f"{field!r}; they have {sorted(props)}")
        for x, y in np.asarray(geometry.__geo_interface__["coordinates"],
                               dtype=np.float64).reshape(-1, 2):
            gid = str(props[field]) if field is not None else str(k)
            lx, ly = x - terrain.x0, y - terrain.y0
            if not (0.0 <= lx <= terrain.width and 0.0 <= ly <= terrain.height):
                raise InputError(f"{where}: feature {k}: gauge {gid!r} at ({x:.10g}, "
                                 f"{y:.10g}) is outside the DEM extent {extent_text(terrain)}"
                                 f"{lonlat_hint([(x, y)], terrain)}")
            if gid in ids:
                raise InputError(f"{where}: feature {k}: duplicate gauge id {gid!r}")
            ids.append(gid)
            xs.append(lx)
            ys.append(ly)
    if not ids:
        raise InputError(f"{where}: holds no gauge points")
    x, y = np.array(xs), np.array(ys)
    return GaugePoints(tuple(ids), x, y, bilinear(terrain.elevation, terrain.dx, terrain.dy,
                                                  x, y))
