"""A finished run folder as Python objects: its manifest and its maps as an xarray Dataset.

:class:`RunResult` is what :func:`floodsph.run_scenario` returns and :func:`open_run` reads
back from any run folder (``docs/run-folder.md``). Its maps come from
``flood_maps.nc`` when the run wrote it, else from the GeoTIFFs; either way it is the same
Dataset, that of ``flood_maps.nc`` (class maps as uint8): one variable per map
(``max_depth`` [m], ``max_speed`` [m/s], ..., ``hazard_uk``), cell-centre coordinates ``x``
(west to east) and ``y`` (north to south) in the DEM's CRS [m], and a scalar ``crs``
variable whose ``crs_wkt`` attribute is the CRS (the CF grid mapping every map names in its
``grid_mapping`` attribute).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from floodsph.errors import InputError
from floodsph.io.run_names import MAP_NAMES
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
        closed): from ``flood_maps.nc``, or from the GeoTIFFs of a run that wrote only those,
        the same Dataset either way (:func:`maps_dataset`).

        Raises InputError naming the folder when the run wrote no maps (it did not end its
        time loop: interrupted or failed).
        """
        if (self.folder / NETCDF_MAPS).is_file():
            import xarray as xr

            return unsigned_classes(xr.load_dataset(self.folder / NETCDF_MAPS))
        if (self.folder / GEOTIFF_MAPS[0]).is_file():
            return maps_from_geotiffs(self.folder, self.manifest)
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


def unsigned_classes(ds):
    """The class maps (flag variables) of a Dataset as uint8, with uint8 ``flag_values``:
    ``flood_maps.nc`` stores them as CF ``byte`` (int8), the GeoTIFFs and the run as uint8."""
    import numpy as np

    for var in ds.data_vars.values():
        if "flag_values" in var.attrs:
            var.values = var.values.astype(np.uint8)
            var.attrs["flag_values"] = np.asarray(var.attrs["flag_values"]).astype(np.uint8)
    return ds


def maps_from_geotiffs(folder: Path, manifest: dict):
    """The GeoTIFF maps of ``folder`` as the Dataset ``flood_maps.nc`` gives: the same
    variables, dtypes, attributes, flags, coordinates and dated ``time``, built by the
    NetCDF writer's own :func:`~floodsph.output.netcdf.flood_maps_dataset` from the maps, their
    tags (wet threshold, period, class names) and ``run.json`` (the scenario and its start)."""
    from datetime import datetime

    import rasterio
    import xarray as xr

    from floodsph.output.envelopes import MAPS
    from floodsph.output.grid import OutputGrid
    from floodsph.output.netcdf import flood_maps_dataset

    maps, class_names, grid, tags = {}, {}, None, {}
    for name in GEOTIFF_MAPS:
        path = folder / name
        if not path.is_file():
            continue
        with rasterio.open(path) as src:
            maps[path.stem] = src.read(1)[::-1]
            band = src.tags(1)
            if grid is None:
                t, tags = src.transform, src.tags()
                grid = OutputGrid(src.width, src.height, t.a, -t.e, t.c, t.f + t.e * src.height,
                                  src.crs.to_wkt() if src.crs is not None else None, None)
        names = [band[f"class_{k}"] for k in range(len(band)) if f"class_{k}" in band]
        if names:
            class_names[path.stem] = names
    period = tags.get("period_s")
    start = manifest.get("start")
    ds = flood_maps_dataset(maps, MAPS, grid, class_names=class_names,
                            scenario=manifest.get("scenario"),
                            wet_threshold=float(tags.get("wet_threshold_m", 0.01)),
                            period_s=None if period is None else float(period),
                            start=None if start is None else datetime.fromisoformat(start))
    return unsigned_classes(xr.decode_cf(ds))
