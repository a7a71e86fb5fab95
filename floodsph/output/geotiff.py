"""Single-band GeoTIFF writer for map grids (Cloud-Optimized GeoTIFF layout).

Float maps: float32, NaN nodata, DEFLATE with the floating-point predictor (3). Class maps:
uint8, 0 = dry (declared nodata so that viewers leave it transparent), a colour table and
the class names in the band tags. The band description is the map name; its units are both
GDAL's band unit type (rasterio's ``src.units``) and the ``units`` band tag, beside a
``long_name`` tag. Tiles of 512 x 512 and internal overviews, written with GDAL's ``COG``
driver when this GDAL has it (GDAL >= 3.1), else a tiled GTiff whose overviews are copied in
with ``COPY_SRC_OVERVIEWS`` (the COG layout). Rows are flipped to north-up and the transform
is the grid's world transform in the DEM CRS.

Files are written under a temporary name and renamed
(:func:`floodsph.io.atomic_files.atomic_path`),
so a file of the final name is complete.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from floodsph.io.atomic_files import atomic_path

BLOCK = 512


def _profile(shape, crs, transform, dtype, nodata, predictor) -> dict:
    ny, nx = shape
    return {
        "width": nx,
        "height": ny,
        "count": 1,
        "dtype": dtype,
        "nodata": nodata,
        "crs": crs,
        "transform": transform,
        "compress": "deflate",
        "predictor": predictor,
        "blocksize": BLOCK if min(nx, ny) >= BLOCK else 256,
    }


def write_geotiff(path, array, grid, name: str, units: str, *, long_name: str = "",
                  class_names=None, colours=None, tags: dict | None = None,
                  driver: str | None = None) -> Path:
    """Write one south-up map (row 0 = south) as a north-up GeoTIFF.

    Parameters
    ----------
    path : path-like
        Output file.
    array : (ny, nx) array
        The map; float maps are written as float32 with NaN nodata; uint8 maps as class
        maps with 0 = dry (nodata).
    grid : OutputGrid
        Georeference (CRS, origin, cell size).
    name, units, long_name : str
        Band description, ``units`` tag and ``long_name`` tag.
    class_names, colours : sequences, optional
        Class maps only: name and RGB colour per class value 0, 1, ...
    tags : dict, optional
        Extra dataset tags (e.g. wet threshold, floodsph version).
    driver : {"COG", "GTiff", None}
        None: "COG" when GDAL has it, else a tiled GTiff with copied overviews.

    Returns
    -------
    Path of the written file.
    """
    from rasterio.crs import CRS

    crs = CRS.from_wkt(grid.crs_wkt) if grid.crs_wkt else None
    return write_north_up(path, np.asarray(array)[::-1], crs, grid.north_up_transform(), name,
                          units, long_name=long_name, class_names=class_names,
                          colours=colours, tags=tags, driver=driver)


def write_north_up(path, array, crs, transform, name: str, units: str, *, long_name: str = "",
                   class_names=None, colours=None, tags: dict | None = None,
                   driver: str | None = None) -> Path:
    """Write one north-up map (row 0 = north) with its CRS and affine ``transform`` as a
    GeoTIFF in the COG layout; the other arguments are those of :func:`write_geotiff`."""
    import rasterio
    from rasterio.enums import ColorInterp

    path = Path(path)
    is_class = np.asarray(array).dtype == np.uint8
    if is_class:
        data = np.ascontiguousarray(array, dtype=np.uint8)
        profile = _profile(data.shape, crs, transform, "uint8", 0, 2)
    else:
        data = np.ascontiguousarray(array, dtype=np.float32)
        profile = _profile(data.shape, crs, transform, "float32", float("nan"), 3)
    band_tags = {"units": units, "long_name": long_name or name}
    if class_names is not None:
        band_tags.update({f"class_{k}": str(n) for k, n in enumerate(class_names)})
    with atomic_path(path) as part:
        if (driver or ("COG" if _has_cog() else "GTiff")) == "COG":
            cog = dict(profile, driver="COG", predictor="NO" if is_class else "FLOATING_POINT",
                       overview_resampling="nearest" if is_class else "average")
            with rasterio.open(part, "w", **cog) as dst:
                _fill(dst, data, name, band_tags, tags, colours, ColorInterp)
        else:
            _write_gtiff_cog_layout(part, data, profile, name, band_tags, tags, colours,
                                    is_class)
    return path


def _fill(dst, data, name, band_tags, tags, colours, ColorInterp) -> None:
    dst.write(data, 1)
    dst.set_band_description(1, name)
    dst.set_band_unit(1, band_tags["units"])
    dst.update_tags(1, **band_tags)
    if tags:
        dst.update_tags(**{k: str(v) for k, v in tags.items()})
    if colours is not None:
        dst.write_colormap(1, {k: tuple(c) + (255,) for k, c in enumerate(colours)})
        dst.colorinterp = [ColorInterp.palette]


def _has_cog() -> bool:
    import rasterio

    with rasterio.Env() as env:
        return "COG" in env.drivers()


def _write_gtiff_cog_layout(part, data, profile, name, band_tags, tags, colours,
                            is_class) -> None:
    """Tiled GTiff with overviews built in memory and copied first (COG layout)."""
    import rasterio
    from rasterio.enums import ColorInterp, Resampling
    from rasterio.shutil import copy as rio_copy

    mem = dict(profile, driver="GTiff", tiled=True, blockxsize=profile["blocksize"],
               blockysize=profile["blocksize"])
    mem.pop("blocksize")
    tmp = part.with_name(part.name + ".tmp.tif")
    with rasterio.open(tmp, "w", **mem) as dst:
        _fill(dst, data, name, band_tags, tags, colours, ColorInterp)
        factors = [f for f in (2, 4, 8, 16, 32) if min(dst.width, dst.height) // f >= 64]
        if factors:
            dst.build_overviews(factors, Resampling.nearest if is_class else Resampling.average)
    rio_copy(tmp, part, driver="GTiff", copy_src_overviews=True, tiled=True,
             blockxsize=mem["blockxsize"], blockysize=mem["blockysize"], compress="deflate",
             predictor=profile["predictor"])
    os.remove(tmp)
