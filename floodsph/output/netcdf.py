"""NetCDF writers: the envelope maps (``flood_maps.nc``) and map snapshots (``snapshots.nc``).

Both follow CF-1.8 as set out in :mod:`floodsph.output.cf`: dimensions ``y`` (north to south,
like the GeoTIFFs) and ``x`` with coordinate variables in the DEM CRS, a scalar ``crs``
grid-mapping variable (when the DEM has a CRS), ``long_name`` / ``units`` / ``grid_mapping``
on every data variable and a CF ``standard_name`` where one fits. In ``flood_maps.nc`` maxima
have ``cell_methods = "time: maximum"``, the arrival time refers to the scalar coordinate
``wet_threshold`` [m], the maxima's period is the scalar ``time`` with its bounds, and class
maps are flag variables (CF ``byte``, 0 = dry). Float maps are
float32, zlib level 4, ``_FillValue = NaN`` (never wet or outside the DEM).

Global attributes: ``Conventions``, ``title``, ``source = "floodsph <version>"``,
``history``, ``references``, the wet threshold and the resolved scenario as a JSON string.
"""

from __future__ import annotations

import os
from datetime import datetime
from pathlib import Path

import numpy as np

from floodsph.io.atomic_files import atomic_path
from floodsph.output.cf import (
    CLASS_DTYPE,
    COORD_ATTRS,
    THRESHOLD,
    THRESHOLD_ATTRS,
    USES_THRESHOLD,
    flag_attrs,
    global_attrs,
    grid_coords,
    grid_mapping_attrs,
    no_fill,
    time_attrs,
    variable_attrs,
)


def write_flood_maps(path, maps: dict, info: dict, grid, *, class_names: dict,
                     scenario: dict | None = None, wet_threshold: float = 0.01,
                     period_s: float | None = None, title: str = "floodsph flood maps",
                     start: datetime | None = None) -> Path:
    """Write the envelope maps as one CF-1.8 NetCDF file: :func:`flood_maps_dataset` with
    float maps as float32, zlib level 4, ``_FillValue = NaN``, and class maps as CF ``byte``.

    Parameters
    ----------
    path : path-like
        Output file (``flood_maps.nc``).
    maps, info, grid, class_names, scenario, wet_threshold, period_s, title, start
        As :func:`flood_maps_dataset`.
    """
    path = Path(path)
    ds = flood_maps_dataset(maps, info, grid, class_names=class_names, scenario=scenario,
                            wet_threshold=wet_threshold, period_s=period_s, title=title,
                            start=start)
    chunks = (min(grid.ny, 256), min(grid.nx, 256))
    encoding = no_fill([*ds.coords, *(n for n in ("time_bounds",) if n in ds)])
    if "crs" in ds:
        encoding["crs"] = {"dtype": "int32"}
    for name in maps:
        if "flag_values" in ds[name].attrs:
            encoding[name] = {"_FillValue": None, "dtype": CLASS_DTYPE}
            ds[name].attrs["flag_values"] = ds[name].attrs["flag_values"].astype(CLASS_DTYPE)
        else:
            encoding[name] = {"_FillValue": np.float32(np.nan)}
        encoding[name].update(zlib=True, complevel=4, chunksizes=chunks)
    with atomic_path(path) as part:
        ds.to_netcdf(part, engine="netcdf4", format="NETCDF4", encoding=encoding)
    return path


def flood_maps_dataset(maps: dict, info: dict, grid, *, class_names: dict,
                       scenario: dict | None = None, wet_threshold: float = 0.01,
                       period_s: float | None = None, title: str = "floodsph flood maps",
                       start: datetime | None = None):
    """The envelope maps as an ``xarray.Dataset`` laid out and described as ``flood_maps.nc``
    (CF-1.8, :mod:`floodsph.output.cf`), before encoding: ``time`` in seconds.

    Parameters
    ----------
    maps : dict name -> (ny, nx) array
        South-up maps (row 0 = south); uint8 arrays are class maps (flag variables, uint8;
        :func:`write_flood_maps` stores them as CF ``byte``).
    info : dict name -> (long_name, units, cell_methods or None)
        Metadata per map (:data:`floodsph.output.envelopes.MAPS`).
    grid : OutputGrid
        Georeference of the maps.
    class_names : dict name -> sequence of str
        Class names (index = value) of each class map.
    wet_threshold : float
        Depth [m] above which a cell is wet: the scalar coordinate ``wet_threshold``.
    period_s : float, optional
        Simulated time [s] of the last update of the maps: the scalar coordinate ``time``
        with bounds [0, period_s], the interval of the maps' ``cell_methods``.
    scenario, title
        Recorded in the global attributes.
    start : datetime, optional
        The calendar instant of t = 0 (``[scenario] start``): ``time`` is seconds since it.
    """
    import xarray as xr

    crs = grid_mapping_attrs(grid)
    coords = grid_coords(grid)
    coords[THRESHOLD] = xr.Variable((), np.float64(wet_threshold), THRESHOLD_ATTRS)
    data_vars = {}
    if period_s is not None:
        coords["time"] = xr.Variable((), np.float64(period_s),
                                     dict(time_attrs(start), bounds="time_bounds"))
        data_vars["time_bounds"] = xr.Variable("nv", np.array([0.0, period_s]))
    if crs is not None:
        data_vars["crs"] = xr.Variable((), np.int32(0), crs)
    for name, arr in maps.items():
        long_name, units, cell_methods = info[name]
        attrs = variable_attrs(name, long_name, units, cell_methods=cell_methods,
                               grid_mapping=crs is not None)
        data: np.ndarray
        if np.asarray(arr).dtype == np.uint8:
            attrs.update(flag_attrs(class_names[name]))
            data = np.asarray(arr, dtype=np.uint8)[::-1]
        else:
            data = np.asarray(arr, dtype=np.float32)[::-1]
        data_vars[name] = xr.Variable(("y", "x"), data, attrs)
        names = [THRESHOLD] if name in USES_THRESHOLD else []
        if cell_methods and period_s is not None:
            names.append("time")
        data_vars[name].encoding["coordinates"] = " ".join(names) or None
    for name in ("crs", "time_bounds"):
        if name in data_vars:
            data_vars[name].encoding["coordinates"] = None
    return xr.Dataset(data_vars, coords=coords, attrs=global_attrs(title, scenario, wet_threshold))


