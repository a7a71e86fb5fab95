"""Low-level raster access shared by the DEM, Manning and initial-depth readers.

Every reader here turns rasterio/GDAL failures into one :class:`~floodsph.errors.InputError`
that names the file, and every grid is handled *north-up* (row 0 = north, as rasterio
returns it). Only :func:`floodsph.inputs.dem.load_terrain` flips to the solver's south-up order.
"""

from __future__ import annotations

import re
import warnings as pywarnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import rasterio
from rasterio.crs import CRS
from rasterio.enums import Resampling
from rasterio.errors import CRSError, NotGeoreferencedWarning, RasterioError
from rasterio.transform import Affine
from rasterio.warp import reproject

from floodsph.errors import InputError, warn


@dataclass
class Grid:
    """A north-up single-band raster in memory.

    Attributes
    ----------
    values : (rows, cols) float64 array
        Cell values, NaN where the source had no data.
    transform : Affine
        Cell (col, row) -> world (x, y) of the upper-left corner, north-up, no rotation.
    crs : CRS or None
        The raster's coordinate reference system.
    units : str or None
        The band's unit name as the file states it (GDAL unit type: ``"metre"``, ``"ft"``,
        ``"US survey foot"``...), None when it states none.
    nodata : float or None
        The nodata value the file declares (those cells are NaN in ``values``).
    """

    values: np.ndarray
    transform: Affine
    crs: CRS | None
    units: str | None = None
    nodata: float | None = None

    @property
    def shape(self) -> tuple[int, int]:
        return self.values.shape

    @property
    def dx(self) -> float:
        return float(self.transform.a)

    @property
    def dy(self) -> float:
        return float(-self.transform.e)


@dataclass(frozen=True)
class GridHeader:
    """Shape, north-up transform and CRS of a raster, read without its values."""

    shape: tuple[int, int]
    transform: Affine
    crs: CRS | None

    @property
    def cells(self) -> int:
        return int(self.shape[0]) * int(self.shape[1])


def parse_crs(value, what: str) -> CRS:
    """A CRS from user input (``"EPSG:27572"``, WKT, PROJ string); InputError names ``what``."""
    try:
        return CRS.from_user_input(value)
    except (CRSError, ValueError, TypeError) as exc:
        raise InputError(
            f"{what}: {value!r} is not a coordinate reference system ({exc})"
        ) from None


def crs_wkt(crs: CRS | None) -> str | None:
    """The WKT of ``crs``; None for a raster without one."""
    return None if crs is None else crs.to_wkt()


def crs_label(crs_wkt: str | None) -> str:
    """``'EPSG:32632 (WGS 84 / UTM zone 32N)'`` from a WKT (name only if there is no code)."""
    if not crs_wkt:
        return "none (synthetic terrain)"
    match = re.search(r'^\s*\w+\["([^"]*)"', crs_wkt)
    name = match.group(1) if match else "unnamed"
    epsg = CRS.from_wkt(crs_wkt).to_epsg()
    return f"EPSG:{epsg} ({name})" if epsg else name


def dataset_name(path: Path, variable: str | None) -> str:
    """The GDAL dataset name: the path, or ``NETCDF:"path":variable`` for a NetCDF variable."""
    if variable is None:
        return str(path)
    return f'NETCDF:"{path}":{variable}'


def _sidecar_prj_crs(path: Path) -> CRS | None:
    """The CRS of an ESRI ASCII grid's sibling ``.prj`` file, if there is one."""
    for prj in (path.with_suffix(".prj"), path.with_suffix(".PRJ")):
        if prj.is_file():
            try:
                return CRS.from_wkt(prj.read_text().strip())
            except (CRSError, ValueError) as exc:
                raise InputError(f"{prj}: not a valid WKT projection file ({exc})") from None
    return None


def read_grid(path, *, variable: str | None = None, crs=None, what: str = "raster",
              warnings: list[str] | None = None) -> Grid:
    """Read band 1 of a raster as a north-up float64 grid with NaN for nodata.

    Parameters
    ----------
    path : str or Path
        GeoTIFF, ESRI ASCII grid (``.asc``, CRS from the sibling ``.prj``) or NetCDF.
    variable : str, optional
        NetCDF variable name (GDAL subdataset ``NETCDF:"path":variable``).
    crs : str or CRS, optional
        CRS to use when the file carries none; if the file has one and it differs, the
        argument wins and a warning is reported (into ``warnings``, :func:`floodsph.errors.warn`).
    what : str
        Role of the file in messages (``"DEM"``, ``"manning raster"``...).

    Raises
    ------
    InputError
        Missing/unreadable file, unknown NetCDF variable, a raster not georeferenced (identity
        transform), rotated or sheared transform.
    """
    path = Path(path)
    name = _dataset(path, variable, what)
    try:
        with _open(name) as src:
            _refuse_container(src, path, variable, what)
            values = src.read(1, out_dtype="float64")
            nodata = src.nodata
            transform = src.transform
            file_crs = src.crs
            units = src.units[0] or None
    except RasterioError as exc:
        raise _unreadable(exc, path, variable, what) from None
    if nodata is not None and not np.isnan(nodata):
        values[values == nodata] = np.nan
    values[~np.isfinite(values)] = np.nan
    own = _own_crs(file_crs, path)
    used = own if crs is None else parse_crs(crs, f"{what} {path}: crs")
    if own is not None and own != used:
        warn(f"{what} {path}: its own CRS is overridden by crs={crs}", warnings)
    values, transform = _north_up(values, transform, path, what)
    return Grid(values, transform, used, units, nodata)


