"""Malpasset results: levels and arrival times at the survey points, costs, pictures.

From a finished run folder (the file names of docs/run-folder.md) and the benchmark points:

* maximum water level at a point: ``max_level.tif`` in the cell holding the point
  (``max_level_m``), and the highest maximum level among the cells within ``RADIUS_M`` whose
  maximum depth exceeds ``ARRIVAL_DEPTH_M`` (``max_level_r40_m``; SOURCE.md: several survey
  points lie on steep valley sides where the 20 m DEM bed is close to or above the recorded
  level, so sample within a small radius). The depth condition keeps out the cells at the
  wet margin that the SPH interpolation touches with a film of water;
* ``gauge_max_level_m``: the highest ``level_m`` of the point's time series (``gauges.csv``);
* arrival time: the first gauge time at which the depth exceeds ``ARRIVAL_DEPTH_M``
  (0.05 m); its resolution is the gauge interval. NaN: the water never arrived.

``ParticleCounter`` is a simulation callback recording the particle count over time (with a
sink the count falls as the flood reaches the sea).
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np

ARRIVAL_DEPTH_M = 0.05
RADIUS_M = 40.0
POINT_COLUMNS = ("sea", "id", "type", "x", "y", "bed_m", "max_level_m", "max_level_r40_m",
                 "max_depth_m", "gauge_max_level_m", "arrival_time_s")
COST_COLUMNS = ("sea", "status", "sim_time_s", "steps", "particles_initial", "particles_max",
                "particles_final", "volume_initial_m3", "volume_out_m3", "mass_error_rel",
                "wall_time_s", "peak_rss_mb", "threads")


class ParticleCounter:
    """Callback ``(sim)``: rows of (time [s], particles, wall time [s], outflow volume [m3])."""

    def __init__(self):
        self.rows: list[tuple[float, int, float, float]] = []

    def __call__(self, sim) -> None:
        model = sim.model
        self.rows.append((float(model.t), len(model.particles), sim.wall_time,
                          float(model.state.volume_out)))

    def write_csv(self, path: Path) -> Path:
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["time_s", "particles", "wall_time_s", "volume_out_m3"])
            for t, n, wall, vout in self.rows:
                w.writerow([f"{t:.3f}", n, f"{wall:.3f}", f"{vout:.6g}"])
        return path


def arrival_times(gauges_csv: Path, threshold: float = ARRIVAL_DEPTH_M) -> dict[str, float]:
    """First ``time_s`` with ``depth_m > threshold`` per gauge id (NaN: never)."""
    out: dict[str, float] = {}
    with open(gauges_csv, newline="") as f:
        for row in csv.DictReader(f):
            gid = row["id"]
            out.setdefault(gid, math.nan)
            if math.isnan(out[gid]) and float(row["depth_m"]) > threshold:
                out[gid] = float(row["time_s"])
    return out


def gauge_max_levels(gauges_csv: Path) -> dict[str, float]:
    """Highest ``level_m`` per gauge id (NaN: always dry)."""
    out: dict[str, float] = {}
    with open(gauges_csv, newline="") as f:
        for row in csv.DictReader(f):
            level = float(row["level_m"])
            best = out.setdefault(row["id"], math.nan)
            if math.isfinite(level) and (math.isnan(best) or level > best):
                out[row["id"]] = level
    return out


def _read(path: Path):
    import rasterio

    with rasterio.open(path) as src:
        data = src.read(1).astype(np.float64)
        if src.nodata is not None and not math.isnan(src.nodata):
            data[data == src.nodata] = np.nan
        return data, src.transform


def point_table(run_dir: Path, dem: Path, points: list[dict], sea: str) -> list[dict]:
    """One row (POINT_COLUMNS) per point: bed, maximum levels, maximum depth, arrival time."""
    from rasterio.transform import rowcol

    level, transform = _read(run_dir / "max_level.tif")
    depth, _ = _read(run_dir / "max_depth.tif")
    bed, bed_transform = _read(dem)
    if bed.shape != level.shape or not bed_transform.almost_equals(transform):
        raise ValueError(f"{run_dir}: the maps are not on the DEM grid; cannot sample points")
    ny, nx = level.shape
    cols, rows = np.meshgrid(np.arange(nx), np.arange(ny))
    xc = transform.c + (cols + 0.5) * transform.a
    yc = transform.f + (rows + 0.5) * transform.e
    arrival = arrival_times(run_dir / "gauges.csv")
    gauge_level = gauge_max_levels(run_dir / "gauges.csv")
    out = []
    for p in points:
        i, j = rowcol(transform, p["x"], p["y"])
        near = (np.hypot(xc - p["x"], yc - p["y"]) <= RADIUS_M) & (
            np.nan_to_num(depth) > ARRIVAL_DEPTH_M)
        out.append({"sea": sea, "id": p["id"], "type": p["type"], "x": p["x"], "y": p["y"],
                    "bed_m": bed[i, j], "max_level_m": level[i, j],
                    "max_level_r40_m": float(level[near].max()) if near.any() else math.nan,
                    "max_depth_m": depth[i, j],
                    "gauge_max_level_m": gauge_level.get(p["id"], math.nan),
                    "arrival_time_s": arrival.get(p["id"], math.nan)})
    return out


def cost_row(run_dir: Path, sea: str, peak_rss_mb: float) -> dict:
    """COST_COLUMNS of one run from its ``run.json`` plus the process peak memory [MB]."""
    run = json.loads((run_dir / "run.json").read_text())
    row = {c: run.get(c) for c in COST_COLUMNS}
    row.update(sea=sea, peak_rss_mb=float(peak_rss_mb))
    return row


def plot_max_level(run_dir: Path, dem: Path, points: list[dict], path: Path, title: str):
    """Maximum water level over a hillshade, the points marked; the PNG path."""
    from matplotlib import colors
    from matplotlib.figure import Figure

    level, t = _read(run_dir / "max_level.tif")
    depth, _ = _read(run_dir / "max_depth.tif")
    bed, _ = _read(dem)
    ny, nx = level.shape
    extent = (t.c / 1e3, (t.c + nx * t.a) / 1e3, (t.f + ny * t.e) / 1e3, t.f / 1e3)
    fig = Figure(figsize=(7.5, 11.0), dpi=110)
    ax = fig.add_subplot()
    shade = colors.LightSource(azdeg=315, altdeg=45).hillshade(
        np.nan_to_num(bed, nan=float(np.nanmin(bed))), vert_exag=2.0, dx=t.a, dy=-t.e)
    ax.imshow(np.ma.masked_where(np.isnan(bed), shade), cmap="gray", extent=extent,
              interpolation="nearest")
    wet = np.nan_to_num(depth) > ARRIVAL_DEPTH_M
    im = ax.imshow(np.ma.masked_where(~wet, level), cmap="viridis", extent=extent, alpha=0.85,
                   interpolation="nearest")
    fig.colorbar(im, ax=ax, label=f"maximum water level [m] (depth > {ARRIVAL_DEPTH_M} m)",
                 shrink=0.7)
    for p in points:
        ax.plot(p["x"] / 1e3, p["y"] / 1e3, "r+" if p["id"].startswith("P") else "kx", ms=5)
        ax.annotate(p["id"], (p["x"] / 1e3, p["y"] / 1e3), fontsize=6,
                    xytext=(3, 2), textcoords="offset points")
    ax.set_title(title)
    ax.set_xlabel("Easting, EPSG:27572 [km]")
    ax.set_ylabel("Northing, EPSG:27572 [km]")
    fig.savefig(path, bbox_inches="tight")
    return path


def plot_particles(curves: dict[str, Path], path: Path):
    """Particle count and wall time against simulated time, one line per sea mode."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10.0, 4.2), dpi=110)
    ax1, ax2 = fig.subplots(1, 2)
    for sea, csv_path in sorted(curves.items()):
        with open(csv_path, newline="") as f:
            rows = list(csv.DictReader(f))
        t = [float(r["time_s"]) for r in rows]
        ax1.plot(t, [int(r["particles"]) for r in rows], label=f"sea as {sea}")
        ax2.plot(t, [float(r["wall_time_s"]) for r in rows], label=f"sea as {sea}")
    ax1.set_xlabel("simulated time [s]")
    ax1.set_ylabel("particles")
    ax1.set_title("particle count")
    ax2.set_xlabel("simulated time [s]")
    ax2.set_ylabel("wall time [s]")
    ax2.set_title("cost")
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
        ax.legend()
    fig.savefig(path, bbox_inches="tight")
    return path
