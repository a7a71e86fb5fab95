"""Read a DEM file into the solver's :class:`~floodsph.terrain.Terrain`.

Steps (each failure is one :class:`~floodsph.errors.InputError` naming the file):

1. read band 1 (GeoTIFF, ESRI ASCII ``.asc`` + ``.prj``, NetCDF variable), nodata -> NaN;
2. check the CRS: projected with metre units; a geographic DEM is reprojected (bilinear) to
   the UTM zone of its centre on square cells of about its native size;
3. crop to ``extent`` (whole cells);
4. fill small interior holes (``rasterio.fill.fillnodata``); larger nodata areas are outside
   the model (``valid = False``) and get the nearest valid elevation so bed derivatives stay
   finite;
5. Manning n on the same grid (:mod:`floodsph.io.manning`);
6. flip to row 0 = south and set the local origin to the lower-left corner of the grid.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
from rasterio.crs import CRS
from rasterio.enums import Resampling
from rasterio.fill import fillnodata
from rasterio.transform import Affine
from rasterio.warp import calculate_default_transform, reproject
from scipy import ndimage

from floodsph.errors import InputError
from floodsph.io.manning import manning_grid
from floodsph.io.raster import Grid, read_grid
from floodsph.terrain import Terrain

log = logging.getLogger(__name__)

FILL_HOLES_MAX_CELLS = 100
"""Default size [cells] of the largest interior nodata hole that is filled, not masked."""


def load_terrain(
    dem_path,
    *,
    crs=None,
    dem_variable: str | None = None,
    manning=0.035,
    landcover=None,
    manning_table=None,
    extent=None,
    fill_holes_max_cells: int = FILL_HOLES_MAX_CELLS,
) -> Terrain:
    """Load a DEM and its roughness as a :class:`Terrain` in a local origin.

    Parameters
    ----------
    dem_path : str or Path
        GeoTIFF, ESRI ASCII grid or NetCDF file of bed elevation [m].
    crs : str, optional
        CRS for a file that carries none (``"EPSG:27572"``).
    dem_variable : str, optional
        Variable name inside a NetCDF file.
    manning : float or path
        Uniform Manning n [s m^-1/3], or a raster of n on any grid (bilinear resampling).
    landcover, manning_table : path, optional
        A land-cover class raster and a CSV ``class,manning_n`` (or ``"worldcover"``), used
        instead of ``manning``.
    extent : [xmin, ymin, xmax, ymax], optional
        Crop window in the DEM's projected CRS [m] (after any reprojection); every cell
        touching it is kept.
    fill_holes_max_cells : int
        Interior nodata regions of at most this many cells are filled by interpolation.

    Returns
    -------
    Terrain
        Row 0 = south; ``x0, y0`` = world coordinates of the lower-left grid corner.
    """
    path = Path(dem_path)
    grid = read_grid(path, variable=dem_variable, crs=crs, what="DEM")
    if not np.any(np.isfinite(grid.values)):
        raise InputError(f"DEM {path}: every cell is nodata")
    grid = _ensure_projected_metres(grid, path)
    if extent is not None:
        grid = _crop(grid, extent, path)
    elevation, valid = _fill_nodata(grid.values, fill_holes_max_cells, path)
    n = manning_grid(
        grid.transform,
        grid.shape,
        grid.crs,
        valid,
        manning=manning,
        landcover=landcover,
        manning_table=manning_table,
    )
    rows = grid.shape[0]
    t = grid.transform
    return Terrain(
        elevation=elevation[::-1].copy(),
        dx=t.a,
        dy=-t.e,
        manning=n[::-1].copy(),
        x0=t.c,
        y0=t.f + t.e * rows,
        crs_wkt=grid.crs.to_wkt(),
        valid=valid[::-1].copy(),
    )


def _ensure_projected_metres(grid: Grid, path: Path) -> Grid:
    """Accept a projected metre CRS; reproject a geographic one to UTM; refuse the rest."""
    crs = grid.crs
    if crs is None:
        raise InputError(
            f"DEM {path} has no coordinate reference system; give terrain.crs "
            '(e.g. crs = "EPSG:32632") or add a .prj file'
        )
    if crs.is_geographic:
        return _reproject_to_utm(grid, path)
    unit, factor = crs.linear_units_factor
    if not crs.is_projected or not math.isclose(factor, 1.0):
        raise InputError(
            f"DEM {path}: the CRS must be projected in metres, got {crs.to_string()} "
            f"(units: {unit}); reproject the DEM first"
        )
    return grid


def utm_crs_for(lon: float, lat: float) -> CRS:
    """WGS 84 / UTM zone of a point: EPSG 326zz (north) or 327zz (south), zz = 1..60.

    zone = floor((lon + 180) / 6) + 1 (the Norway/Svalbard exceptions are not applied).
    """
    zone = min(max(int(math.floor((lon + 180.0) / 6.0)) + 1, 1), 60)
    return CRS.from_epsg((32600 if lat >= 0.0 else 32700) + zone)


def _reproject_to_utm(grid: Grid, path: Path) -> Grid:
    """Bilinear reprojection of a geographic DEM to the UTM zone of its centre."""
    rows, cols = grid.shape
    t = grid.transform
    west, north = t.c, t.f
    east, south = west + t.a * cols, north + t.e * rows
    lon_c, lat_c = 0.5 * (west + east), 0.5 * (south + north)
    dst_crs = utm_crs_for(lon_c, lat_c)
    # Native cell size in metres on the sphere of radius 6371 km, made square.
    m_per_deg = math.pi * 6_371_000.0 / 180.0
    dx_m = grid.dx * m_per_deg * math.cos(math.radians(lat_c))
    dy_m = grid.dy * m_per_deg
    cell = float(f"{math.sqrt(dx_m * dy_m):.3g}")
    dst_t, w, h = calculate_default_transform(
        grid.crs, dst_crs, cols, rows, west, south, east, north, resolution=cell
    )
    out = np.full((h, w), np.nan, dtype=np.float64)
    reproject(
        source=grid.values,
        destination=out,
        src_transform=t,
        src_crs=grid.crs,
        src_nodata=np.nan,
        dst_transform=dst_t,
        dst_crs=dst_crs,
        dst_nodata=np.nan,
        resampling=Resampling.bilinear,
        tolerance=0.0,  # exact transformer, not GDAL's 0.125-pixel approximation
    )
    log.warning(
        "DEM %s is in geographic coordinates (%s); reprojected to %s (EPSG:%d) "
        "with %.3g m square cells",
        path,
        grid.crs.to_string(),
        dst_crs.to_wkt().split('"')[1],
        dst_crs.to_epsg(),
        cell,
    )
    return Grid(out, dst_t, dst_crs)


def _crop(grid: Grid, extent, path: Path) -> Grid:
    """Keep the whole cells that overlap ``[xmin, ymin, xmax, ymax]``."""
    try:
        xmin, ymin, xmax, ymax = (float(v) for v in extent)
    except (TypeError, ValueError):
        raise InputError(
            f"terrain.extent: expected [xmin, ymin, xmax, ymax], got {extent!r}"
        ) from None
    if not (xmin < xmax and ymin < ymax):
        raise InputError(f"terrain.extent: need xmin < xmax and ymin < ymax, got {extent!r}")
    t = grid.transform
    rows, cols = grid.shape
    c0 = max(int(math.floor((xmin - t.c) / t.a)), 0)
    c1 = min(int(math.ceil((xmax - t.c) / t.a)), cols)
    r0 = max(int(math.floor((t.f - ymax) / -t.e)), 0)
    r1 = min(int(math.ceil((t.f - ymin) / -t.e)), rows)
    if c1 <= c0 or r1 <= r0:
        bounds = (t.c, t.f + t.e * rows, t.c + t.a * cols, t.f)
        raise InputError(
            f"terrain.extent {list(extent)} does not overlap the DEM {path} "
            f"(bounds {[round(b, 3) for b in bounds]})"
        )
    if c1 - c0 < 3 or r1 - r0 < 3:
        raise InputError(f"terrain.extent {list(extent)} keeps fewer than 3x3 cells of {path}")
    values = grid.values[r0:r1, c0:c1].copy()
    if not np.any(np.isfinite(values)):
        raise InputError(f"terrain.extent {list(extent)}: every DEM cell in it is nodata")
    new_t = Affine(t.a, 0.0, t.c + c0 * t.a, 0.0, t.e, t.f + r0 * t.e)
    return Grid(values, new_t, grid.crs)


def _fill_nodata(z: np.ndarray, max_cells: int, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Fill small interior holes; mark the other nodata invalid and give it finite values.

    Holes are the 8-connected nodata regions; one of at most ``max_cells`` cells that does
    not touch the grid border is interpolated by ``rasterio.fill.fillnodata`` (inverse
    distance weighting from the hole's rim). The remaining nodata cells get the elevation
    of the nearest valid cell (``scipy.ndimage.distance_transform_edt``) and ``valid=False``.
    """
    nodata = ~np.isfinite(z)
    if not nodata.any():
        return z, np.ones(z.shape, dtype=bool)
    labels, count = ndimage.label(nodata, structure=np.ones((3, 3), dtype=bool))
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    border = np.unique(np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]]))
    small = sizes <= max_cells
    small[0] = False
    small[border] = False
    fill = small[labels]
    z = z.copy()
    if fill.any():
        filled = fillnodata(
            np.where(nodata, 0.0, z).astype(np.float32),
            mask=(~nodata).astype(np.uint8),
            max_search_distance=float(max_cells + 1),
        )
        z[fill] = filled[fill]
        log.info(
            "DEM %s: filled %d nodata cells in %d small holes",
            path,
            fill.sum(),
            int(np.count_nonzero(small)),
        )
    valid = np.isfinite(z)
    if not valid.all():
        _, (ri, ci) = ndimage.distance_transform_edt(~valid, return_indices=True)
        z = z[ri, ci]
    return z, valid
