"""Manning's n on the DEM grid: a constant, an n raster, or land cover + a class table.

Forms (``docs/scenario-reference.md``, ``[terrain]``; as in AutoRoutePy and HydroMT mapping
tables):

* a number: uniform n [s m^-1/3];
* a raster of n on any grid / CRS: reprojected onto the DEM grid, bilinear resampling;
* a land-cover class raster + a CSV table with columns ``class,manning_n``: classes are
  resampled nearest-neighbour (categories must never be averaged) and mapped through the
  table. ``manning_table = "worldcover"`` selects the table shipped with floodsph for the
  ESA WorldCover classes (``floodsph/data/worldcover_manning.csv``, textbook values).

Every valid DEM cell the DEM file holds must end up with a finite n > 0, else one InputError.
Cells of the interior DEM holes that were filled by interpolation (``floodsph.inputs.dem``) take
the n (or land-cover class) of the nearest cell that has one, with a warning giving the count:
a roughness raster derived from the DEM has the DEM's holes. Values that are Strickler or Chezy
coefficients (n >= 1) are refused and unusually high ones (n > 0.2) warned of
(:mod:`floodsph.io.roughness`). Tables are UTF-8 CSV, with or without a BOM.
"""

from __future__ import annotations

import csv
import io
from importlib import resources
from pathlib import Path

import numpy as np
from rasterio.crs import CRS
from rasterio.enums import Resampling
from rasterio.transform import Affine
from scipy import ndimage

from floodsph.errors import InputError, warn
from floodsph.io.raster import resample_onto
from floodsph.io.roughness import (
    N_DEFAULT,
    N_STRICKLER,
    check_manning_grid,
    check_manning_number,
    strickler_text,
)
from floodsph.io.text import read_text

WORLDCOVER = "worldcover"
"""Name that selects the shipped ESA WorldCover class table."""


def worldcover_table_path() -> Path:
    """Path of the shipped ESA WorldCover -> Manning n table."""
    return Path(str(resources.files("floodsph") / "data" / "worldcover_manning.csv"))


def read_manning_table(path) -> dict[int, float]:
    """Read a ``class,manning_n`` CSV (extra columns such as ``name`` are ignored).

    Raises InputError naming the file for a file that is not UTF-8, a missing column, a
    non-integer class, a duplicate class, an n that is not a finite positive number or one
    that is a Strickler coefficient (n >= 1).
    """
    path = worldcover_table_path() if str(path) == WORLDCOVER else Path(path)
    if not path.is_file():
        raise InputError(f"terrain.manning_table: file not found: {path}")
    table: dict[int, float] = {}
    text = read_text(path, f"manning table {path}")
    with io.StringIO(text, newline="") as fh:
        reader = csv.DictReader(fh)
        fields = [f.strip() for f in (reader.fieldnames or [])]
        if "class" not in fields or "manning_n" not in fields:
            raise InputError(f"manning table {path}: needs columns class,manning_n, found {fields}")
        for line, row in enumerate(reader, start=2):
            row = {k.strip(): (v or "").strip() for k, v in row.items() if k is not None}
            try:
                cls = int(row["class"])
                n = float(row["manning_n"])
            except ValueError:
                raise InputError(
                    f"manning table {path}, line {line}: class must be an integer and "
                    f"manning_n a number, got {row['class']!r}, {row['manning_n']!r}"
                ) from None
            if not (np.isfinite(n) and n > 0):
                raise InputError(f"manning table {path}, line {line}: manning_n must be > 0")
            if n >= N_STRICKLER:
                raise InputError(f"manning table {path}, line {line}: {strickler_text(n)}")
            if cls in table:
                raise InputError(f"manning table {path}, line {line}: class {cls} repeated")
            table[cls] = n
    if not table:
        raise InputError(f"manning table {path}: no rows")
    return table