def read_header(path, *, variable: str | None = None, crs=None, what: str = "raster"
                ) -> GridHeader:
    """The shape, north-up transform and CRS of a raster, without reading its values (to
    estimate the memory a run needs before the grid is allocated); errors as
    :func:`read_grid`."""
    path = Path(path)
    name = _dataset(path, variable, what)
    try:
        with _open(name) as src:
            _refuse_container(src, path, variable, what)
            shape, transform, file_crs = src.shape, src.transform, src.crs
    except RasterioError as exc:
        raise _unreadable(exc, path, variable, what) from None
    _check_axes(transform, path, what)
    (rows, cols), t = shape, transform
    north_up = Affine(abs(t.a), 0.0, min(t.c, t.c + t.a * cols),
                      0.0, -abs(t.e), max(t.f, t.f + t.e * rows))
    own = _own_crs(file_crs, path)
    used = own if crs is None else parse_crs(crs, f"{what} {path}: crs")
    return GridHeader((int(rows), int(cols)), north_up, used)


def _open(name: str):
    """``rasterio.open`` without its NotGeoreferencedWarning: :func:`_check_axes` refuses such a
    raster with a message that says what to do."""
    with pywarnings.catch_warnings():
        pywarnings.simplefilter("ignore", NotGeoreferencedWarning)
        return rasterio.open(name)


def _dataset(path: Path, variable: str | None, what: str) -> str:
    if not path.is_file():
        raise InputError(f"{what} file not found: {path}")
    return dataset_name(path, variable)


def _refuse_container(src, path: Path, variable: str | None, what: str) -> None:
    """A NetCDF file of several variables opened without naming one."""
    if variable is None and src.count == 0 and src.subdatasets:
        names = [s.rsplit(":", 1)[-1] for s in src.subdatasets]
        raise InputError(
            f"{what} {path}: the file holds several variables {names}; "
            "name one with dem_variable"
        )


def _unreadable(exc: Exception, path: Path, variable: str | None, what: str) -> InputError:
    extra = f" (variable {variable!r})" if variable else ""
    return InputError(f"cannot read {what} {path}{extra}: {exc}")


def _own_crs(file_crs, path: Path):
    """The CRS the file carries (an ``.asc`` grid's from its sibling ``.prj``), or None."""
    if file_crs is None and path.suffix.lower() == ".asc":
        return _sidecar_prj_crs(path)
    return file_crs


def _check_axes(t: Affine, path: Path, what: str) -> None:
    """Refuse a raster that is not georeferenced (GDAL gives the identity transform, cells of
    one unit from the origin, to a file whose coordinates it could not read: a NetCDF file
    whose x and y carry no CF attributes, a bare GeoTIFF), a rotated or sheared transform, or
    a zero cell size."""
    if t.almost_equals(Affine.identity()):
        raise InputError(
            f"{what} {path}: the raster is not georeferenced (its transform is the identity: "
            "cells of one unit from the origin); in a NetCDF file give the x and y variables "
            'the CF attributes units ("m", or "degrees_east" / "degrees_north") and '
            "standard_name (projection_x_coordinate / projection_y_coordinate, or longitude / "
            "latitude), or convert it to a GeoTIFF with its transform"
        )
    if t.b != 0.0 or t.d != 0.0:
        raise InputError(
            f"{what} {path}: the raster is rotated or sheared (transform {tuple(t)[:6]}); "
            "resample it to a north-up grid first (e.g. gdalwarp)"
        )
    if t.a == 0.0 or t.e == 0.0:
        raise InputError(f"{what} {path}: zero cell size in the transform {tuple(t)[:6]}")


def _north_up(values: np.ndarray, t: Affine, path: Path, what: str):
    """Refuse rotation/shear; flip south-up or east-to-west rasters to north-up."""
    _check_axes(t, path, what)
    rows, cols = values.shape
    if t.e > 0:  # row 0 is the southern row
        values = values[::-1]
        t = Affine(t.a, 0.0, t.c, 0.0, -t.e, t.f + t.e * rows)
    if t.a < 0:  # column 0 is the eastern column
        values = values[:, ::-1]
        t = Affine(-t.a, 0.0, t.c + t.a * cols, 0.0, t.e, t.f)
    return np.ascontiguousarray(values), t


def resample_onto(
    source,
    dst_transform: Affine,
    dst_shape: tuple[int, int],
    dst_crs: CRS | None,
    *,
    resampling: Resampling,
    what: str,
    label=None,
) -> np.ndarray:
    """Resample a raster (a path or a read :class:`Grid`) onto a north-up target grid.

    The source may be on any grid and in any CRS (``rasterio.warp.reproject``); the result
    is NaN where it has no data. When neither side has a CRS (synthetic terrain), the source
    is taken to be in the target's coordinates and only resampled. ``label`` names the
    source in messages (default: its path).
    """
    path = label if label is not None else source
    src = source if isinstance(source, Grid) else read_grid(source, what=what)
    if (src.crs is None) != (dst_crs is None):
        missing = str(path) if src.crs is None else "the DEM"
        raise InputError(f"{what} {path}: {missing} has no CRS, cannot align it with the DEM")
    # Same stand-in CRS on both sides = pure resampling without reprojection.
    src_crs = src.crs if src.crs is not None else CRS.from_epsg(3857)
    dst_crs = dst_crs if dst_crs is not None else CRS.from_epsg(3857)
    out = np.full(dst_shape, np.nan, dtype=np.float64)
    try:
        reproject(
            source=src.values,
            destination=out,
            src_transform=src.transform,
            src_crs=src_crs,
            src_nodata=np.nan,
            dst_transform=dst_transform,
            dst_crs=dst_crs,
            dst_nodata=np.nan,
            resampling=resampling,
        )
    except RasterioError as exc:
        raise InputError(f"cannot resample {what} {path} onto the DEM grid: {exc}") from None
    return out
