"""A raster input multiplied by a factor, written into a member's folder.

``mode = "factor"`` on a raster key (a Manning n raster, an initial depth raster) gives the
member a copy of the base raster with every valid cell times the factor; nodata cells stay
nodata. The copy is a single-band GeoTIFF on the base raster's own grid and CRS (the run
resamples it onto the DEM exactly as it would the base raster), float32 unless the base is
float64.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from floodsph.errors import InputError
from floodsph.io.atomic_files import atomic_path

#: Key patterns whose value may be a raster file that a factor scales.
RASTER_KEYS = ("terrain.manning", "initial_water[].depth")


def raster_name(key) -> str:
    """The scaled raster's file name in the member folder (``terrain.manning.tif``)."""
    return "".join(c if c.isalnum() or c in "._" else "_" for c in key.text) + ".tif"


def scale_raster(source: Path, target: Path, factor: float, where: str) -> Path:
    """Write ``source`` x ``factor`` to ``target`` (GeoTIFF); ``where`` names the key."""
    import rasterio
    from rasterio.errors import RasterioError

    try:
        with rasterio.open(source) as src:
            data = src.read(1, masked=True)
            nodata = src.nodata
            profile = {"driver": "GTiff", "width": src.width, "height": src.height,
                       "count": 1, "crs": src.crs, "transform": src.transform,
                       "compress": "deflate"}
    except RasterioError as exc:
        raise InputError(f"{where}: cannot read the raster {source} to scale it: {exc}") from None
    dtype = np.float64 if data.dtype == np.float64 else np.float32
    scaled = np.ma.filled(data.astype(dtype) * dtype(factor),
                          np.nan if nodata is None else nodata)
    with (atomic_path(target) as part,
          rasterio.open(part, "w", dtype=scaled.dtype, nodata=nodata, **profile) as dst):
        dst.write(scaled, 1)
    return target
