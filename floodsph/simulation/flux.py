"""Flux lines: the discharge through named polylines, counted from the water that crosses them.

A flux line (``[[flux_lines]]``) is a polyline A_0 A_1 ... A_k. Each particle that moves from
one side of a segment to the other, across the segment itself, carries its volume m / rho_w
over the line: positive when it goes from the left of the direction of travel (A_0 towards
A_k) to the right, negative the other way. Every displacement of water is counted, so the
volume is exact, with no interpolation of depth or velocity onto the line:

* the drift of each step, x^n -> x^{n+1} (``floodsph.model.stages.move``; walls reflect a
  move, and the chord from the old to the new position is counted);
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
from numba import njit

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

    STATE = ("since_row", "forward", "backward", "t_last", "rows")
    """What changes during a run (``floodsph.simulation.state_arrays``): the volumes counted
    and the rows recorded."""

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
        n = len(self.names)
        self.since_row = np.zeros(n)  # net volume since the last row [m3]
        self.forward = np.zeros(n)  # left -> right over the run [m3]
        self.backward = np.zeros(n)  # right -> left over the run [m3]
        self.t_last: float | None = None
        self.rows: list[tuple[float, ...]] = []

    def __repr__(self) -> str:
        return f"FluxLines({', '.join(self.names)}; {self.seg.shape[0]} segments)"

    # -- counting ----------------------------------------------------------------------------
    def count(self, x0, y0, x1, y1, m) -> None:
        """Add the volume m / rho_w [m3] of each move (x0, y0) -> (x1, y1) [m] that crosses a
        line, with its sign (module docstring)."""
        if self.seg.shape[0] == 0 or len(x0) == 0:
            return
        n = len(self.names)
        forward, backward = np.zeros(n), np.zeros(n)
        count_crossings(*(np.ascontiguousarray(a, dtype=np.float64) for a in (x0, y0, x1, y1, m)),  # type: ignore[call-arg]  # numba
                        self.seg, self.owner, forward, backward)
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


@njit(cache=True)
def count_crossings(x0, y0, x1, y1, m, seg, owner, forward, backward):
    """Add m / rho_w of each move (x0, y0) -> (x1, y1) that crosses a segment (x_a, y_a, x_b,
    y_b) of ``seg`` to ``forward[owner]`` (from the left of a -> b to the right) or
    ``backward[owner]`` (the other way). A move crosses where its ends lie strictly left and
    not strictly left of the segment's line, at a point from a up to, not including, b."""
    for i in range(x0.shape[0]):
        px0, py0, px1, py1 = x0[i], y0[i], x1[i], y1[i]
        for k in range(seg.shape[0]):
            ax, ay, bx, by = seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3]
            if (max(px0, px1) < min(ax, bx) or min(px0, px1) > max(ax, bx)
                    or max(py0, py1) < min(ay, by) or min(py0, py1) > max(ay, by)):
                continue
            dx, dy = bx - ax, by - ay
            s0 = dx * (py0 - ay) - dy * (px0 - ax)
            s1 = dx * (py1 - ay) - dy * (px1 - ax)
            left = s0 > 0.0
            if left == (s1 > 0.0):
                continue
            f = s0 / (s0 - s1)
            qx = px0 + f * (px1 - px0)
            qy = py0 + f * (py1 - py0)
            w = ((qx - ax) * dx + (qy - ay) * dy) / (dx * dx + dy * dy)
            if w < 0.0 or w >= 1.0:
                continue
            if left:
                forward[owner[k]] += m[i] / RHO_WATER
            else:
                backward[owner[k]] += m[i] / RHO_WATER
