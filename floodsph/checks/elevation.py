"""DEM values no terrain holds, and elevations stated in feet.

A DEM whose voids hold a fill value without declaring it as nodata is read as terrain: a
cliff of 3.4e38 m that the solver turns into speeds of 1e18 m/s. Such cells are refused
(:func:`check_elevations`): any value beyond ``ELEVATION_LIMIT_M`` and the common fills
within it (``FILL_VALUES``). The fix is the file's nodata tag, which the message spells out.

Elevations are converted to metres when the file says they are in another unit
(:func:`vertical_unit`): the vertical axis of a compound CRS (e.g. ``EPSG:26910+6360``,
NAVD88 height in US survey feet), else the band's unit (GDAL unit type).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pyproj

from floodsph.errors import InputError

ELEVATION_LIMIT_M = 1.0e4
"""|z| above this [m] is no terrain: the land tops out at 8,849 m (Everest) and the deepest sea
floor near any flood domain is far above -10,000 m (only ocean trenches go deeper)."""

FILL_VALUES = (-9999.0,)
"""Fill values within the limit that GIS tools write into voids (ESRI ASCII grids, many
GeoTIFF exports); no real cell holds exactly -9999 m."""

METRE_NAMES = ("m", "metre", "metres", "meter", "meters", "m asl", "m a.s.l.", "masl")
FOOT_NAMES = ("ft", "foot", "feet", "international foot")
US_FOOT_NAMES = ("us survey foot", "us_survey_foot", "ftus", "us-ft", "foot_us", "survey foot")
US_SURVEY_FOOT_M = 1200.0 / 3937.0
"""The US survey foot [m] (exactly 1200/3937 m); the international foot is 0.3048 m."""


@dataclass(frozen=True)
class VerticalUnit:
    """The unit of a DEM's elevations: its name and its length [m] (None: not a known length)."""

    name: str
    metres: float | None


def vertical_unit(crs, band_units: str | None) -> VerticalUnit:
    """The unit of a DEM's elevations.

    From the up axis of the CRS when it has one (pyproj gives its exact conversion factor),
    else from the band's unit name; metres when neither says anything.
    """
    if crs is not None:
        for axis in pyproj.CRS.from_wkt(crs.to_wkt()).axis_info:
            if axis.direction == "up":
                return VerticalUnit(axis.unit_name, float(axis.unit_conversion_factor))
    if not band_units:
        return VerticalUnit("metre", 1.0)
    name = band_units.strip().lower()
    if name in METRE_NAMES:
        return VerticalUnit(band_units, 1.0)
    if name in FOOT_NAMES:
        return VerticalUnit(band_units, 0.3048)
    if name in US_FOOT_NAMES:
        return VerticalUnit(band_units, US_SURVEY_FOOT_M)
    return VerticalUnit(band_units, None)


def value_text(value: float) -> str:
    """A cell value as the file's tools show it: the shortest float32 form when the value is a
    float32 (-1e+38 rather than -9.9999997e+37), else 10 significant digits."""
    single = np.float32(value)
    if float(single) == value:
        return f"{float(str(single)):.8g}"
    return f"{value:.10g}"


def check_elevations(values: np.ndarray, path, nodata: float | None,
                     metres_per_unit: float = 1.0) -> None:
    """Refuse DEM cells (NaN = declared nodata) that hold a fill value, not terrain.

    ``values`` are in the file's unit (``metres_per_unit`` m each); the message names the file,
    the most frequent bad value, the number of cells and how to declare it as nodata.
    """
    finite = values[np.isfinite(values)]
    limit = ELEVATION_LIMIT_M / metres_per_unit
    bad = finite[(np.abs(finite) > limit) | np.isin(finite, FILL_VALUES)]
    if bad.size == 0:
        return
    distinct, counts = np.unique(bad, return_counts=True)
    value = value_text(float(distinct[np.argmax(counts)]))
    which = (f"{bad.size} cells hold {value}" if distinct.size == 1 else
             f"{bad.size} cells hold values no terrain has, most often {value} "
             f"({int(counts.max())} cells)")
    declared = "no nodata value" if nodata is None else f"nodata = {nodata:.8g}"
    raise InputError(
        f"DEM {path}: {which}, a nodata fill (|z| beyond {ELEVATION_LIMIT_M:g} m or "
        f"{FILL_VALUES[0]:g}), but the file declares {declared}; declare the fill as nodata "
        f"(e.g. gdal_edit.py -a_nodata {value} {path}, NODATA_value in an .asc header, "
        "_FillValue in NetCDF) or correct those cells")
