"""The ensemble folder's map files: COG GeoTIFFs, ``ensemble_maps.nc`` and ``ensemble.png``.

File names (contract, ``ensemble-format.md``; labels from :mod:`floodsph.ensemble.spec`):

* ``p_depth_gt_<t>m.tif`` per depth threshold t (``p_depth_gt_0.1m.tif``);
* ``max_depth_<q>.tif``, ``max_speed_<q>.tif``, ``arrival_time_<q>.tif`` per quantile
  (``q05``, ``q50``, ``q95``);
* ``p_hazard_uk_ge_<k>.tif`` for the UK hazard classes k = 1..4 (an extension of the
  contract: the probability of class k or worse);
* ``ensemble_maps.nc`` with all of them (:mod:`floodsph.ensemble.netcdf`);
* ``ensemble.png``: the probability of the 0.1 m threshold (else the smallest one) over a
  hillshade, when matplotlib is installed.

GeoTIFFs go through :func:`floodsph.output.geotiff.write_geotiff` (GDAL's COG driver, float32,
NaN nodata).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from floodsph.ensemble.aggregate import UK_CLASSES, EnsembleMaps
from floodsph.ensemble.spec import quantile_label, threshold_label

NETCDF_NAME = "ensemble_maps.nc"
PICTURE_NAME = "ensemble.png"
#: Names the ensemble writes (and may remove again before it writes new maps).
OUTPUT_PATTERN = re.compile(
    r"^(p_depth_gt_.+m|(max_depth|max_speed|arrival_time)_q.+|p_hazard_uk_ge_\d)\.tif$"
    rf"|^{re.escape(NETCDF_NAME)}$|^{re.escape(PICTURE_NAME)}$")
QUANTILE_MAPS = {
    "max_depth_q": ("max_depth", "maximum water depth", "m"),
    "max_speed_q": ("max_speed", "maximum depth-averaged speed", "m s-1"),
    "arrival_time_q": ("arrival_time", "arrival time over the members that wet the cell", "s"),
}


@dataclass(frozen=True)
class Layer:
    """One GeoTIFF: its file name, south-up map, units and long name."""

    file_name: str
    data: np.ndarray
    units: str
    long_name: str


def geotiff_layers(maps: EnsembleMaps) -> list[Layer]:
    """Every GeoTIFF of the ensemble maps, in writing order."""
    out = []
    for k, t in enumerate(maps.thresholds):
        out.append(Layer(f"p_depth_gt_{threshold_label(t)}m.tif", maps.p_depth_gt[k], "1",
                         f"probability that the maximum depth exceeds {t:g} m"))
    for attr, (stem, long_name, units) in QUANTILE_MAPS.items():
        for k, q in enumerate(maps.quantiles):
            out.append(Layer(f"{stem}_{quantile_label(q)}.tif", getattr(maps, attr)[k], units,
                             f"{long_name}, {q:g} quantile over the members"))
    for k, cls in enumerate(UK_CLASSES):
        out.append(Layer(f"p_hazard_uk_ge_{cls}.tif", maps.p_hazard_uk_ge[k], "1",
                         f"probability of UK hazard rating class {cls} or worse"))
    return out


@dataclass(frozen=True)
class Written:
    """The files written: map file names, and the picture's name (or why it was skipped)."""

    maps: list[str]
    pictures: list[str] | str


def write_outputs(maps: EnsembleMaps, grid, out: Path, *, ensemble: dict, scenario: dict,
                  wet_threshold: float, title: str) -> Written:
    """Write every map file into ``out``."""
    from floodsph._version import __version__
    from floodsph.ensemble.netcdf import write_ensemble_netcdf
    from floodsph.output.geotiff import write_geotiff
    from floodsph.output.pictures import write_probability_picture

    tags = {"members_completed": maps.members, "ensemble": ensemble["name"],
            "wet_threshold_m": wet_threshold, "source": f"floodsph {__version__}"}
    names = []
    for layer in geotiff_layers(maps):
        write_geotiff(out / layer.file_name, layer.data, grid,
                      layer.file_name.removesuffix(".tif"), layer.units,
                      long_name=layer.long_name, tags=tags)
        names.append(layer.file_name)
    write_ensemble_netcdf(out / NETCDF_NAME, maps, grid, ensemble=ensemble, scenario=scenario,
                          wet_threshold=wet_threshold)
    names.append(NETCDF_NAME)
    k = maps.thresholds.index(0.1) if 0.1 in maps.thresholds else maps.thresholds.index(
        min(maps.thresholds))
    t = maps.thresholds[k]
    picture = write_probability_picture(
        grid, maps.p_depth_gt[k], out / PICTURE_NAME,
        f"{title}: P(max depth > {t:g} m) over {maps.members} members",
        label=f"probability that the maximum depth exceeds {t:g} m")
    return Written(names, picture if isinstance(picture, str) else [Path(picture).name])


def remove_previous(out: Path, names) -> None:
    """Remove the map files of an earlier ensemble (only names the ensemble writes)."""
    for name in names or ():
        if OUTPUT_PATTERN.match(str(name)):
            (out / name).unlink(missing_ok=True)
