"""A finished run folder as Python objects: its manifest and its maps as an xarray Dataset.

:class:`RunResult` is what :func:`floodsph.run_scenario` returns and :func:`open_run` reads
back from any run folder (scenario-format.md, "Run folder"). Its maps come from
``flood_maps.nc`` when the run wrote it, else from the GeoTIFFs; either way the Dataset has
the same layout: one variable per map (``max_depth`` [m], ``max_speed`` [m/s], ...,
``hazard_uk``), cell-centre coordinates ``x`` (west to east) and ``y`` (north to south) in
the DEM's CRS [m], and a scalar ``crs`` variable whose ``crs_wkt`` attribute is the CRS (the
CF grid mapping every map names in its ``grid_mapping`` attribute).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from floodsph.errors import InputError
from floodsph.run.folder import MAP_NAMES
from floodsph.run.manifest import MANIFEST_NAME, read_manifest

NETCDF_MAPS = "flood_maps.nc"
GEOTIFF_MAPS = tuple(name for name in MAP_NAMES if name.endswith(".tif"))


@dataclass(frozen=True)
class RunResult:
    """One run folder: where it is and what its ``run.json`` says.

    Attributes
    ----------
    folder : Path
        The run folder (absolute).
    manifest : dict
        ``run.json`` as a dict (status, volumes, counters, the resolved scenario...).
    """

    folder: Path
    manifest: dict

    @property
    def status(self) -> str:
        """``"completed"``, ``"stopped"``, ``"interrupted"``, ``"failed"`` or ``"running"``."""
        return self.manifest["status"]

    @property
    def crs(self):
        """The maps' CRS as a ``pyproj.CRS`` (the DEM's), None for synthetic terrain."""
        import pyproj

        wkt = self.maps()["crs"].attrs.get("crs_wkt")
        return pyproj.CRS.from_wkt(wkt) if wkt else None

    def maps(self):
        """The envelope maps as an ``xarray.Dataset``, read into memory (the files stay
        closed): from ``flood_maps.nc``, or from the GeoTIFFs of a run that wrote only those.

        Raises InputError naming the folder when the run wrote no maps (it did not end its
        time loop: interrupted or failed).
        """
        if (self.folder / NETCDF_MAPS).is_file():
            import xarray as xr

            return xr.load_dataset(self.folder / NETCDF_MAPS)
        if (self.folder / GEOTIFF_MAPS[0]).is_file():
            return maps_from_geotiffs(self.folder)
        raise InputError(f"{self.folder}: the run wrote no maps (status {self.status!r}); "
                         "only a completed or stopped run has them")

    def __repr__(self) -> str:
        return f"RunResult({str(self.folder)!r}, status={self.status!r})"


def open_run(folder: str | Path) -> RunResult:
    """The :class:`RunResult` of an existing run folder (one that holds a ``run.json``)."""
    folder = Path(folder).resolve()
    manifest = read_manifest(folder)
    if manifest is None:
        raise InputError(f"{folder}: not a floodsph run folder (no readable {MANIFEST_NAME})")
    return RunResult(folder, manifest)


def maps_from_geotiffs(folder: Path):
    """The GeoTIFF maps of ``folder`` as one Dataset laid out as ``flood_maps.nc`` (float maps
    with NaN where never wet, class maps uint8 with 0 = dry)."""
    import numpy as np
    import rasterio
    import xarray as xr

    data_vars, coords, wkt = {}, None, None
    for name in GEOTIFF_MAPS:
        path = folder / name
        if not path.is_file():
            continue
        with rasterio.open(path) as src:
            values = src.read(1)
            tags = src.tags(1)
            if coords is None:
                t = src.transform
                coords = {"x": t.c + t.a * (np.arange(src.width) + 0.5),
                          "y": t.f + t.e * (np.arange(src.height) + 0.5)}
                wkt = src.crs.to_wkt() if src.crs is not None else None
        attrs = {"long_name": tags.get("long_name", path.stem), "grid_mapping": "crs"}
        if "units" in tags:
            attrs["units"] = tags["units"]
        data_vars[path.stem] = (("y", "x"), values, attrs)
    crs_attrs = {} if wkt is None else {"crs_wkt": wkt, "spatial_ref": wkt}
    data_vars["crs"] = ((), np.int32(0), crs_attrs)
    x = xr.Variable("x", coords["x"], {"units": "m", "axis": "X",
                                      "standard_name": "projection_x_coordinate"})
    y = xr.Variable("y", coords["y"], {"units": "m", "axis": "Y",
                                      "standard_name": "projection_y_coordinate"})
    return xr.Dataset(data_vars, coords={"x": x, "y": y})
