"""Compare two flood maps of one quantity: wet/dry skill scores and the errors of the values.

``compare(model, reference)`` reads each map as one band (a raster file, or a NetCDF variable
``flood_maps.nc:max_depth``: :mod:`floodsph.output.map_source`) with its quantity (depth,
arrival time, speed, ...: :mod:`floodsph.output.quantities`), refuses two maps of different
quantities with one message naming both, reprojects the REFERENCE map onto
the MODEL map's grid (``rasterio.warp.reproject``: bilinear for float maps, nearest for
class maps) and evaluates only the cells the reference map covers. A cell is wet when its
depth is above the threshold (class maps: class > 0; the other quantities: where the map
has a value); NaN/nodata counts as dry.
With hits = wet in both, false alarms = wet in the model only, misses = wet in the reference
only (``docs/outputs.md``, ``floodsph compare`` outputs; seamlesswave.com/metrics; Wing et al.
2017 use 0.10 m):

    H   = hits / (hits + misses)                               hit rate
    FAR = false alarms / (hits + false alarms)                 false alarm ratio
    CSI = hits / (hits + false alarms + misses)                critical success index
    F2  = (hits - false alarms) / (hits + false alarms + misses)
    E   = false alarms / misses                                error bias (inf if no misses)

An undefined ratio (0 / 0) is NaN. Depth errors over cells wet in both, e = model - ref:
RMSE = sqrt(mean e^2), bias = mean e, MAE = mean |e|. CSI favours over-prediction (Stephens
et al. 2014): read it with the depth errors. The other float quantities (arrival time,
speed, level, ...) give the same errors of their values over the cells wet in both. Optional
observation points (CSV ``id, x, y, observed``) give the same error statistics at the points
(a dry cell of a depth map counts as depth 0) and a per-point table; a point off the model
map is a row marked ``outside``, left out of the statistics.
"""

from __future__ import annotations

import csv
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from floodsph.errors import InputError
from floodsph.output.map_source import Raster, read_raster
from floodsph.output.quantities import BY_NAME, CLASS, Quantity


def align(model: Raster, ref: Raster) -> tuple[np.ndarray, np.ndarray]:
    """The reference on the model's grid and the mask of model cells the reference covers."""
    from rasterio.warp import Resampling, reproject

    shape = model.data.shape
    nearest = ref.quantity is not None and ref.quantity.classes
    on_model = np.full(shape, np.nan)
    reproject(ref.data, on_model, src_transform=ref.transform, src_crs=ref.crs,
              dst_transform=model.transform, dst_crs=model.crs, src_nodata=np.nan,
              dst_nodata=np.nan,
              resampling=Resampling.nearest if nearest else Resampling.bilinear)
    covered = np.zeros(shape, dtype=np.uint8)
    reproject(np.ones(ref.data.shape, dtype=np.uint8), covered, src_transform=ref.transform,
              src_crs=ref.crs, dst_transform=model.transform, dst_crs=model.crs,
              dst_nodata=0, resampling=Resampling.nearest)
    if not covered.any():
        raise InputError(f"{model.path} and {ref.path} do not overlap")
    return on_model, covered.astype(bool)


def contingency(wet_model, wet_ref, mask) -> dict:
    """Counts of hits, false alarms, misses and correct negatives over ``mask``."""
    m, r = wet_model[mask], wet_ref[mask]
    return {"hits": int(np.sum(m & r)), "false_alarms": int(np.sum(m & ~r)),
            "misses": int(np.sum(~m & r)), "correct_negatives": int(np.sum(~m & ~r))}


def _ratio(num: float, den: float) -> float:
    if den == 0:
        return math.nan if num == 0 else math.inf
    return num / den


def scores(hits: int, false_alarms: int, misses: int) -> dict:
    """H, FAR, CSI, F2 and E from the contingency counts (see module docstring)."""
    union = hits + false_alarms + misses
    return {"hit_rate": _ratio(hits, hits + misses),
            "false_alarm_ratio": _ratio(false_alarms, hits + false_alarms),
            "csi": _ratio(hits, union),
            "f2": _ratio(hits - false_alarms, union),
            "error_bias": _ratio(false_alarms, misses)}


