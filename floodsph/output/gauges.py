"""Point gauges: depth, water level and speed time series at fixed points -> ``gauges.csv``.

Values are the Shepard SPH interpolation of the particles at the gauge point
(:func:`floodsph.output.rasterise.interpolate`); level = d + b with b the bilinear DEM
elevation at the point. A gauge that is dry (d <= wet threshold, or no particle support)
reports NaN for all three (GeoClaw #540: values on dry gauges give step artefacts).
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from pathlib import Path

import numpy as np

from floodsph.checks.placement import lonlat_hint, user_extent_text
from floodsph.errors import InputError
from floodsph.io.coordinates import to_model
from floodsph.io.text import header_found, read_text
from floodsph.output.grid import bilinear

HEADER = ("time_s", "id", "depth_m", "level_m", "speed_ms")
CALENDAR_COLUMN = "time_utc"
"""The column added when the scenario has a calendar start: start + time_s, ISO 8601 in UTC."""


@dataclass(frozen=True)
class GaugePoints:
    """Gauge ids, positions in LOCAL coordinates [m] and bed elevation there [m]."""

    ids: tuple[str, ...]
    x: np.ndarray
    y: np.ndarray
    bed: np.ndarray


def read_gauge_file(path, terrain) -> GaugePoints:
    """Read a UTF-8 CSV (a BOM allowed) with columns ``id, x, y`` (world coordinates in the
    CRS of the inline coordinates, ``floodsph.io.coordinates``).

    Raises InputError naming the file and line for a file that is not UTF-8, a missing
    column, a non-numeric coordinate, a duplicate id or a point outside the DEM (saying so
    when the points look like longitude/latitude).
    """
    path = Path(path)
    text = read_text(path, f"gauge file {path}")
    with io.StringIO(text, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows or not {"id", "x", "y"} <= set(rows[0]):
        raise InputError(f"{path}: gauge file needs the columns id, x, y; "
                         f"{header_found(text)}")
    ids: list[str] = []
    xs: list[float] = []
    ys: list[float] = []
    for line, row in enumerate(rows, start=2):
        try:
            x, y = float(row["x"]), float(row["y"])
        except (TypeError, ValueError):
            raise InputError(f"{path}, line {line}: x and y must be numbers, got "
                             f"{row['x']!r}, {row['y']!r}") from None
        mx, my = to_model(terrain, [(x, y)], f"{path}, line {line}")[0]
        lx, ly = mx - terrain.x0, my - terrain.y0
        if not (0.0 <= lx <= terrain.width and 0.0 <= ly <= terrain.height):
            raise InputError(f"{path}, line {line}: gauge {row['id']!r} at ({x}, {y}) is "
                             f"outside the DEM extent {user_extent_text(terrain)}"
                             f"{lonlat_hint([(mx, my)], terrain)}")
        if row["id"] in ids:
            raise InputError(f"{path}, line {line}: duplicate gauge id {row['id']!r}")
        ids.append(row["id"])
        xs.append(lx)
        ys.append(ly)
    gx, gy = np.array(xs), np.array(ys)
    return GaugePoints(tuple(ids), gx, gy, bilinear(terrain.elevation, terrain.dx, terrain.dy,
                                                    gx, gy))


class Gauges:
    """Record gauge time series every ``interval_s`` of simulated time.

    Parameters
    ----------
    points : GaugePoints
    interval_s : float
        Sampling interval [s] used by :meth:`due` / :meth:`record`.
    wet_threshold : float
        Depth [m] at or below which a gauge reports NaN.
    min_support : float
        Minimum kernel sum (see :mod:`floodsph.output.rasterise`).
    start : datetime, optional
        The calendar instant of t = 0 (``[scenario] start``); adds :data:`CALENDAR_COLUMN`.
    """

    def __init__(self, points: GaugePoints, interval_s: float = 10.0,
                 wet_threshold: float = 0.01, min_support: float = 0.5,
                 start: datetime | None = None):
        self.points = points
        self.start = start
        self.interval_s = float(interval_s)
        self.wet_threshold = float(wet_threshold)
        self.min_support = float(min_support)
        self.t_last: float | None = None
        self.rows: list[tuple] = []

    def sample(self, t, x, y, u, v, m, rho, h, level=None, walls=None) -> None:
        """Interpolate the particles at the gauges at time t [s] and store one row each;
        ``level``: the particles' free-surface levels, ``walls`` the walls that hide gauges
        from particles (``rasterise.interpolate``)."""
        from floodsph.output.rasterise import interpolate

        p = self.points
        d, gu, gv, _ = interpolate(p.x, p.y, x, y, u, v, m, rho, h, self.min_support, level,
                                   p.bed, walls)
        for k, gid in enumerate(p.ids):
            if d[k] > self.wet_threshold:
                row = (float(t), gid, d[k], d[k] + p.bed[k], math.hypot(gu[k], gv[k]))
            else:
                row = (float(t), gid, math.nan, math.nan, math.nan)
            self.rows.append(row)
        self.t_last = float(t)

    def record(self, model) -> None:
        """Sample a FloodModel (``model.t``, ``model.particles``); the simulation's schedule
        (``floodsph.simulation.recorders``) decides when."""
        q = model.particles
        self.sample(model.t, q.x, q.y, q.u, q.v, q.m, q.rho, q.h, model.surface_levels(),
                    model.map_walls())

    def write_csv(self, path) -> Path:
        """Write ``time_s, id, depth_m, level_m, speed_ms`` (mm / ms precision; ``nan`` = dry),
        and ``time_utc`` (``2024-01-15T06:10:00.000Z``) when the scenario has a start."""
        path = Path(path)
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(HEADER + ((CALENDAR_COLUMN,) if self.start is not None else ()))
            for t, gid, d, lvl, s in self.rows:
                row: tuple[str, ...] = (f"{t:.3f}", gid, f"{d:.4f}", f"{lvl:.4f}", f"{s:.4f}")
                if self.start is not None:
                    row += (utc_text(self.start + timedelta(seconds=round(t, 3))),)
                w.writerow(row)
        return path


def utc_text(instant: datetime) -> str:
    """An instant as ISO 8601 in UTC to the millisecond: ``2024-01-15T06:10:00.000Z``."""
    return instant.astimezone(UTC).strftime("%Y-%m-%dT%H:%M:%S.%f")[:-3] + "Z"
