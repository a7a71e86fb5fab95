"""CF-1.8 NetCDF writers: the envelope maps (``flood_maps.nc``) and map snapshots.

Layout (CF conventions 1.8, sections 4, 5.6, 7.3 and 3.5):

* dimensions ``y`` (north to south, like the GeoTIFFs) and ``x``; coordinate variables with
  ``standard_name = projection_y_coordinate / projection_x_coordinate`` and ``units = "m"``
  holding the world coordinates of the cell centres;
* a scalar ``crs`` grid-mapping variable with ``crs_wkt`` and ``spatial_ref`` (the WKT, as
  GDAL reads it), ``GeoTransform`` (GDAL order) and, for transverse Mercator / UTM and
  Lambert conformal conic CRSs, the CF ``grid_mapping_name`` and its parameters;
* every data variable has ``long_name``, ``units`` and ``grid_mapping = "crs"``; maxima have
  ``cell_methods = "time: maximum"``; class maps are uint8 with ``flag_values`` /
  ``flag_meanings`` (0 = dry);
* float maps are float32, zlib level 4, ``_FillValue = NaN``.

Global attributes: ``Conventions``, ``title``, ``source = "floodsph <version>"``,
``history``, ``references``, the wet threshold and the resolved scenario as a JSON string.
"""

from __future__ import annotations

import json
import os
import re
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from floodsph._version import __version__

REFERENCES = ("Vacondio, Rogers, Stansby, Mignosa & Feldman (2013), Adv. Water Resour. 58, "
              "10-23; hazard: Defra/EA FD2320-FD2321; AIDR Guideline 7-3 (2017)")


def grid_mapping_attrs(grid) -> dict:
    """Attributes of the ``crs`` grid-mapping variable for a grid's CRS."""
    from rasterio.crs import CRS

    t = grid.north_up_transform()
    attrs = {"GeoTransform": " ".join(str(v) for v in (t.c, t.a, t.b, t.f, t.d, t.e))}
    if not grid.crs_wkt:
        return attrs
    attrs["crs_wkt"] = grid.crs_wkt
    attrs["spatial_ref"] = grid.crs_wkt
    p = CRS.from_wkt(grid.crs_wkt).to_dict()
    proj = p.get("proj")
    if proj == "utm":
        attrs.update(grid_mapping_name="transverse_mercator",
                     longitude_of_central_meridian=6.0 * p["zone"] - 183.0,
                     latitude_of_projection_origin=0.0,
                     scale_factor_at_central_meridian=0.9996, false_easting=500000.0,
                     false_northing=1.0e7 if p.get("south") else 0.0)
    elif proj == "tmerc" and p.get("pm", "greenwich") == "greenwich":
        attrs.update(grid_mapping_name="transverse_mercator",
                     longitude_of_central_meridian=float(p.get("lon_0", 0.0)),
                     latitude_of_projection_origin=float(p.get("lat_0", 0.0)),
                     scale_factor_at_central_meridian=float(p.get("k", p.get("k_0", 1.0))),
                     false_easting=float(p.get("x_0", 0.0)),
                     false_northing=float(p.get("y_0", 0.0)))
    elif proj == "lcc" and p.get("pm", "greenwich") == "greenwich" and "k_0" not in p:
        attrs.update(grid_mapping_name="lambert_conformal_conic",
                     standard_parallel=[float(p["lat_1"]), float(p.get("lat_2", p["lat_1"]))],
                     longitude_of_central_meridian=float(p.get("lon_0", 0.0)),
                     latitude_of_projection_origin=float(p.get("lat_0", 0.0)),
                     false_easting=float(p.get("x_0", 0.0)),
                     false_northing=float(p.get("y_0", 0.0)))
    return attrs


def grid_coords(grid) -> dict:
    """The CF ``x`` and ``y`` coordinate variables (world cell centres, y north to south)."""
    import xarray as xr

    xw, yw = grid.world_centres()
    x = xr.Variable("x", xw, {"standard_name": "projection_x_coordinate",
                              "long_name": "x coordinate of the cell centre", "units": "m",
                              "axis": "X"})
    y = xr.Variable("y", yw, {"standard_name": "projection_y_coordinate",
                              "long_name": "y coordinate of the cell centre", "units": "m",
                              "axis": "Y"})
    return {"x": x, "y": y}


def flag_meanings(names) -> str:
    """CF ``flag_meanings``: class names as blank-separated words (underscores inside)."""
    return " ".join(re.sub(r"[^A-Za-z0-9]+", "_", n).strip("_").lower() for n in names)


def global_attrs(title: str, scenario: dict | None, wet_threshold: float) -> dict:
    """The global attributes shared by the map and snapshot files."""
    stamp = datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
    return {
        "Conventions": "CF-1.8",
        "title": title,
        "source": f"floodsph {__version__}",
        "history": f"{stamp} written by floodsph {__version__}",
        "references": REFERENCES,
        "wet_threshold_m": float(wet_threshold),
        "scenario": json.dumps(scenario or {}, sort_keys=True, default=str),
    }