def errors(model_values, ref_values) -> dict:
    """RMSE, bias and MAE of ``model - ref`` and the number of values n."""
    e = np.asarray(model_values, dtype=np.float64) - np.asarray(ref_values, dtype=np.float64)
    if e.size == 0:
        return {"n": 0, "rmse": math.nan, "bias": math.nan, "mae": math.nan}
    return {"n": int(e.size), "rmse": float(np.sqrt(np.mean(e * e))), "bias": float(e.mean()),
            "mae": float(np.abs(e).mean())}


def read_points(path) -> list[tuple[str, float, float, float]]:
    """Observation points ``id, x, y, observed`` (map CRS); InputError naming file and line."""
    path = Path(path)
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows or not {"id", "x", "y", "observed"} <= set(rows[0]):
        raise InputError(f"{path}: point file needs the columns id, x, y, observed")
    out = []
    for line, r in enumerate(rows, start=2):
        try:
            out.append((r["id"], float(r["x"]), float(r["y"]), float(r["observed"])))
        except (TypeError, ValueError):
            raise InputError(f"{path}, line {line}: x, y and observed must be numbers") from None
    return out


POINT_COLUMNS = ("id", "x", "y", "observed", "modelled", "error", "status")
"""Columns of the per-point table ``points.csv``; ``status`` is one of :data:`POINT_STATUS`."""
POINT_STATUS = {"compared": "the point's error counts in the statistics",
                "outside": "the point is off the model map",
                "no value": "the model map has no value there (never wet)"}


def point_rows(raster: Raster, points) -> list[dict]:
    """One row per observation point (:data:`POINT_COLUMNS`): the model value of the cell
    holding it (a depth map's dry cell is depth 0) and ``error = modelled - observed``; a
    point off the map is a row marked ``outside``, not an error."""
    from rasterio.transform import rowcol

    rows, cols = rowcol(raster.transform, [p[1] for p in points], [p[2] for p in points])
    ny, nx = raster.data.shape
    out = []
    for (pid, x, y, observed), i, j in zip(points, rows, cols, strict=True):
        row = {"id": pid, "x": x, "y": y, "observed": observed, "modelled": math.nan,
               "error": math.nan, "status": "outside"}
        if 0 <= i < ny and 0 <= j < nx:
            value = float(raster.data[i, j])
            if raster.quantity is not None and raster.quantity.threshold and math.isnan(value):
                value = 0.0
            row["modelled"] = value
            row["status"] = "compared" if math.isfinite(value) else "no value"
            row["error"] = value - observed
        out.append(row)
    return out


def point_summary(rows: list[dict]) -> dict:
    """The error statistics of the compared points, and the ids of the others by status."""
    used = [r for r in rows if r["status"] == "compared"]
    summary = errors([r["modelled"] for r in used], [r["observed"] for r in used])
    for status in ("outside", "no value"):
        summary[status.replace(" ", "_")] = [r["id"] for r in rows if r["status"] == status]
    return summary


@dataclass
class Comparison:
    """Result of :func:`compare`: a JSON-ready summary and the difference map (model grid)."""

    summary: dict
    difference: np.ndarray
    categories: np.ndarray  # 0 no data, 1 correct negative, 2 hit, 3 false alarm, 4 miss
    model: Raster
    points: list[dict] | None = None  # the per-point table (POINT_COLUMNS), with --points


def compare(model_path, ref_path, threshold: float = 0.1, points=None,
            arrival: bool = False) -> Comparison:
    """Compare a model map with a reference map of the same quantity (see the module
    docstring); InputError naming both maps when their quantities differ."""
    if not threshold >= 0:
        raise InputError(f"--threshold must be >= 0, got {threshold}")
    model, ref = read_raster(model_path), read_raster(ref_path)
    quantity = same_quantity(model, ref, arrival)
    model.quantity = ref.quantity = quantity
    on_model, covered = align(model, ref)
    a, b = model.data, on_model
    wet_a, wet_b = _wet(a, quantity, threshold), _wet(b, quantity, threshold)
    counts = contingency(wet_a, wet_b, covered)
    both = covered & wet_a & wet_b
    summary = {"model": str(model.path), "reference": str(ref.path), "kind": quantity.name,
               "threshold_m": threshold if quantity.threshold else None,
               "cells_compared": int(covered.sum()), **counts,
               **scores(counts["hits"], counts["false_alarms"], counts["misses"])}
    if quantity.classes:
        summary["class_agreement"] = _ratio(float(np.sum(a[both] == b[both])), both.sum())
    else:
        summary[quantity.name] = errors(a[both], b[both])
    if quantity.threshold:
        diff = np.where(covered & (wet_a | wet_b), np.nan_to_num(a) - np.nan_to_num(b), np.nan)
    else:
        diff = np.where(both, a - b, np.nan)
    rows = None
    if points is not None:
        rows = point_rows(model, read_points(points))
        summary["points"] = point_summary(rows)
    cat = np.zeros(a.shape, dtype=np.uint8)
    cat[covered] = 1
    cat[covered & wet_a & wet_b] = 2
    cat[covered & wet_a & ~wet_b] = 3
    cat[covered & ~wet_a & wet_b] = 4
    return Comparison(summary, diff, cat, model, rows)


