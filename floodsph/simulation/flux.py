"""Flux lines: the discharge through named polylines, counted from the water that crosses them.

A flux line (``[[flux_lines]]``) is a polyline A_0 A_1 ... A_k. Each particle that moves from
one side of a segment to the other, across the segment itself, carries its volume m / rho_w
over the line: positive when it goes from the left of the direction of travel (A_0 towards
A_k) to the right, negative the other way. Every displacement of water is counted, so the
volume is exact, with no interpolation of depth or velocity onto the line:

* the drift of each step, x^n -> x^{n+1} (``FloodModel.move``; walls reflect a move, and
  the chord from the old to the new position is counted);
* the daughters of a split (parent -> each daughter, with the daughter's mass) and a
  coalesced pair (each of the two -> the merged particle, with its own mass,
  ``floodsph.model.refinement``);
* water an inflow mirrors back across its section (``floodsph.boundaries.inflow``).

For a line that divides the domain in two (drawn from bank to bank, or beyond the DEM), the
net volume through it is therefore the change of the volume on its right side less what
entered or left the model there, to round-off. A segment counts the crossing points from its
first end up to, but not including, its second, so a move through a vertex is counted once.

Each row of ``flux.csv`` is the mean discharge over the interval that ends at its time: the
net volume crossed since the previous row divided by the time between them [m3/s].
:meth:`FluxLines.summary` gives the volumes over the whole run for ``run.json``. The object
lives on the model (``FloodModel.flux_lines``), so a checkpoint holds what it has counted and
recorded, and a resumed run continues it exactly.
"""

from __future__ import annotations

import csv
from datetime import datetime, timedelta
from pathlib import Path

import numpy as np

from floodsph.constants import RHO_WATER

TIME_COLUMN = "time_s"
CALENDAR_COLUMN = "time_utc"
"""The column added when the scenario has a calendar start, as in gauges.csv."""
UNIT_SUFFIX = "_m3s"
"""A line's column in flux.csv is its name with this suffix."""