SNAPSHOT_VARIABLES = {
    "depth": ("water depth", "m"),
    "u": ("depth-averaged velocity, component along the projection x axis (grid east)",
          "m s-1"),
    "v": ("depth-averaged velocity, component along the projection y axis (grid north)",
          "m s-1"),
    "level": ("water-surface elevation (depth + bed), where wet", "m"),
}
"""Snapshot variable -> (long name, units)."""


class SnapshotWriter:
    """Append depth, velocity and water-level maps at successive times to ``snapshots.nc``
    (CF-1.8).

    The file has an unlimited ``time`` dimension (seconds since the start of the run,
    ``start``: :func:`floodsph.output.cf.time_attrs`) and the variables of
    :data:`SNAPSHOT_VARIABLES` on (time, y, x), NaN where unsupported. Use as a context
    manager or call :meth:`close`. ``keep_frames`` > 0 continues the frames of an earlier
    file, ``source`` (default ``path`` itself; a resumed run): its first ``keep_frames``
    frames are copied into the new file, the frames after them (written after the
    checkpoint) are dropped.
    """

    def __init__(self, path, grid, *, scenario: dict | None = None,
                 wet_threshold: float = 0.01, keep_frames: int = 0, source=None,
                 start: datetime | None = None):
        import netCDF4

        self.path = Path(path)
        self.grid = grid
        previous = None if not keep_frames else Path(source or self.path)
        if previous == self.path:
            previous = self.path.with_name(self.path.name + ".previous")
            os.replace(self.path, previous)
        ds = netCDF4.Dataset(self.path, "w", format="NETCDF4")
        ds.setncatts(global_attrs("floodsph map snapshots", scenario, wet_threshold))
        ds.createDimension("time", None)
        ds.createDimension("y", grid.ny)
        ds.createDimension("x", grid.nx)
        xw, yw = grid.world_centres()
        for name, values in (("x", xw), ("y", yw)):
            var = ds.createVariable(name, "f8", (name,), fill_value=False)
            var.setncatts(COORD_ATTRS[name])
            var[:] = values
        t = ds.createVariable("time", "f8", ("time",), fill_value=False)
        t.setncatts(time_attrs(start))
        crs = grid_mapping_attrs(grid)
        if crs is not None:
            ds.createVariable("crs", "i4", ()).setncatts(crs)
        chunks = (1, min(grid.ny, 256), min(grid.nx, 256))
        for name, (long_name, units) in SNAPSHOT_VARIABLES.items():
            var = ds.createVariable(name, "f4", ("time", "y", "x"), zlib=True, complevel=4,
                                    chunksizes=chunks, fill_value=np.float32(np.nan))
            var.setncatts(variable_attrs(name, long_name, units, grid_mapping=crs is not None))
        self._ds = ds
        if previous is not None:
            with netCDF4.Dataset(previous) as src:
                for k in range(keep_frames):
                    for name in ("time", *SNAPSHOT_VARIABLES):
                        ds[name][k] = src[name][k]
            ds.sync()
            if source is None:
                previous.unlink()

    @property
    def frames(self) -> int:
        """Number of frames written."""
        return len(self._ds.dimensions["time"])

    def append(self, t: float, d, u, v, level=None) -> None:
        """Add the south-up maps d [m], u, v [m/s] and the water level [m] (NaN where dry;
        None: all NaN) at time t [s]."""
        ds = self._ds
        k = len(ds.dimensions["time"])
        ds["time"][k] = float(t)
        if level is None:
            level = np.full(np.shape(d), np.nan)
        for name, arr in (("depth", d), ("u", u), ("v", v), ("level", level)):
            ds[name][k, :, :] = np.asarray(arr, dtype=np.float32)[::-1]
        ds.sync()

    def close(self) -> None:
        self._ds.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