def same_quantity(model: Raster, ref: Raster, arrival: bool = False) -> Quantity:
    """The quantity both maps hold.

    A float map that says nothing takes the other map's quantity (arrival time with
    ``arrival``; depth when neither says). An integer map of no known scheme matches any class
    map. Maps of different quantities are refused with one message naming both.
    """
    if arrival:
        for r in (model, ref):
            if r.quantity is not None and r.quantity.name != "arrival":
                raise InputError(f"{r.described()}, but --arrival asks for arrival times")
        return BY_NAME["arrival"]
    known = [r.quantity for r in (model, ref) if r.quantity is not None]
    if not known:
        return BY_NAME["depth"]
    first, last = known[0], known[-1]
    if first == last:
        return first
    if first.classes and last.classes and CLASS in (first, last):
        return last if first == CLASS else first
    raise InputError(f"{model.described()} but {ref.described()}; compare needs two maps of "
                     f"the same quantity")


def _wet(data, quantity: Quantity, threshold: float) -> np.ndarray:
    """Wet cells: depth > threshold; a class > 0; any other quantity where it has a value.
    NaN is dry."""
    if quantity.threshold:
        return np.nan_to_num(data) > threshold
    if quantity.classes:
        return np.nan_to_num(data) > 0.0
    return np.isfinite(data)


def _finite(v):
    """JSON-safe number: NaN -> None, +-inf -> "inf"/"-inf"."""
    if isinstance(v, dict):
        return {k: _finite(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_finite(x) for x in v]
    if isinstance(v, float | np.floating):
        v = float(v)
        if math.isnan(v):
            return None
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
    return v


def format_table(summary: dict) -> str:
    """The summary as an aligned two-column text table."""
    lines = []
    for k, v in summary.items():
        if isinstance(v, dict):
            for k2, v2 in v.items():
                if not isinstance(v2, dict):
                    lines.append((f"{k}.{k2}", v2))
        else:
            lines.append((k, v))
    width = max(len(k) for k, _ in lines)
    return "\n".join(f"{k:<{width}}  {v:.4g}" if isinstance(v, float) else f"{k:<{width}}  {v}"
                     for k, v in lines)


def write_outputs(result: Comparison, out_dir) -> list:
    """Write ``difference.tif`` (a Cloud-Optimized GeoTIFF on the model's grid),
    ``comparison.json``, ``points.csv`` (with observation points) and ``comparison.png``
    (if matplotlib)."""
    from floodsph.output.geotiff import write_north_up
    from floodsph.output.tables import write_csv

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    m = result.model
    quantity = m.quantity
    assert quantity is not None  # compare_maps gave both maps their quantity
    diff_path = write_north_up(out_dir / "difference.tif", result.difference.astype(np.float32),
                               m.crs, m.transform, f"{quantity.name} difference",
                               "1" if quantity.classes else quantity.units,
                               long_name=f"{quantity.name} difference (model - reference)")
    written = [diff_path]
    json_path = out_dir / "comparison.json"
    json_path.write_text(json.dumps(_finite(result.summary), indent=2) + "\n")
    written.append(json_path)
    if result.points is not None:
        written.append(write_csv(out_dir / "points.csv", result.points, POINT_COLUMNS))
    from floodsph.output.pictures import plot_comparison

    png = plot_comparison(result, out_dir / "comparison.png")
    return written + ([png] if isinstance(png, Path) else [])
