"""CF-1.8 metadata shared by the NetCDF writers (maps, snapshots, ensemble maps).

Conventions followed (CF conventions 1.8; standard names from the CF standard name table,
version 93 and later):

* ``x`` / ``y`` coordinate variables (``projection_x_coordinate`` /
  ``projection_y_coordinate``, ``units = "m"``) hold the cell centres and have no
  ``_FillValue`` (CF 2.5.1: coordinate variables must not have missing values);
* the grid mapping (CF 5.6) is pyproj's ``CRS.to_cf()`` of the DEM CRS: ``grid_mapping_name``
  and its parameters for every projection CF names, and ``crs_wkt`` always. GDAL's
  ``spatial_ref`` and ``GeoTransform`` are added so that GDAL reads the georeference without
  guessing. A grid without a CRS (synthetic terrain) has no grid-mapping variable;
* ``standard_name`` only where a CF standard name means exactly what the map holds
  (:data:`STANDARD_NAMES`); the other maps carry ``long_name`` and ``units`` only;
* class maps (hazard) are flag variables (CF 3.5) of type ``byte``: ``flag_values`` 0, 1,
  ... with one ``flag_meanings`` word per value (0 = dry);
* the maxima, the duration and the hazard classes (``cell_methods = "time: ..."``) refer to
  a scalar ``time`` coordinate whose bounds are the period they cover (0 to the last update);
* ``time`` is ``seconds since`` the scenario's ``[scenario] start`` in UTC
  (:func:`time_attrs`); a scenario without one has its start placed at the fixed date
  :data:`NO_START`, and the ``comment`` of ``time`` says that date means nothing. Arrival
  time, time of the maximum and duration are durations in ``s`` from the same start.
"""

from __future__ import annotations

import json
import re
from datetime import UTC, datetime

import numpy as np

from floodsph._version import __version__

CONVENTIONS = "CF-1.8"
REFERENCES = ("Vacondio, Rogers, Stansby, Mignosa & Feldman (2013), Adv. Water Resour. 58, "
              "10-23; hazard: Defra/EA FD2320-FD2321; AIDR Guideline 7-3 (2017)")

NO_START = datetime(1970, 1, 1, tzinfo=UTC)
"""The instant given to t = 0 when the scenario has no ``[scenario] start``: a placeholder
with no meaning (the times are then seconds of simulated time)."""


def time_units(start: datetime | None) -> str:
    """CF ``units`` of the ``time`` coordinate: ``seconds since <start in UTC>``."""
    instant = (start or NO_START).astimezone(UTC)
    return f"seconds since {instant.strftime('%Y-%m-%d %H:%M:%S')}"


def time_attrs(start: datetime | None) -> dict:
    """Attributes of the ``time`` coordinate: seconds since the scenario's start (UTC), or
    since :data:`NO_START` with a comment saying it has no meaning."""
    if start is None:
        comment = ("time since the start of the run; the scenario gives no calendar start "
                   "([scenario] start), so the start of the run is placed at the fixed "
                   "reference 1970-01-01 00:00:00 UTC, which carries no meaning: read the "
                   "values as seconds of simulated time")
    else:
        comment = (f"time since the start of the run, {start.isoformat()} "
                   f"([scenario] start), in UTC")
    return {"standard_name": "time", "long_name": "simulated time", "units": time_units(start),
            "calendar": "standard", "axis": "T", "comment": comment}


STANDARD_NAMES = {
    "max_depth": "flood_water_thickness",
    "max_speed": "flood_water_speed",
    "max_level": "water_surface_height_above_reference_datum",
    "arrival_time": "time_when_flood_water_rises_above_threshold",
    "time_of_max_depth": "time_of_maximum_flood_depth",
    "depth": "flood_water_thickness",
    "level": "water_surface_height_above_reference_datum",
}
"""Variable -> CF standard name, where one fits exactly. ``duration`` (total wet time, not
first-wet to last-dry), ``max_unit_discharge``, the hazard classes and the velocity
components along the projection axes (grid east/north, not true east/north) have none."""