def write_flood_maps(path, maps: dict, info: dict, grid, *, class_names: dict,
                     scenario: dict | None = None, wet_threshold: float = 0.01,
                     title: str = "floodsph flood maps") -> Path:
    """Write the envelope maps as one CF-1.8 NetCDF file.

    Parameters
    ----------
    path : path-like
        Output file (``flood_maps.nc``).
    maps : dict name -> (ny, nx) array
        South-up maps (row 0 = south); uint8 arrays are class maps.
    info : dict name -> (long_name, units, cell_methods or None)
        Metadata per map (:data:`floodsph.output.envelopes.MAPS`).
    grid : OutputGrid
        Georeference of the maps.
    class_names : dict name -> sequence of str
        Class names (index = value) of each class map.
    scenario, wet_threshold, title
        Recorded in the global attributes.
    """
    import xarray as xr

    path = Path(path)
    chunks = (min(grid.ny, 256), min(grid.nx, 256))
    data_vars = {"crs": xr.Variable((), np.int32(0), grid_mapping_attrs(grid))}
    encoding = {"crs": {"dtype": "int32"}}
    for name, arr in maps.items():
        long_name, units, cell_methods = info[name]
        attrs = {"long_name": long_name, "units": units, "grid_mapping": "crs"}
        if cell_methods:
            attrs["cell_methods"] = cell_methods
        if np.asarray(arr).dtype == np.uint8:
            names = class_names[name]
            attrs["flag_values"] = np.arange(len(names), dtype=np.uint8)
            attrs["flag_meanings"] = flag_meanings(names)
            data = np.asarray(arr)[::-1]
            encoding[name] = {"dtype": "uint8", "_FillValue": None, "zlib": True,
                              "complevel": 4, "chunksizes": chunks}
        else:
            data = np.asarray(arr, dtype=np.float32)[::-1]
            encoding[name] = {"dtype": "float32", "_FillValue": np.float32(np.nan),
                              "zlib": True, "complevel": 4, "chunksizes": chunks}
        data_vars[name] = xr.Variable(("y", "x"), data, attrs)
    ds = xr.Dataset(data_vars, coords=grid_coords(grid),
                    attrs=global_attrs(title, scenario, wet_threshold))
    part = path.with_name(path.name + ".part")
    ds.to_netcdf(part, engine="netcdf4", format="NETCDF4", encoding=encoding)
    os.replace(part, path)
    return path


class SnapshotWriter:
    """Append depth and velocity maps at successive times to ``snapshots.nc`` (CF-1.8).

    The file has an unlimited ``time`` dimension (seconds since the start of the run) and
    variables ``depth`` [m], ``u`` and ``v`` [m/s] on (time, y, x), NaN where unsupported.
    Use as a context manager or call :meth:`close`. ``keep_frames`` > 0 continues the frames
    of an earlier file, ``source`` (default ``path`` itself; a resumed run): its first
    ``keep_frames`` frames are copied into the new file, the frames after them (written after
    the checkpoint) are dropped.
    """

    def __init__(self, path, grid, *, scenario: dict | None = None,
                 wet_threshold: float = 0.01, keep_frames: int = 0, source=None):
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
            var = ds.createVariable(name, "f8", (name,))
            var.setncatts({"standard_name": f"projection_{name}_coordinate", "units": "m",
                           "axis": name.upper()})
            var[:] = values
        t = ds.createVariable("time", "f8", ("time",))
        t.setncatts({"long_name": "simulated time since the start of the run", "units": "s",
                     "axis": "T"})
        crs = ds.createVariable("crs", "i4", ())
        crs.setncatts(grid_mapping_attrs(grid))
        chunks = (1, min(grid.ny, 256), min(grid.nx, 256))
        for name, long_name, units in (("depth", "water depth", "m"),
                                       ("u", "depth-averaged velocity, east component",
                                        "m s-1"),
                                       ("v", "depth-averaged velocity, north component",
                                        "m s-1")):
            var = ds.createVariable(name, "f4", ("time", "y", "x"), zlib=True, complevel=4,
                                    chunksizes=chunks, fill_value=np.float32(np.nan))
            var.setncatts({"long_name": long_name, "units": units, "grid_mapping": "crs"})
        self._ds = ds
        if previous is not None:
            with netCDF4.Dataset(previous) as src:
                for k in range(keep_frames):
                    for name in ("time", "depth", "u", "v"):
                        ds[name][k] = src[name][k]
            ds.sync()
            if source is None:
                previous.unlink()

    @property
    def frames(self) -> int:
        """Number of frames written."""
        return len(self._ds.dimensions["time"])

    def append(self, t: float, d, u, v) -> None:
        """Add the south-up maps d [m], u, v [m/s] at time t [s]."""
        ds = self._ds
        k = len(ds.dimensions["time"])
        ds["time"][k] = float(t)
        for name, arr in (("depth", d), ("u", u), ("v", v)):
            ds[name][k, :, :] = np.asarray(arr, dtype=np.float32)[::-1]
        ds.sync()

    def close(self) -> None:
        self._ds.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
