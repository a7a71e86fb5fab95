"""Read a DEM file into the solver's :class:`~floodsph.model.terrain.Terrain`.

Steps (each failure is one :class:`~floodsph.errors.InputError` naming the file):

1. read band 1 (GeoTIFF, ESRI ASCII ``.asc`` + ``.prj``, NetCDF variable, or the mosaic of
   several such tiles: :mod:`floodsph.io.mosaic`), nodata -> NaN;
   refuse a grid under 3 x 3 cells and undeclared fill values (:mod:`floodsph.checks.elevation`),
   convert elevations in feet to metres;
2. bring the grid to ground metres (:mod:`floodsph.io.crs`): a projected CRS in feet becomes
   the same projection in metres (the coordinates scaled, no resampling); a geographic DEM, or
   one whose CRS has a point scale factor beyond 1 +- 0.5 % anywhere in the domain (Web
   Mercator away from the equator), is reprojected (bilinear) to the UTM zone of its centre on
   square cells of about its native ground size;
3. crop to ``extent`` (whole cells), given in the DEM file's CRS or ``coordinates_crs``;
4. fill small interior holes (``rasterio.fill.fillnodata``); larger nodata areas are outside
   the model (``valid = False``) and get the nearest valid elevation so bed derivatives stay
   finite;
5. Manning n on the same grid (:mod:`floodsph.io.manning`), taken from the nearest cell in
   the filled holes where the roughness raster has none there;
6. flip to row 0 = south and set the local origin to the lower-left corner of the grid.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyproj
from rasterio.crs import CRS
from rasterio.enums import Resampling
from rasterio.fill import fillnodata
from rasterio.transform import Affine
from rasterio.warp import calculate_default_transform, reproject, transform_bounds
from scipy import ndimage

from floodsph.checks.elevation import check_elevations, vertical_unit
from floodsph.errors import InputError, warn
from floodsph.io.crs import (
    SCALE_TOLERANCE,
    centre_scale,
    in_metres,
    is_ground_metres,
    length_unit,
    scale_range,
)
from floodsph.io.manning import manning_grid
from floodsph.io.mosaic import read_dem_grid, tile_names
from floodsph.io.raster import Grid, GridHeader, crs_label, crs_wkt, parse_crs
from floodsph.io.roughness import N_DEFAULT
from floodsph.model.terrain import Terrain

log = logging.getLogger(__name__)

FILL_HOLES_MAX_CELLS = 100
"""Default size [cells] of the largest interior nodata hole that is filled, not masked."""

MIN_CELLS = 3
"""Fewest rows and columns of a DEM: the bed slopes and curvatures are second-order
differences over three cells (``floodsph.model.terrain``)."""


def load_terrain(
    dem_path,
    *,
    crs=None,
    dem_variable: str | None = None,
    manning=N_DEFAULT,
    landcover=None,
    manning_table=None,
    extent=None,
    coordinates_crs=None,
    fill_holes_max_cells: int = FILL_HOLES_MAX_CELLS,
    warnings: list[str] | None = None,
) -> Terrain:
    """Load a DEM and its roughness as a :class:`Terrain` in a local origin.

    Parameters
    ----------
    dem_path : str, Path or tuple of Path
        GeoTIFF, ESRI ASCII grid or NetCDF file of bed elevation [m], or a tuple of tiles
        mosaicked into one grid (:mod:`floodsph.io.mosaic`).
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
        Crop window in the coordinates' CRS; every cell of the model grid touching it (its
        bounds transformed into the model's CRS) is kept.
    coordinates_crs : str or CRS, optional
        The CRS of ``extent`` and of the scenario's inline coordinates (``[scenario] crs``,
        kept as ``Terrain.coordinates_crs_wkt``); default: the DEM file's own CRS.
    fill_holes_max_cells : int
        Interior nodata regions of at most this many cells are filled by interpolation.
    warnings : list of str, optional
        Receives the warnings (elevations converted from feet, a geographic DEM reprojected,
        the file's CRS overridden; :func:`floodsph.errors.warn`).

    Returns
    -------
    Terrain
        Row 0 = south; ``x0, y0`` = world coordinates of the lower-left grid corner.
    """
    path = tile_names(dem_path) if isinstance(dem_path, tuple) else Path(dem_path)
    grid = read_dem_grid(dem_path, variable=dem_variable, crs=crs, warnings=warnings)
    if not np.any(np.isfinite(grid.values)):
        raise InputError(f"DEM {path}: every cell is nodata")
    check_dem_size(grid.shape, path)
    grid = _elevations_in_metres(grid, path, warnings)
    source_crs = grid.crs
    user_crs = None if coordinates_crs is None else parse_crs(coordinates_crs, "scenario.crs")
    grid, scales = _to_ground_metres(grid, path, warnings)
    if extent is not None:
        grid = _crop(grid, _extent_in(extent, user_crs or source_crs, grid.crs), path)
    elevation, valid = _fill_nodata(grid.values, fill_holes_max_cells, path)
    n = manning_grid(
        grid.transform,
        grid.shape,
        grid.crs,
        valid,
        manning=manning,
        landcover=landcover,
        manning_table=manning_table,
        filled=valid & ~np.isfinite(grid.values),
        warnings=warnings,
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
        crs_wkt=crs_wkt(grid.crs),
        valid=valid[::-1].copy(),
        source_crs_wkt=crs_wkt(source_crs),
        source_scale=scales,
        coordinates_crs_wkt=None if user_crs is None else user_crs.to_wkt(),
    )


def check_dem_size(shape: tuple[int, int], path) -> None:
    """Refuse a DEM of fewer than ``MIN_CELLS`` rows or columns."""
    rows, cols = shape
    if rows < MIN_CELLS or cols < MIN_CELLS:
        raise InputError(
            f"DEM {path}: {cols} x {rows} cells (columns x rows); at least {MIN_CELLS} x "
            f"{MIN_CELLS} are needed (the bed slope and curvature are differences over "
            f"{MIN_CELLS} cells)")


def _elevations_in_metres(grid: Grid, path: str | Path, warnings) -> Grid:
    """Refuse undeclared fill values; convert elevations in feet (or any stated length unit
    pyproj knows) to metres, with a warning; the result has the horizontal CRS only."""
    unit = vertical_unit(grid.crs, grid.units)
    factor = unit.metres
    if factor is None:
        warn(f"DEM {path}: the band's unit {unit.name!r} is not a length unit floodsph knows; "
             "its values are read as metres", warnings)
        factor = 1.0
    check_elevations(grid.values, path, grid.nodata, factor)
    if factor == 1.0:
        return grid
    warn(f"DEM {path}: elevations are in {unit.name} ({factor:.10g} m each); converted to "
         "metres", warnings)
    crs = horizontal_crs(grid.crs) if grid.crs is not None else None
    return Grid(grid.values * factor, grid.transform, crs, "metre", grid.nodata)


def horizontal_crs(crs: CRS) -> CRS:
    """The horizontal part of a compound CRS (the CRS itself otherwise)."""
    full = pyproj.CRS.from_wkt(crs.to_wkt())
    if not full.is_compound:
        return crs
    return CRS.from_wkt(full.sub_crs_list[0].to_wkt())


def _to_ground_metres(grid: Grid, path: str | Path, warnings=None
                      ) -> tuple[Grid, tuple[float, float] | None]:
    """The grid in a projected CRS of ground metres, and the scale factor range found in the
    file's CRS (None when geographic): feet converted, a geographic or distorting CRS
    reprojected to UTM (:mod:`floodsph.io.crs`), each with a warning; other CRSs refused."""
    crs = grid.crs
    if crs is None:
        raise InputError(
            f"DEM {path} has no coordinate reference system; give terrain.crs "
            '(e.g. crs = "EPSG:32632") or add a .prj file'
        )
    if crs.is_geographic:
        cell = metric_cell_size(grid.transform, grid.shape)
        utm = _reproject_to_utm(grid, cell)
        warn(f"DEM {path} is in geographic coordinates ({crs_label(crs.to_wkt())}); "
             f"reprojected to {crs_label(crs_wkt(utm.crs))} with {cell:.3g} m square cells",
             warnings)
        return utm, None
    if not crs.is_projected:
        raise InputError(f"DEM {path}: the CRS must be projected or geographic, got "
                         f"{crs.to_string()}; reproject the DEM first")
    unit, metres = length_unit(crs)
    if not math.isclose(metres, 1.0):
        grid = _in_metres(grid, metres)
        warn(f"DEM {path}: its CRS {crs_label(crs.to_wkt())} is in {unit} ({metres:.10g} m "
             f"each); converted to the same projection in metres (cells of {grid.dx:.6g} m x "
             f"{grid.dy:.6g} m)", warnings)
    scales = scale_range(grid.crs, grid.transform, grid.shape)
    if is_ground_metres(scales):
        return grid, scales
    k = centre_scale(grid.crs, grid.transform, grid.shape)
    cell = float(f"{math.sqrt(grid.dx * grid.dy) / k:.3g}")
    utm = _reproject_to_utm(grid, cell)
    warn(f"DEM {path}: its CRS {crs_label(crs.to_wkt())} has a point scale factor of "
         f"{scales[0]:.4f} to {scales[1]:.4f} over the domain ({k:.4f} at its centre), beyond "
         f"1 +- {SCALE_TOLERANCE:.1%}: its lengths are not ground metres; reprojected to "
         f"{crs_label(crs_wkt(utm.crs))} with {cell:.3g} m square cells", warnings)
    return utm, scales


def _in_metres(grid: Grid, metres: float) -> Grid:
    """A grid in a projected CRS of another length unit, in the same projection in metres:
    the coordinates multiplied by the unit's length (exact, no resampling)."""
    t = grid.transform
    scaled = Affine(t.a * metres, 0.0, t.c * metres, 0.0, t.e * metres, t.f * metres)
    return Grid(grid.values, scaled, in_metres(grid.crs), grid.units, grid.nodata)


def _extent_in(extent, extent_crs, crs: CRS):
    """``extent`` [xmin, ymin, xmax, ymax] given in ``extent_crs``, as bounds in ``crs`` (the
    bounding box of its densified edges); unchanged when the two are the same CRS."""
    try:
        xmin, ymin, xmax, ymax = (float(v) for v in extent)
    except (TypeError, ValueError):
        raise InputError(
            f"terrain.extent: expected [xmin, ymin, xmax, ymax], got {extent!r}"
        ) from None
    source = CRS.from_user_input(extent_crs)
    if source == crs:
        return extent
    return list(transform_bounds(source, crs, xmin, ymin, xmax, ymax, densify_pts=21))


def utm_crs_for(lon: float, lat: float) -> CRS:
    """The WGS 84 / UTM zone of a point (EPSG 326zz north of the equator, 327zz south), picked
    by pyproj (``pyproj.database.query_utm_crs_info``) from the EPSG areas of use.

    Those areas are the regular 6-degree zones; the Norway (32V) and Svalbard (31X-37X)
    exceptions of the military grid are not among them, so a DEM there gets its regular zone,
    whose scale error stays below 0.1 % within the zone. On a zone border (a longitude that
    is a multiple of 6 degrees) the eastern zone is taken.
    """
    from pyproj.aoi import AreaOfInterest
    from pyproj.database import query_utm_crs_info

    lon = min(max(float(lon), -180.0), 180.0)
    lat = min(max(float(lat), -80.0), 84.0)
    hemisphere = "N" if lat >= 0.0 else "S"
    found = [info for info in query_utm_crs_info(
                 datum_name="WGS 84", area_of_interest=AreaOfInterest(lon, lat, lon, lat))
             if info.name.endswith(hemisphere)]
    if not found:
        raise InputError(f"no UTM zone covers longitude {lon:g}, latitude {lat:g}")
    eastern = max(found, key=lambda info: info.area_of_use.west if info.area_of_use else -180.0)
    return CRS.from_epsg(int(eastern.code))


def metric_cell_size(t: Affine, shape: tuple[int, int]) -> float:
    """Square cell size [m] a geographic grid is reprojected to: its native cell size at its
    central latitude on the sphere of radius 6371 km, to 3 significant digits."""
    m_per_deg = math.pi * 6_371_000.0 / 180.0
    lat_c = t.f + 0.5 * t.e * shape[0]
    dx_m = abs(t.a) * m_per_deg * math.cos(math.radians(lat_c))
    dy_m = abs(t.e) * m_per_deg
    return float(f"{math.sqrt(dx_m * dy_m):.3g}")


@dataclass(frozen=True)
class PlannedGrid:
    """The model grid :func:`load_terrain` will build: rows and columns of dx x dy [m] cells."""

    rows: int
    cols: int
    dx: float
    dy: float

    @property
    def cells(self) -> float:
        return float(self.rows) * float(self.cols)

    @property
    def width(self) -> float:
        return self.cols * self.dx

    @property
    def height(self) -> float:
        return self.rows * self.dy


def planned_grid(header: GridHeader, extent=None, extent_crs=None) -> PlannedGrid:
    """The grid :func:`load_terrain` builds from a DEM, estimated from its header alone
    (before the values are read, for the memory estimate).

    A grid that will be reprojected (geographic, or a scale factor beyond the tolerance)
    keeps about its rows and columns on square cells of its ground size, and one in feet its
    rows and columns on cells in metres; neither is cut to ``extent`` (errs high). A grid
    already in ground metres is cut to the cells of ``extent`` when that is in its own CRS
    (``extent_crs`` None or the same).
    """
    rows, cols = header.shape
    t = header.transform
    crs = header.crs
    if crs is not None and crs.is_geographic:
        cell = metric_cell_size(t, header.shape)
        return PlannedGrid(rows, cols, cell, cell)
    if crs is None or not crs.is_projected:
        return PlannedGrid(rows, cols, abs(t.a), abs(t.e))
    _, metres = length_unit(crs)
    dx, dy = abs(t.a) * metres, abs(t.e) * metres
    if not math.isclose(metres, 1.0):
        return PlannedGrid(rows, cols, dx, dy)
    if not is_ground_metres(scale_range(crs, t, header.shape)):
        cell = math.sqrt(dx * dy) / centre_scale(crs, t, header.shape)
        return PlannedGrid(rows, cols, cell, cell)
    same = extent_crs is None or CRS.from_user_input(extent_crs) == crs
    if extent is not None and same:
        r0, r1, c0, c1 = _window(t, header.shape, extent)
        rows, cols = max(r1 - r0, 0), max(c1 - c0, 0)
    return PlannedGrid(rows, cols, dx, dy)


def _window(t: Affine, shape: tuple[int, int], extent) -> tuple[int, int, int, int]:
    """Rows r0:r1 and columns c0:c1 of a north-up grid overlapping ``extent``."""
    xmin, ymin, xmax, ymax = (float(v) for v in extent)
    rows, cols = shape
    c0 = max(int(math.floor((xmin - t.c) / t.a)), 0)
    c1 = min(int(math.ceil((xmax - t.c) / t.a)), cols)
    r0 = max(int(math.floor((t.f - ymax) / -t.e)), 0)
    r1 = min(int(math.ceil((t.f - ymin) / -t.e)), rows)
    return r0, r1, c0, c1


def _reproject_to_utm(grid: Grid, cell: float) -> Grid:
    """Bilinear reprojection of a grid to the UTM zone of its centre on ``cell`` [m] squares."""
    rows, cols = grid.shape
    t = grid.transform
    west, north = t.c, t.f
    east, south = west + t.a * cols, north + t.e * rows
    assert grid.crs is not None  # a DEM without a CRS is refused when it is read
    to_lonlat = pyproj.Transformer.from_crs(pyproj.CRS.from_wkt(grid.crs.to_wkt()),
                                            "EPSG:4326", always_xy=True)
    lon, lat = to_lonlat.transform(0.5 * (west + east), 0.5 * (south + north))
    dst_crs = utm_crs_for(lon, lat)
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
    return Grid(out, dst_t, dst_crs)


def _crop(grid: Grid, extent, path: str | Path) -> Grid:
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
    r0, r1, c0, c1 = _window(t, grid.shape, extent)
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


def _fill_nodata(z: np.ndarray, max_cells: int, path: str | Path
                 ) -> tuple[np.ndarray, np.ndarray]:
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
