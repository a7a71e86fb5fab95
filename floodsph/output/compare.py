"""Compare two flood maps: binary wet/dry skill scores, depth errors, arrival-time errors.

``compare(model, reference)`` reads each map as one band (a raster file, or a NetCDF variable
``flood_maps.nc:max_depth``: :mod:`floodsph.output.map_source`), reprojects the REFERENCE map onto
the MODEL map's grid (``rasterio.warp.reproject``: bilinear for depth and arrival time,
nearest for class maps) and evaluates only the cells the reference map covers. A cell is wet
when its depth is above the threshold (class maps: class > 0); NaN/nodata counts as dry.
With hits = wet in both, false alarms = wet in the model only, misses = wet in the reference
only (flood-practice.md section 1.6; seamlesswave.com/metrics; Wing et al. 2017 use 0.10 m):

    H   = hits / (hits + misses)                               hit rate
    FAR = false alarms / (hits + false alarms)                 false alarm ratio
    CSI = hits / (hits + false alarms + misses)                critical success index
    F2  = (hits - false alarms) / (hits + false alarms + misses)
    E   = false alarms / misses                                error bias (inf if no misses)

An undefined ratio (0 / 0) is NaN. Depth errors over cells wet in both, e = model - ref:
RMSE = sqrt(mean e^2), bias = mean e, MAE = mean |e|. CSI favours over-prediction (Stephens
et al. 2014): read it with the depth errors. Arrival-time maps (``arrival=True``, or a band
description, NetCDF variable or standard name that says arrival) give the mean and RMSE of
the arrival difference over cells wet in both. Optional observation points (CSV ``id, x, y,
observed``) give the same depth error statistics at the points (a dry model cell counts as
depth 0).
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


def align(model: Raster, ref: Raster) -> tuple[np.ndarray, np.ndarray]:
    """The reference on the model's grid and the mask of model cells the reference covers."""
    from rasterio.warp import Resampling, reproject

    shape = model.data.shape
    nearest = ref.kind == "class"
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


def sample(raster: Raster, points) -> np.ndarray:
    """Values of the raster cells holding the points; InputError for a point off the map."""
    from rasterio.transform import rowcol

    rows, cols = rowcol(raster.transform, [p[1] for p in points], [p[2] for p in points])
    ny, nx = raster.data.shape
    for (pid, x, y, _), i, j in zip(points, rows, cols, strict=True):
        if not (0 <= i < ny and 0 <= j < nx):
            raise InputError(f"point {pid!r} at ({x}, {y}) is outside {raster.path}")
    return raster.data[np.asarray(rows), np.asarray(cols)]


@dataclass
class Comparison:
    """Result of :func:`compare`: a JSON-ready summary and the difference map (model grid)."""

    summary: dict
    difference: np.ndarray
    categories: np.ndarray  # 0 no data, 1 correct negative, 2 hit, 3 false alarm, 4 miss
    model: Raster


def compare(model_path, ref_path, threshold: float = 0.1, points=None,
            arrival: bool = False) -> Comparison:
    """Compare a model map with a reference map (see the module docstring)."""
    if not threshold >= 0:
        raise InputError(f"--threshold must be >= 0, got {threshold}")
    model = read_raster(model_path, arrival)
    ref = read_raster(ref_path, arrival)
    if model.kind != ref.kind:
        raise InputError(f"{model.path} is a {model.kind} map but {ref.path} is a "
                         f"{ref.kind} map")
    on_model, covered = align(model, ref)
    a, b = model.data, on_model
    wet_a, wet_b = _wet(a, model.kind, threshold), _wet(b, model.kind, threshold)
    counts = contingency(wet_a, wet_b, covered)
    both = covered & wet_a & wet_b
    summary = {"model": str(model.path), "reference": str(ref.path), "kind": model.kind,
               "threshold_m": threshold if model.kind == "depth" else None,
               "cells_compared": int(covered.sum()), **counts,
               **scores(counts["hits"], counts["false_alarms"], counts["misses"])}
    if model.kind == "class":
        summary["class_agreement"] = _ratio(float(np.sum(a[both] == b[both])), both.sum())
    key = "arrival" if model.kind == "arrival" else "depth"
    summary[key] = errors(a[both], b[both])
    if model.kind == "depth":
        diff = np.where(covered & (wet_a | wet_b), np.nan_to_num(a) - np.nan_to_num(b), np.nan)
    else:
        diff = np.where(both, a - b, np.nan)
    if points is not None:
        pts = read_points(points)
        at_model = sample(model, pts)
        if model.kind == "depth":
            at_model = np.nan_to_num(at_model)
        obs = np.array([p[3] for p in pts])
        ok = np.isfinite(at_model)
        summary["points"] = errors(at_model[ok], obs[ok])
        summary["points"]["values"] = {p[0]: _finite(v) for p, v in zip(pts, at_model,
                                                                          strict=True)}
    cat = np.zeros(a.shape, dtype=np.uint8)
    cat[covered] = 1
    cat[covered & wet_a & wet_b] = 2
    cat[covered & wet_a & ~wet_b] = 3
    cat[covered & ~wet_a & wet_b] = 4
    return Comparison(summary, diff, cat, model)


def _wet(data, kind: str, threshold: float) -> np.ndarray:
    """Wet cells: depth > threshold; a finite arrival time; a class > 0. NaN is dry."""
    if kind == "arrival":
        return np.isfinite(data)
    return np.nan_to_num(data) > (threshold if kind == "depth" else 0.0)


def _finite(v):
    """JSON-safe number: NaN -> None, +-inf -> "inf"/"-inf"."""
    if isinstance(v, dict):
        return {k: _finite(x) for k, x in v.items()}
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
    """Write ``difference.tif``, ``comparison.json`` and ``comparison.png`` (if matplotlib)."""
    import rasterio

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    m = result.model
    ny, nx = m.data.shape
    profile = {"driver": "GTiff", "width": nx, "height": ny, "count": 1, "dtype": "float32",
               "nodata": float("nan"), "crs": m.crs, "transform": m.transform,
               "compress": "deflate", "predictor": 3, "tiled": nx >= 256 and ny >= 256}
    diff_path = out_dir / "difference.tif"
    with rasterio.open(diff_path, "w", **profile) as dst:
        dst.write(result.difference.astype(np.float32), 1)
        dst.set_band_description(1, f"{result.summary['kind']} difference (model - reference)")
        units = "s" if result.summary["kind"] == "arrival" else "m"
        dst.set_band_unit(1, units)
        dst.update_tags(1, units=units)
    json_path = out_dir / "comparison.json"
    json_path.write_text(json.dumps(_finite(result.summary), indent=2) + "\n")
    from floodsph.output.pictures import plot_comparison

    png = plot_comparison(result, out_dir / "comparison.png")
    return [diff_path, json_path] + ([png] if isinstance(png, Path) else [])
