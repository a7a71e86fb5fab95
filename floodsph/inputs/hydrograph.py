"""Discharge hydrographs Q(t): read, evaluate, integrate and write the ``time_s,discharge_m3s`` CSV.

The CSV format (scenario-format.md, ``[[inflows]] hydrograph``) is a header line naming at least
the columns ``time_s`` (s) and ``discharge_m3s`` (m3/s, total through the inflow section), in any
order, followed by one row per sample. Other columns are ignored; blank lines are skipped. Times
must increase strictly and discharges must be finite, >= 0 and at most ``MAX_DISCHARGE_M3S``.
The file is UTF-8, with or without a byte-order mark (``floodsph.io.text``).

Between samples the discharge is linear in time; outside the table it is zero. The volume is
the exact integral of that piecewise-linear function, so the volume a model injects by linear
interpolation equals ``Hydrograph.volume`` to round-off.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from floodsph.errors import InputError
from floodsph.io.text import read_csv_rows
from floodsph.run.atomic_files import atomic_path
from floodsph.scenario.schema import LARGEST_VALUE

TIME_COLUMN = "time_s"
DISCHARGE_COLUMN = "discharge_m3s"

MAX_DISCHARGE_M3S = 1.0e7
"""The largest discharge accepted [m3/s]: about thirty times the largest river discharge ever
gauged (the Amazon, about 3e5 m3/s), above the peak of every known dam or landslide-dam
breach (a few 1e5 m3/s at most), of the order of the prehistoric glacial-lake outbursts. A
value above it is a unit or typing error."""


@dataclass(frozen=True, eq=False)
class Hydrograph:
    """A discharge table Q(t), linear between samples and zero outside the table.

    Attributes
    ----------
    t : numpy.ndarray
        Sample times [s], float64, strictly increasing, at least 2 (read-only).
    Q : numpy.ndarray
        Discharge at the sample times [m3/s], float64, >= 0 (read-only).
    """

    t: np.ndarray
    Q: np.ndarray

    def __post_init__(self):
        t = np.array(self.t, dtype=np.float64)
        Q = np.array(self.Q, dtype=np.float64)
        t.flags.writeable = False
        Q.flags.writeable = False
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "Q", Q)

    def discharge(self, t):
        """Discharge at time(s) ``t`` [m3/s]: linear interpolation, 0 before and after the table."""
        return np.interp(t, self.t, self.Q, left=0.0, right=0.0)

    def _cumulative(self, tau):
        """Volume released from ``t[0]`` to ``tau`` (clipped to the table) [m3].

        On sample interval i, with s = tau - t_i and slope a = (Q_{i+1} - Q_i)/(t_{i+1} - t_i),
        V(tau) = V_i + Q_i s + a s^2 / 2, where V_i is the trapezoidal volume up to t_i.
        """
        t, Q = self.t, self.Q
        tau = np.clip(np.asarray(tau, dtype=np.float64), t[0], t[-1])
        dt = np.diff(t)
        nodes = np.concatenate(([0.0], np.cumsum(0.5 * (Q[1:] + Q[:-1]) * dt)))
        i = np.clip(np.searchsorted(t, tau, side="right") - 1, 0, len(t) - 2)
        s = tau - t[i]
        slope = (Q[i + 1] - Q[i]) / dt[i]
        return nodes[i] + Q[i] * s + 0.5 * slope * s * s

    def volume(self, t0, t1):
        """Exact integral of Q from ``t0`` to ``t1`` [m3] (negative when ``t1 < t0``)."""
        return self._cumulative(t1) - self._cumulative(t0)

    def total_volume(self):
        """Integral of Q over the whole table [m3] (the trapezoidal sum, which is exact here)."""
        return float(np.sum(0.5 * (self.Q[1:] + self.Q[:-1]) * np.diff(self.t)))


def _fail(name, path, line, message):
    where = f"{name}: {path}" if line is None else f"{name}: {path}, line {line}"
    raise InputError(f"{where}: {message}")


def _number(text, column, name, path, line):
    try:
        value = float(text)
    except ValueError:
        _fail(name, path, line, f"{column} = {text.strip()!r} is not a number")
    if math.isnan(value):
        _fail(name, path, line, f"{column} is NaN")
    if math.isinf(value):
        _fail(name, path, line, f"{column} = {text.strip()} is not finite")
    if abs(value) > LARGEST_VALUE:
        _fail(name, path, line, f"{column} = {text.strip()} is beyond +-{LARGEST_VALUE:g}, "
                                "more than any quantity of a flood scenario in SI units")
    return value


def read_csv_columns(path, name, columns, one_of=()):
    """Read numeric columns of a CSV file with a header line (a shared, strict reader).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file. Blank lines are skipped; columns not asked for are ignored.
    name : str
        Key path used in error messages.
    columns : sequence of str
        Columns that must be present.
    one_of : sequence of str
        Alternative columns of which exactly the first one present is read (none present is an
        error listing them); empty for none.

    Returns
    -------
    values : dict of str to numpy.ndarray
        Float64 values of each column read.
    lines : list of int
        The 1-based line number of each data row, for callers' own checks.

    Raises
    ------
    InputError
        Naming the key, the file and the line: missing file, not UTF-8, missing column
        (listing the columns found), empty cell, non-numeric, NaN, infinite value or one
        beyond ``LARGEST_VALUE``.
    """
    path = Path(path)
    if not path.is_file():
        _fail(name, path, None, "file not found")
    rows = [(n, row) for n, row in enumerate(read_csv_rows(path, f"{name}: {path}"), start=1)
            if row]
    if not rows:
        _fail(name, path, None, f"is empty (expected a header with {','.join(columns)})")
    header_line, header = rows[0][0], [cell.strip() for cell in rows[0][1]]
    wanted = list(columns)
    if one_of:
        present = [column for column in one_of if column in header]
        if not present:
            _fail(name, path, header_line,
                  f"missing column: one of {', '.join(map(repr, one_of))} "
                  f"(found: {', '.join(header)})")
        wanted.append(present[0])
    for column in columns:
        if column not in header:
            _fail(name, path, header_line,
                  f"missing column {column!r} (found: {', '.join(header)})")
    index = {column: header.index(column) for column in wanted}
    values = {column: [] for column in wanted}
    lines = []
    for n, row in rows[1:]:
        for column, k in index.items():
            if k >= len(row) or not row[k].strip():
                _fail(name, path, n, f"no value in column {column!r}")
            values[column].append(_number(row[k], column, name, path, n))
        lines.append(n)
    return {column: np.array(v, dtype=np.float64) for column, v in values.items()}, lines


def read_hydrograph(path, name="inflows[0].hydrograph") -> Hydrograph:
    """Read a ``time_s,discharge_m3s`` CSV into a :class:`Hydrograph`.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.
    name : str
        Key path used in error messages (e.g. ``inflows[0].hydrograph``).

    Raises
    ------
    InputError
        Naming the key, the file and (where it applies) the line: missing file, missing column,
        non-numeric / NaN / infinite value, times not strictly increasing, negative discharge
        or one above ``MAX_DISCHARGE_M3S``, fewer than 2 data rows.
    """
    values, lines = read_csv_columns(path, name, (TIME_COLUMN, DISCHARGE_COLUMN))
    t, Q = values[TIME_COLUMN], values[DISCHARGE_COLUMN]
    for k, n in enumerate(lines):
        if k > 0 and t[k] <= t[k - 1]:
            _fail(name, path, n,
                  f"time_s = {t[k]:g} is not greater than the previous time {t[k - 1]:g} "
                  "(times must increase strictly)")
        if Q[k] < 0.0:
            _fail(name, path, n, f"discharge_m3s = {Q[k]:g} is negative")
        if Q[k] > MAX_DISCHARGE_M3S:
            _fail(name, path, n,
                  f"discharge_m3s = {Q[k]:g} is above {MAX_DISCHARGE_M3S:g} m3/s, more than "
                  "any flood on record; check the units (m3/s) and the value")
    if len(lines) < 2:
        _fail(name, path, None, f"needs at least 2 data rows, found {len(lines)}")
    return Hydrograph(t, Q)


def write_hydrograph_csv(path, t, Q):
    """Write ``time_s,discharge_m3s`` rows at full precision, readable by :func:`read_hydrograph`.

    The file is written to a temporary name in the same folder and renamed at the end, so an
    interrupted write never leaves a truncated hydrograph under the final name.

    Raises
    ------
    ValueError
        If ``t`` and ``Q`` differ in length or hold fewer than 2 samples.
    """
    t = np.asarray(t, dtype=np.float64)
    Q = np.asarray(Q, dtype=np.float64)
    if t.ndim != 1 or t.shape != Q.shape or t.size < 2:
        raise ValueError("t and Q must be 1-D arrays of the same length >= 2")
    path = Path(path)
    with atomic_path(path) as partial, open(partial, "w", newline="",
                                            encoding="utf-8") as stream:
        writer = csv.writer(stream)
        writer.writerow([TIME_COLUMN, DISCHARGE_COLUMN])
        writer.writerows((repr(float(a)), repr(float(b))) for a, b in zip(t, Q, strict=True))
