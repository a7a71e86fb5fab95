"""One map named on the command line, read as a single band: a raster file, or a NetCDF variable.

A map is named as

* ``path``: any single-band raster GDAL (rasterio) reads: GeoTIFF, ESRI ASCII grid, a
  NetCDF file holding one map variable, ...;
* ``path:variable``: the variable of a NetCDF file, e.g. ``flood_maps.nc:max_depth``;
* a GDAL dataset name (``NETCDF:"flood_maps.nc":max_depth``, ``/vsizip/maps.zip/depth.tif``).

Whatever cannot be read is one :class:`~floodsph.errors.InputError` naming the map (and the
variables a NetCDF file does hold), never a traceback.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from floodsph.errors import InputError
from floodsph.output.quantities import MapMetadata, Quantity, identify

NETCDF_MAGIC = (b"CDF\x01", b"CDF\x02", b"CDF\x05", b"\x89HDF\r\n\x1a\n")
"""First bytes of classic, 64-bit offset, CDF5 and netCDF-4 (HDF5) files."""
GDAL_PREFIXES = ("/vsi", "NETCDF:", "HDF5:", "GTIFF_DIR:")
"""Starts of GDAL dataset names that are not plain paths."""


@dataclass
class Raster:
    """One band of a map file: data as float64 (NaN = nodata), georeference and quantity.

    ``quantity`` is None for a float map whose metadata say nothing
    (:func:`floodsph.output.quantities.identify`); ``evidence`` says what decided it.
    """

    path: str
    data: np.ndarray
    transform: object
    crs: object
    quantity: Quantity | None
    evidence: str = ""

    @property
    def kind(self) -> str | None:
        """The quantity's name (``depth``, ``arrival``, ``hazard_uk``...), None if unknown."""
        return None if self.quantity is None else self.quantity.name

    def described(self) -> str:
        """``max_depth.tif is a depth map (band description 'max_depth')``."""
        if self.quantity is None:
            return f"{self.path} is a map of unknown quantity"
        return f"{self.path} is {self.quantity.label} map ({self.evidence})"


def is_netcdf(path: Path) -> bool:
    """True when the file starts like a netCDF (classic, 64-bit, CDF5 or netCDF-4) file."""
    with open(path, "rb") as f:
        head = f.read(8)
    return any(head.startswith(magic) for magic in NETCDF_MAGIC)


def dataset_name(name: str) -> tuple[str, str | None]:
    """The GDAL dataset name of a map argument and its NetCDF variable (or None)."""
    path = Path(name)
    if path.is_file() or name.startswith(GDAL_PREFIXES):
        return name, None
    head, sep, variable = name.rpartition(":")
    if sep and Path(head).is_file():
        if not is_netcdf(Path(head)):
            raise InputError(f"{name}: {head} is not a NetCDF file, so it has no variable "
                             f"{variable!r}; name the raster file alone")
        return f'NETCDF:"{head}":{variable}', variable
    raise InputError(f"{name}: no such file")


def netcdf_maps(path: str) -> list[str]:
    """Names of the map variables GDAL finds in a NetCDF file (its subdatasets)."""
    import rasterio

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rasterio.errors.NotGeoreferencedWarning)
        with rasterio.open(path) as src:
            return [s.rsplit(":", 1)[-1] for s in src.subdatasets]


def read_raster(name) -> Raster:
    """Read the single band of a map (see the module docstring); InputError if it cannot be
    read, holds several bands or variables, or has no CRS.

    Its quantity comes from its metadata (:func:`floodsph.output.quantities.identify`).
    Class maps (integer data) read nodata, or 0 without one, as class 0 = dry; float maps
    read nodata as NaN.
    """
    import rasterio

    name = str(name)
    source, variable = dataset_name(name)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", rasterio.errors.NotGeoreferencedWarning)
            src = rasterio.open(source)
    except rasterio.errors.RasterioError as e:
        raise InputError(_unreadable(name, variable, e)) from None
    with src:
        if src.count == 0 and src.subdatasets:
            maps = [s.rsplit(":", 1)[-1] for s in src.subdatasets]
            raise InputError(f"{name} holds several maps ({', '.join(maps)}); name one as "
                             f"{name}:<variable>, e.g. {name}:{maps[0]}")
        if src.count != 1:
            raise InputError(f"{name} has {src.count} bands (a time series?); compare reads "
                             f"single-band maps")
        data = src.read(1).astype(np.float64)
        nodata, dtype = src.nodata, src.dtypes[0]
        transform, crs = src.transform, src.crs
        tags = src.tags(1)
        integer = bool(np.issubdtype(np.dtype(dtype), np.integer))
        meta = MapMetadata(description=src.descriptions[0] or "", variable=variable or "",
                           long_name=tags.get("long_name", ""),
                           standard_name=tags.get("standard_name", ""),
                           units=src.units[0] or tags.get("units", ""), integer=integer)
    if crs is None:
        raise InputError(f"{name}: the raster has no CRS; cannot align it with the other map")
    if integer:
        data[data == (nodata if nodata is not None else 0)] = 0.0
    elif nodata is not None and not math.isnan(nodata):
        data[data == nodata] = np.nan
    quantity, evidence = identify(meta)
    return Raster(name, data, transform, crs, quantity, evidence)


def _unreadable(name: str, variable: str | None, error) -> str:
    """The message for a map GDAL cannot open, listing a NetCDF file's maps."""
    import rasterio

    if variable is not None:
        head = name[: -len(variable) - 1]
        try:
            maps = netcdf_maps(head)
        except rasterio.errors.RasterioError:  # the file itself is unreadable: GDAL's reason
            maps = []
        if maps and variable not in maps:
            return f"{name}: {head} has no map variable {variable!r}; it has {', '.join(maps)}"
    return f"{name}: cannot read it as a raster ({error})"
