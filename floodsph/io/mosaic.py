"""A DEM given as tiles (``terrain.dem`` a list of files or a glob): one grid, mosaicked.

Free global DEMs (SRTM, Copernicus GLO-30, ALOS, FABDEM) come in 1-degree tiles, and a study
area often crosses a tile edge. Each tile is read as any raster
(:func:`floodsph.io.raster.read_grid`: its own nodata value becomes NaN, so tiles may differ in
it); a tile in another CRS than the first is reprojected (bilinear) to the first one's at the
first one's cell size, with a warning; then ``rasterio.merge.merge`` lays them on the first
tile's grid over the union of their bounds, the first tile that has data winning where tiles
overlap. Cells no tile covers are nodata.

A GDAL VRT mosaic (``gdalbuildvrt dem.vrt tiles/*.tif``) is read as one file and works too.
"""

from __future__ import annotations

import math
from contextlib import ExitStack
from pathlib import Path

import numpy as np
from rasterio.enums import Resampling
from rasterio.io import MemoryFile
from rasterio.merge import merge
from rasterio.transform import Affine
from rasterio.warp import calculate_default_transform, reproject, transform_bounds

from floodsph.errors import InputError, warn
from floodsph.io.raster import Grid, GridHeader, crs_label, crs_wkt, read_grid, read_header


def read_dem_grid(dem, *, variable=None, crs=None, warnings=None) -> Grid:
    """The DEM as one north-up grid: the file, or the mosaic of a tuple of tiles."""
    if not isinstance(dem, tuple):
        return read_grid(dem, variable=variable, crs=crs, what="DEM", warnings=warnings)
    tiles = [read_grid(path, variable=variable, crs=crs, what="DEM tile", warnings=warnings)
             for path in dem]
    first = tiles[0]
    for path, tile in zip(dem, tiles, strict=True):
        if tile.crs is None:
            raise InputError(f"DEM tile {path} has no coordinate reference system; give "
                             'terrain.crs (e.g. crs = "EPSG:4326") or add a .prj file')
    units = {tile.units for tile in tiles}
    if len(units) > 1:
        raise InputError(f"DEM tiles {dem[0]} ...: the tiles give their elevations in "
                         f"different units {sorted(str(u) for u in units)}")
    on_first = [tiles[0]]
    for path, tile in zip(dem[1:], tiles[1:], strict=True):
        if tile.crs != first.crs:
            warn(f"DEM tile {path} is in {crs_label(crs_wkt(tile.crs))}, the first tile "
                 f"{dem[0].name} in {crs_label(crs_wkt(first.crs))}; reprojected to the "
                 "first one's", warnings)
            tile = _reprojected(tile, first)
        on_first.append(tile)
    values, transform = _merged(on_first)
    return Grid(values, transform, first.crs, first.units, first.nodata)


def read_dem_header(dem, *, variable=None, crs=None) -> GridHeader:
    """Shape, transform and CRS of the DEM (a file, or the mosaic of tiles: the union of the
    tiles' bounds in the first one's CRS, on its cell size) without reading the values."""
    if not isinstance(dem, tuple):
        return read_header(dem, variable=variable, crs=crs, what="DEM")
    heads = [read_header(path, variable=variable, crs=crs, what="DEM tile") for path in dem]
    first = heads[0]
    boxes = []
    for head in heads:
        rows, cols = head.shape
        t = head.transform
        box = (t.c, t.f + t.e * rows, t.c + t.a * cols, t.f)
        if head.crs is not None and first.crs is not None and head.crs != first.crs:
            box = transform_bounds(head.crs, first.crs, *box, densify_pts=21)
        boxes.append(box)
    west, south = min(b[0] for b in boxes), min(b[1] for b in boxes)
    east, north = max(b[2] for b in boxes), max(b[3] for b in boxes)
    dx, dy = first.transform.a, -first.transform.e
    shape = (math.ceil((north - south) / dy - 1e-9), math.ceil((east - west) / dx - 1e-9))
    return GridHeader(shape, Affine(dx, 0.0, west, 0.0, -dy, north), first.crs)


def _reprojected(tile: Grid, first: Grid) -> Grid:
    """A tile reprojected (bilinear) to the first tile's CRS, on its cell size."""
    rows, cols = tile.shape
    t = tile.transform
    dst_t, w, h = calculate_default_transform(
        tile.crs, first.crs, cols, rows, t.c, t.f + t.e * rows, t.c + t.a * cols, t.f,
        resolution=(first.dx, first.dy))
    out = np.full((h, w), np.nan)
    reproject(tile.values, out, src_transform=t, src_crs=tile.crs, src_nodata=np.nan,
              dst_transform=dst_t, dst_crs=first.crs, dst_nodata=np.nan,
              resampling=Resampling.bilinear)
    return Grid(out, dst_t, first.crs, tile.units, np.nan)


def _merged(tiles: list[Grid]) -> tuple[np.ndarray, Affine]:
    """``rasterio.merge.merge`` of grids in one CRS (NaN = nodata; the first tile with data
    wins), through in-memory GeoTIFFs."""
    with ExitStack() as stack:
        sources = []
        for tile in tiles:
            memory = stack.enter_context(MemoryFile())
            rows, cols = tile.shape
            with memory.open(driver="GTiff", width=cols, height=rows, count=1,
                             dtype="float64", crs=tiles[0].crs, transform=tile.transform,
                             nodata=np.nan) as dst:
                dst.write(tile.values, 1)
            sources.append(stack.enter_context(memory.open()))
        values, transform = merge(sources, nodata=np.nan, method="first",
                                  resampling=Resampling.nearest)
    return np.ascontiguousarray(values[0], dtype=np.float64), transform


def tile_names(dem) -> str:
    """The DEM's file, or its tiles' names, for messages."""
    if isinstance(dem, tuple):
        return "tiles " + ", ".join(Path(p).name for p in dem)
    return str(dem)
