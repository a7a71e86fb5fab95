"""``ensemble_maps.nc``: the ensemble's maps as one CF-1.8 NetCDF file.

The same conventions as the run's ``flood_maps.nc`` (``floodsph.output.cf``): ``y`` north to
south and ``x`` coordinates in the DEM CRS (no ``_FillValue`` on any coordinate variable), a
``crs`` grid-mapping variable from pyproj's ``CRS.to_cf()``, float32 data with ``_FillValue =
NaN`` (outside the DEM), zlib level 4. No CF standard name describes a probability or a
quantile over members, so the maps carry ``long_name`` and ``units`` only. The stacked maps
have one more dimension each, with its coordinate variable:

=================  =============================  ======  ==================================
variable           dimensions                     units   content
=================  =============================  ======  ==================================
``p_depth_gt``     (threshold, y, x)              1       P(max depth > threshold)
``max_depth_q``    (quantile, y, x)               m       quantile of max depth
``max_speed_q``    (quantile, y, x)               m s-1   quantile of max speed
``arrival_time_q`` (quantile, y, x)               s       quantile of arrival time (wet
                                                          members; NaN if fewer than half)
``p_hazard_uk_ge`` (hazard_uk_class, y, x)        1       P(UK hazard class >= k), k = 1..4
=================  =============================  ======  ==================================

``threshold`` is in m, ``quantile`` a probability (0..1), ``hazard_uk_class`` the class k.
Global attributes add the resolved ensemble (JSON) and the number of completed members.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from floodsph.ensemble.aggregate import UK_CLASSES, EnsembleMaps
from floodsph.io.atomic_files import atomic_path

#: variable -> (dimension, long name, units)
VARIABLES = {
    "p_depth_gt": ("threshold", "probability that the maximum depth exceeds the threshold",
                   "1"),
    "max_depth_q": ("quantile", "maximum water depth, quantile over the members", "m"),
    "max_speed_q": ("quantile", "maximum depth-averaged speed, quantile over the members",
                    "m s-1"),
    "arrival_time_q": ("quantile", "arrival time, quantile over the members that wet the "
                                   "cell (NaN where fewer than half do)", "s"),
    "p_hazard_uk_ge": ("hazard_uk_class", "probability of the UK hazard rating class or a "
                                          "worse one", "1"),
}


def write_ensemble_netcdf(path, maps: EnsembleMaps, grid, *, ensemble: dict,
                          scenario: dict, wet_threshold: float) -> Path:
    """Write ``maps`` (south-up) on ``grid`` to ``path``; returns the path."""
    import xarray as xr

    from floodsph.output.cf import (
        CLASS_DTYPE,
        global_attrs,
        grid_coords,
        grid_mapping_attrs,
        no_fill,
    )

    path = Path(path)
    coords = grid_coords(grid)
    coords["threshold"] = xr.Variable("threshold", np.asarray(maps.thresholds, np.float64),
                                      {"long_name": "maximum-depth threshold", "units": "m"})
    coords["quantile"] = xr.Variable("quantile", np.asarray(maps.quantiles, np.float64),
                                     {"long_name": "quantile probability over the members",
                                      "units": "1"})
    coords["hazard_uk_class"] = xr.Variable(
        "hazard_uk_class", np.asarray(UK_CLASSES, CLASS_DTYPE),
        {"long_name": "UK flood hazard rating class (Defra/EA FD2320-FD2321)", "units": "1"})
    crs = grid_mapping_attrs(grid)
    data_vars, encoding = {}, no_fill(coords)
    if crs is not None:
        data_vars["crs"] = xr.Variable((), np.int32(0), crs)
        encoding["crs"] = {"dtype": "int32"}
    chunks = (1, min(grid.ny, 256), min(grid.nx, 256))
    for name, (dim, long_name, units) in VARIABLES.items():
        attrs: dict[str, Any] = {"long_name": long_name, "units": units}
        if crs is not None:
            attrs["grid_mapping"] = "crs"
        if units == "1":
            attrs["valid_range"] = np.array([0.0, 1.0], np.float32)
        data = np.asarray(getattr(maps, name), dtype=np.float32)[:, ::-1, :]
        data_vars[name] = xr.Variable((dim, "y", "x"), data, attrs)
        encoding[name] = {"dtype": "float32", "_FillValue": np.float32(np.nan), "zlib": True,
                          "complevel": 4, "chunksizes": chunks}
    attrs = dict[str, Any](global_attrs("floodsph ensemble maps", scenario, wet_threshold))
    attrs["ensemble"] = json.dumps(ensemble, sort_keys=True)
    attrs["members_completed"] = int(maps.members)
    ds = xr.Dataset(data_vars, coords=coords, attrs=attrs)
    with atomic_path(path) as part:
        ds.to_netcdf(part, engine="netcdf4", format="NETCDF4", encoding=encoding)
    return path
