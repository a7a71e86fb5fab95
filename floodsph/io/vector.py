"""Vector files of the scenario's geometry (walls, initial water, sinks, gauges), in any CRS.

* GeoJSON (``.geojson``, ``.json``) is read with the standard library and shapely: RFC 7946
  coordinates are longitude/latitude on WGS 84 (``OGC:CRS84``), unless the file names another
  CRS in the ``crs`` member of the 2008 GeoJSON specification;
* GeoPackage (``.gpkg``), shapefile (``.shp``) and FlatGeobuf (``.fgb``) are read through
  pyogrio (GDAL/OGR), the optional extra ``floodsph[gis]``; their CRS is the layer's.

The ``crs`` key of the scenario entry gives the CRS of a file that carries none (a shapefile
without its ``.prj``) or overrides the file's. :func:`read_vector` returns the features in
the target CRS (the DEM's), reprojected with pyproj (x = easting / longitude order); Z and M
coordinates are dropped. Every failure is one InputError naming the file (and the scenario
key, through ``where``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from floodsph.errors import InputError

GEOJSON_SUFFIXES = (".geojson", ".json")
OGR_SUFFIXES = (".gpkg", ".shp", ".fgb")
VECTOR_SUFFIXES = GEOJSON_SUFFIXES + OGR_SUFFIXES
GEOJSON_CRS = "OGC:CRS84"
"""The CRS of RFC 7946 GeoJSON: WGS 84 longitude, latitude [degrees]."""


def is_vector_file(path) -> bool:
    """True for a file name ending in one of :data:`VECTOR_SUFFIXES` (any case)."""
    return Path(path).suffix.lower() in VECTOR_SUFFIXES


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
    path = Path(path)
    if path.suffix.lower() in GEOJSON_SUFFIXES:
        if layer is not None:
            raise InputError(f"{where}: a GeoJSON file holds one layer; remove layer")
        geometries, properties, own = _read_geojson(path, where)
    else:
        geometries, properties, own = _read_ogr(path, where, layer)
    source_crs = crs if crs is not None else own
    return Features(_reproject(geometries, source_crs, target_crs_wkt, where), properties)


def _read_geojson(path: Path, where: str):
    """Geometries, properties and CRS of a GeoJSON FeatureCollection, Feature or geometry."""
    import shapely.geometry

    try:
        data = json.loads(path.read_text(encoding="utf-8-sig"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{where}: cannot be read as GeoJSON ({exc})") from None
    kind = data.get("type") if isinstance(data, dict) else None
    if kind == "FeatureCollection":
        features = data.get("features", [])
    elif kind == "Feature":
        features = [data]
    elif kind is not None:
        features = [{"type": "Feature", "geometry": data, "properties": {}}]
    else:
        raise InputError(f"{where}: not GeoJSON (no \"type\" member at the top)")
    geometries, properties = [], []
    for k, feature in enumerate(features, start=1):
        try:
            geometry = feature.get("geometry")
            geometries.append(None if geometry is None else shapely.geometry.shape(geometry))
        except (AttributeError, KeyError, TypeError, ValueError) as exc:
            raise InputError(f"{where}: feature {k}: not a GeoJSON geometry ({exc})") from None
        properties.append(dict(feature.get("properties") or {}))
    return geometries, properties, _geojson_crs(data, where)


def _geojson_crs(data: dict, where: str) -> str:
    """The named CRS of a 2008 GeoJSON ``crs`` member, else RFC 7946's WGS 84 lon/lat."""
    member = data.get("crs")
    if member is None:
        return GEOJSON_CRS
    try:
        return str(member["properties"]["name"])
    except (KeyError, TypeError):
        raise InputError(f"{where}: its \"crs\" member names no CRS "
                         "(expected {\"type\": \"name\", \"properties\": {\"name\": ...}})"
                         ) from None


def _read_ogr(path: Path, where: str, layer: str | None):
    """Geometries, properties and CRS (None if it has none) of one layer, through pyogrio."""
    try:
        import pyogrio
        import pyogrio.errors
        import pyogrio.raw
    except ImportError:
        raise InputError(f"{where}: reading {path.suffix} files needs pyogrio: "
                         "pip install 'floodsph[gis]' (or convert the file to GeoJSON)"
                         ) from None
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
        raise InputError(f"{where}: cannot be read ({exc})") from None
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