def manning_grid(
    transform: Affine,
    shape: tuple[int, int],
    crs: CRS,
    valid: np.ndarray,
    *,
    manning=N_DEFAULT,
    landcover=None,
    manning_table=None,
    filled: np.ndarray | None = None,
    warnings: list[str] | None = None,
) -> np.ndarray:
    """Manning's n [s m^-1/3] on a north-up DEM grid.

    Parameters
    ----------
    transform, shape, crs
        The DEM grid (north-up).
    valid : (rows, cols) bool array
        DEM cells inside the model; n is checked there and set to the median elsewhere.
    manning : float or path
        Uniform n, or an n raster (bilinear).
    landcover, manning_table : path, optional
        Class raster (nearest) and its CSV table or ``"worldcover"``; replace ``manning``.
    filled : (rows, cols) bool array, optional
        DEM cells that were nodata in the file and were filled by interpolation; where the
        roughness has no value there, it takes the nearest cell's (:func:`fill_from_nearest`).
    warnings : list of str, optional
        Receives the warnings of n > 0.2 and of the filled cells (:func:`floodsph.errors.warn`).
    """
    if filled is None:
        filled = np.zeros(shape, dtype=bool)
    if landcover is not None:
        if manning_table is None:
            raise InputError(
                "terrain.landcover needs terrain.manning_table "
                '(a CSV with columns class,manning_n, or "worldcover")'
            )
        n = _from_landcover(transform, shape, crs, valid, filled, landcover, manning_table,
                            warnings)
        check_manning_grid(n, valid, f"landcover {landcover} with manning table "
                                     f"{manning_table}", warnings)
    elif isinstance(manning, (str, Path)):
        n = resample_onto(
            manning, transform, shape, crs, resampling=Resampling.bilinear, what="manning raster"
        )
        n = fill_from_nearest(np.where(n > 0, n, np.nan), valid & filled,
                              f"manning raster {manning}", warnings)
        bad = valid & ~(np.isfinite(n) & (n > 0))
        if bad.any():
            lo = np.nanmin(np.where(valid, n, np.nan)) if np.isfinite(n[valid]).any() else np.nan
            raise InputError(
                f"manning raster {manning}: {int(bad.sum())} DEM cells get no value or n <= 0 "
                f"(minimum there {lo}); n must be > 0 over the whole DEM"
            )
        check_manning_grid(n, valid, f"manning raster {manning}", warnings)
    else:
        try:
            value = float(manning)
        except (TypeError, ValueError):
            raise InputError(
                f"terrain.manning: expected a number or a raster path, got {manning!r}"
            ) from None
        if not (np.isfinite(value) and value > 0):
            raise InputError(f"terrain.manning must be > 0, got {manning!r}")
        check_manning_number(value, "terrain.manning", warnings)
        return np.full(shape, value, dtype=np.float64)
    fallback = float(np.median(n[valid])) if valid.any() else N_DEFAULT
    return np.where(valid, n, fallback)


def fill_from_nearest(values: np.ndarray, filled: np.ndarray, what: str,
                      warnings: list[str] | None) -> np.ndarray:
    """Give the ``filled`` cells that have no value (NaN) the value of the nearest cell that
    has one (Euclidean distance in cells, ``scipy.ndimage.distance_transform_edt``), and warn
    with their count; other cells are returned as they are."""
    missing = filled & ~np.isfinite(values)
    if not missing.any() or not np.isfinite(values).any():
        return values
    _, (ri, ci) = ndimage.distance_transform_edt(~np.isfinite(values), return_indices=True)
    out = values.copy()
    out[missing] = values[ri[missing], ci[missing]]
    warn(f"{what}: {int(missing.sum())} cells of the DEM's filled nodata holes have no value; "
         "they take the value of the nearest cell that has one", warnings)
    return out


def _from_landcover(transform, shape, crs, valid, filled, landcover, manning_table,
                    warnings) -> np.ndarray:
    """Map nearest-resampled land-cover classes through the class table."""
    table = read_manning_table(manning_table)
    classes = resample_onto(
        landcover, transform, shape, crs, resampling=Resampling.nearest, what="landcover"
    )
    classes = fill_from_nearest(classes, valid & filled, f"landcover {landcover}", warnings)
    inside = classes[valid]
    if np.isnan(inside).any():
        raise InputError(
            f"landcover {landcover}: {int(np.isnan(inside).sum())} DEM cells have no land-cover "
            "class (nodata or outside the land-cover raster)"
        )
    present = np.unique(inside).astype(np.int64)
    unknown = [int(c) for c in present if int(c) not in table]
    if unknown:
        table_name = worldcover_table_path() if str(manning_table) == WORLDCOVER else manning_table
        raise InputError(
            f"landcover {landcover}: class value(s) {unknown} are not in the manning table "
            f"{table_name}"
        )
    n = np.full(shape, np.nan, dtype=np.float64)
    codes = np.where(np.isfinite(classes), classes, -1).astype(np.int64)
    for cls, value in table.items():
        n[codes == cls] = value
    return n
