"""Vector files of the scenario's geometry (walls, initial water, sinks, gauges), in any CRS.

Every format is read through pyogrio (GDAL/OGR), which knows the format from the file
itself: GeoJSON, GeoPackage, shapefiles (also zipped: ``walls.zip``, ``walls.shp.zip``),
FlatGeobuf, KML, GML and the other vector formats of GDAL's drivers, each with the CRS it
carries (a shapefile's ``.prj``; GeoJSON's RFC 7946 longitude/latitude on WGS 84 unless the
file names another CRS in its 2008-style ``crs`` member; KML's WGS 84). A file whose name
ends in ``.csv``, ``.tsv`` or ``.txt`` is a table, not a vector file (a gauge CSV).

The ``crs`` key of the scenario entry gives the CRS of a file that carries none (a shapefile
without its ``.prj``) or overrides the file's. :func:`read_vector` returns the features in
the target CRS (the DEM's), reprojected with pyproj (x = easting / longitude order); Z and M
coordinates are dropped. Every failure is one InputError naming the file (and the scenario
key, through ``where``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from floodsph.errors import InputError

TABLE_SUFFIXES = (".csv", ".tsv", ".txt")
"""Names of text tables: a ``[gauges]`` file so named is the ``id,x,y`` CSV."""
VECTOR_FORMATS = "GeoJSON, GeoPackage, shapefile (or a zipped one), FlatGeobuf, KML, GML"
"""The usual vector formats, for messages (GDAL reads more)."""


def is_vector_file(path) -> bool:
    """True for a file that is not a text table (:data:`TABLE_SUFFIXES`, any case)."""
    return Path(path).suffix.lower() not in TABLE_SUFFIXES


@dataclass(frozen=True)
class Features:
    """The features of one layer: shapely geometries (None for a feature without one) in the
    target CRS, and their attributes."""

    geometries: list
    properties: list[dict]


def read_vector(path, where: str, target_crs_wkt: str | None, *, layer: str | None = None,
                crs: str | None = None) -> Features:
    """The features of ``path`` (its ``layer``) reprojected into ``target_crs_wkt``.

    ``where`` starts every message (``"scenario.toml: walls[0].file walls.gpkg"``). ``crs``
    is the CRS of the coordinates when the file has none, or instead of its own.
    """
    geometries, properties, own = _read(Path(path), where, layer)
    source_crs = crs if crs is not None else own
    return Features(_reproject(geometries, source_crs, target_crs_wkt, where), properties)


def _read(path: Path, where: str, layer: str | None):
    """Geometries, properties and CRS (None if it has none) of one layer, through pyogrio."""
    import pyogrio
    import pyogrio.errors
    import pyogrio.raw
    import shapely

    try:
        layers = [str(name) for name in pyogrio.list_layers(path)[:, 0]]
        if layer is not None and layer not in layers:
            raise InputError(f"{where}: no layer {layer!r}; the file holds {layers}")
        if layer is None and len(layers) > 1:
            raise InputError(f"{where}: the file holds several layers {layers}; name one with "
                             "layer")
        meta, _, wkb, fields = pyogrio.raw.read(path, layer=layer)
    except (pyogrio.errors.DataSourceError, pyogrio.errors.DataLayerError) as exc:
        raise InputError(f"{where}: cannot be read as a vector file ({VECTOR_FORMATS}): "
                         f"{exc}") from None
    geometries = [None if g is None else shapely.from_wkb(g) for g in wkb]
    names = [str(n) for n in meta["fields"]]
    properties = [{n: column[k] for n, column in zip(names, fields, strict=True)}
                  for k in range(len(geometries))]
    return geometries, properties, meta.get("crs")


def _reproject(geometries: list, source_crs, target_crs_wkt: str | None, where: str) -> list:
    """Geometries without Z, from ``source_crs`` into the target CRS."""
    import numpy as np
    import pyproj
    import shapely

    flat = [None if g is None else shapely.force_2d(g) for g in geometries]
    if source_crs is None:
        raise InputError(f"{where}: the file has no CRS; give crs (e.g. crs = \"EPSG:32632\")")
    if target_crs_wkt is None:
        raise InputError(f"{where}: the DEM has no CRS, so the file's coordinates cannot be "
                         "placed on it")
    try:
        source = pyproj.CRS.from_user_input(source_crs)
    except pyproj.exceptions.CRSError as exc:
        raise InputError(f"{where}: its CRS {source_crs!r} is unknown to pyproj ({exc})"
                         ) from None
    target = pyproj.CRS.from_wkt(target_crs_wkt)
    if source.equals(target, ignore_axis_order=True):
        return flat
    transformer = pyproj.Transformer.from_crs(source, target, always_xy=True)

    def move(xy: np.ndarray) -> np.ndarray:
        x, y = transformer.transform(xy[:, 0], xy[:, 1])
        return np.column_stack([x, y])

    moved = [None if g is None else shapely.transform(g, move) for g in flat]
    for k, g in enumerate(moved, start=1):
        if g is not None and not np.all(np.isfinite(shapely.get_coordinates(g))):
            raise InputError(f"{where}: feature {k} cannot be reprojected from "
                             f"{source.name} to the DEM's {target.name} (outside its area)")
    return moved