class FluxLines:
    """The crossings of named polylines, and the discharge rows of ``flux.csv``.

    Parameters
    ----------
    lines : sequence of (name, (k, 2) array)
        Each line's name and vertices in local coordinates [m].
    """

    def __init__(self, lines):
        self.names = tuple(name for name, _ in lines)
        seg, owner = [], []
        for index, (_, points) in enumerate(lines):
            pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
            for a, b in zip(pts[:-1], pts[1:], strict=True):
                if np.any(a != b):
                    seg.append((*a, *b))
                    owner.append(index)
        self.seg = np.asarray(seg, dtype=np.float64).reshape(-1, 4)
        self.owner = np.asarray(owner, dtype=np.int64)
        ends = np.concatenate([self.seg[:, :2], self.seg[:, 2:]]) if len(seg) else np.zeros((1, 2))
        self.box = (*ends.min(axis=0), *ends.max(axis=0))
        n = len(self.names)
        self.since_row = np.zeros(n)  # net volume since the last row [m3]
        self.forward = np.zeros(n)  # left -> right over the run [m3]
        self.backward = np.zeros(n)  # right -> left over the run [m3]
        self.t_last: float | None = None
        self.rows: list[tuple[float, ...]] = []

    def __repr__(self) -> str:
        return f"FluxLines({', '.join(self.names)}; {self.seg.shape[0]} segments)"

    # -- counting ----------------------------------------------------------------------------
    def crossings(self, x0, y0, x1, y1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The moves (x0, y0) -> (x1, y1) that cross a segment: (move index, line index,
        sign), one entry per crossing; sign +1 from left to right of the segment, -1 back."""
        xmin, ymin, xmax, ymax = self.box
        near = ((np.minimum(x0, x1) <= xmax) & (np.maximum(x0, x1) >= xmin)
                & (np.minimum(y0, y1) <= ymax) & (np.maximum(y0, y1) >= ymin))
        moves = np.flatnonzero(near)
        found_i, found_line, found_sign = [], [], []
        if moves.size:
            px0, py0, px1, py1 = x0[moves], y0[moves], x1[moves], y1[moves]
            for k, (ax, ay, bx, by) in enumerate(self.seg):
                dx, dy = bx - ax, by - ay
                s0 = dx * (py0 - ay) - dy * (px0 - ax)  # > 0: left of A -> B
                s1 = dx * (py1 - ay) - dy * (px1 - ax)
                left0, left1 = s0 > 0.0, s1 > 0.0
                hit = np.flatnonzero(left0 != left1)
                if hit.size == 0:
                    continue
                f = s0[hit] / (s0[hit] - s1[hit])  # where the move meets the segment's line
                qx = px0[hit] + f * (px1[hit] - px0[hit])
                qy = py0[hit] + f * (py1[hit] - py0[hit])
                w = ((qx - ax) * dx + (qy - ay) * dy) / (dx * dx + dy * dy)
                on = (w >= 0.0) & (w < 1.0)
                hit = hit[on]
                found_i.append(moves[hit])
                found_line.append(np.full(hit.size, self.owner[k]))
                found_sign.append(np.where(left0[hit], 1.0, -1.0))
        if not found_i:
            empty = np.zeros(0, dtype=np.int64)
            return empty, empty, np.zeros(0)
        return np.concatenate(found_i), np.concatenate(found_line), np.concatenate(found_sign)

    def count(self, x0, y0, x1, y1, m) -> None:
        """Add the volume m / rho_w [m3] of each move (x0, y0) -> (x1, y1) [m] that crosses a
        line, with its sign (module docstring)."""
        if self.seg.shape[0] == 0 or len(x0) == 0:
            return
        i, line, sign = self.crossings(np.asarray(x0), np.asarray(y0), np.asarray(x1),
                                       np.asarray(y1))
        if i.size == 0:
            return
        volume = np.asarray(m)[i] / RHO_WATER
        n = len(self.names)
        forward = np.bincount(line[sign > 0], volume[sign > 0], minlength=n)
        backward = np.bincount(line[sign < 0], volume[sign < 0], minlength=n)
        self.forward += forward
        self.backward += backward
        self.since_row += forward - backward

    # -- records ------------------------------------------------------------------------------
    def record(self, t: float) -> None:
        """Close the interval that ends at ``t`` [s]: one row of mean discharges [m3/s]. The
        first call (the start of the run) only opens the first interval."""
        t = float(t)
        if self.t_last is not None and t > self.t_last:
            q = self.since_row / (t - self.t_last)
            self.rows.append((t, *(float(v) for v in q)))
            self.since_row[:] = 0.0
        if self.t_last is None or t > self.t_last:
            self.t_last = t

    def header(self) -> tuple[str, ...]:
        return (TIME_COLUMN, *(name + UNIT_SUFFIX for name in self.names))

    def write_csv(self, path, start: datetime | None = None) -> Path:
        """Write ``flux.csv``: ``time_s`` (ms), one column ``<name>_m3s`` per line (full
        precision), and ``time_utc`` when the scenario has a calendar ``start``."""
        from floodsph.output.gauges import utc_text

        path = Path(path)
        with open(path, "w", newline="", encoding="utf-8") as f:
            w = csv.writer(f)
            w.writerow(self.header() + ((CALENDAR_COLUMN,) if start is not None else ()))
            for t, *q in self.rows:
                row = (f"{t:.3f}", *(repr(v) for v in q))
                if start is not None:
                    row += (utc_text(start + timedelta(seconds=round(t, 3))),)
                w.writerow(row)
        return path

    def summary(self) -> list[dict]:
        """Per line, the volumes over the run [m3] for ``run.json``: ``volume_net_m3`` (left
        to right less right to left), ``volume_left_to_right_m3``, ``volume_right_to_left_m3``."""
        return [{"name": name, "volume_net_m3": float(f - b),
                 "volume_left_to_right_m3": float(f), "volume_right_to_left_m3": float(b)}
                for name, f, b in zip(self.names, self.forward, self.backward, strict=True)]