COMMENTS = {
    "max_level": "reference datum: the vertical datum of the DEM (water level = depth + bed)",
    "level": "reference datum: the vertical datum of the DEM (water level = depth + bed); "
             "NaN where the depth is at or below the wet threshold",
    "duration": "sum of the intervals during which the cell was wet (depth above the wet "
                "threshold)",
}

THRESHOLD = "wet_threshold"
"""Scalar coordinate holding the wet threshold of the threshold standard names."""
THRESHOLD_ATTRS = {"standard_name": "flood_water_thickness",
                   "long_name": "depth above which a cell is wet", "units": "m"}
USES_THRESHOLD = ("arrival_time",)

CLASS_DTYPE = np.int8
"""NetCDF type of the class maps (uint8 in memory and in the GeoTIFFs): CF-1.8 lists the
signed ``byte`` among its types but not the unsigned ones (added in CF-1.9)."""


def grid_mapping_attrs(grid) -> dict | None:
    """Attributes of the ``crs`` grid-mapping variable of a grid, None without a CRS."""
    from pyproj import CRS

    if not grid.crs_wkt:
        return None
    t = grid.north_up_transform()
    attrs = {k: list(v) if isinstance(v, tuple) else v
             for k, v in CRS.from_wkt(grid.crs_wkt).to_cf().items()}
    attrs["spatial_ref"] = attrs["crs_wkt"]
    attrs["GeoTransform"] = " ".join(str(v) for v in (t.c, t.a, t.b, t.f, t.d, t.e))
    return attrs


COORD_ATTRS = {
    "x": {"standard_name": "projection_x_coordinate",
          "long_name": "x coordinate of the cell centre", "units": "m", "axis": "X"},
    "y": {"standard_name": "projection_y_coordinate",
          "long_name": "y coordinate of the cell centre", "units": "m", "axis": "Y"},
}


def grid_coords(grid) -> dict:
    """The ``x`` and ``y`` coordinate variables as xarray Variables (y north to south)."""
    import xarray as xr

    xw, yw = grid.world_centres()
    return {"x": xr.Variable("x", xw, COORD_ATTRS["x"]),
            "y": xr.Variable("y", yw, COORD_ATTRS["y"])}


def no_fill(names) -> dict:
    """xarray encodings that write the variables ``names`` without ``_FillValue``."""
    return {name: {"_FillValue": None} for name in names}


def flag_meanings(names) -> str:
    """CF ``flag_meanings``: class names as blank-separated words (underscores inside)."""
    return " ".join(re.sub(r"[^A-Za-z0-9]+", "_", n).strip("_").lower() for n in names)


def flag_attrs(names) -> dict:
    """``flag_values`` 0..n-1 (uint8, as the class maps in memory; the NetCDF writers store
    both as :data:`CLASS_DTYPE`) and ``flag_meanings`` of the class names (index = value)."""
    return {"flag_values": np.arange(len(names), dtype=np.uint8),
            "flag_meanings": flag_meanings(names)}


def variable_attrs(name: str, long_name: str, units: str, *, cell_methods: str | None = None,
                   grid_mapping: bool = True) -> dict:
    """``long_name``, ``units``, the standard name and comment where there is one,
    ``cell_methods`` and ``grid_mapping``."""
    attrs = {"long_name": long_name, "units": units}
    if name in STANDARD_NAMES:
        attrs["standard_name"] = STANDARD_NAMES[name]
    if name in COMMENTS:
        attrs["comment"] = COMMENTS[name]
    if cell_methods:
        attrs["cell_methods"] = cell_methods
    if grid_mapping:
        attrs["grid_mapping"] = "crs"
    return attrs


def global_attrs(title: str, scenario: dict | None, wet_threshold: float) -> dict:
    """The global attributes shared by the map and snapshot files."""
    stamp = datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
    return {
        "Conventions": CONVENTIONS,
        "title": title,
        "source": f"floodsph {__version__}",
        "history": f"{stamp} written by floodsph {__version__}",
        "references": REFERENCES,
        "wet_threshold_m": float(wet_threshold),
        "scenario": json.dumps(scenario or {}, sort_keys=True, default=str),
    }
