"""Discharge hydrographs Q(t): read, evaluate, integrate and write the ``time_s,discharge_m3s`` CSV.

The CSV format (``docs/scenario-reference.md``, ``[[inflows]] hydrograph``) is a header line
naming one time column and one discharge column, in any order, followed by one row per sample:

* time as ``time_s`` (seconds), ``time_min`` (minutes) or ``time_h`` (hours), or ``time``
  holding ISO 8601 instants (``2024-05-01T06:00:00+02:00``; one without a UTC offset is UTC,
  and a file mixes none with offsets), counted from ``[scenario] start`` when the scenario
  has one, else from the file's first row;
* discharge as ``discharge_m3s`` (m3/s) or ``discharge_cfs`` (cubic feet per second, 0.3048^3
  = 0.028316846592 m3/s each), the total through the inflow section.

Other columns are ignored; blank lines are skipped. Times must increase strictly and
discharges must be finite, >= 0 and at most ``MAX_DISCHARGE_M3S``. The file is UTF-8, with or
without a byte-order mark (``floodsph.io.text``). What was converted is reported in a sentence
per file (``floodsph check`` prints it).

Between samples the discharge is linear in time; outside the table it is zero. The volume is
the exact integral of that piecewise-linear function, so the volume a model injects by linear
interpolation equals ``Hydrograph.volume`` to round-off.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from floodsph.constants import LARGEST_VALUE
from floodsph.errors import InputError
from floodsph.io.atomic_files import atomic_path
from floodsph.io.text import read_csv_rows

TIME_COLUMN = "time_s"
DISCHARGE_COLUMN = "discharge_m3s"

TIME_UNITS = {"time_s": (1.0, "seconds"), "time_min": (60.0, "minutes"),
              "time_h": (3600.0, "hours")}
"""Numeric time columns: seconds per unit, and the unit's name."""

DATE_COLUMN = "time"
"""The time column of ISO 8601 instants."""

CUBIC_FOOT_M3 = 0.3048**3
"""One cubic foot [m3]: the international foot (0.3048 m exactly) cubed."""

DISCHARGE_UNITS = {"discharge_m3s": (1.0, "m3/s"),
                   "discharge_cfs": (CUBIC_FOOT_M3, "cubic feet per second")}
"""Discharge columns: m3/s per unit, and the unit's name."""

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


def read_hydrograph(path, name="inflows[0].hydrograph", *, start: datetime | None = None,
                    conversions: list[str] | None = None) -> Hydrograph:
    """Read a hydrograph CSV (the module's format) into a :class:`Hydrograph` in s and m3/s.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.
    name : str
        Key path used in error messages (e.g. ``inflows[0].hydrograph``).
    start : datetime, optional
        ``[scenario] start`` (timezone-aware): dates in a ``time`` column count from it; without
        it they count from the first row.
    conversions : list of str, optional
        Receives one sentence saying which columns were converted from which unit (nothing
        when the file is in ``time_s`` and ``discharge_m3s``).

    Raises
    ------
    InputError
        Naming the key, the file and (where it applies) the line: missing file, no time or no
        discharge column, two of either, non-numeric / NaN / infinite value, a date that is no
        ISO 8601 instant, dates with and without a UTC offset in one file, times not strictly
        increasing, negative discharge or one above ``MAX_DISCHARGE_M3S``, fewer than 2 rows.
    """
    path = Path(path)
    if not path.is_file():
        _fail(name, path, None, "file not found")
    rows = [(n, row) for n, row in enumerate(read_csv_rows(path, f"{name}: {path}"), start=1)
            if row]
    if not rows:
        _fail(name, path, None, "is empty (expected a header with time_s,discharge_m3s)")
    (header_line, header), data = rows[0], rows[1:]
    header = [cell.strip() for cell in header]
    time_column = _one_column(header, (*TIME_UNITS, DATE_COLUMN), "time", name, path,
                              header_line)
    q_column = _one_column(header, tuple(DISCHARGE_UNITS), "discharge", name, path, header_line)
    cells = {column: _cells(data, header.index(column), column, name, path)
             for column in (time_column, q_column)}
    lines = [n for n, _ in data]
    if time_column == DATE_COLUMN:
        t, origin = _seconds_from_dates(cells[DATE_COLUMN], lines, start, name, path)
    else:
        t = np.array([_number(text, time_column, name, path, n)
                      for text, n in zip(cells[time_column], lines, strict=True)])
        t = t * TIME_UNITS[time_column][0]
    m3s, q_unit = DISCHARGE_UNITS[q_column]
    Q = np.array([_number(text, q_column, name, path, n)
                  for text, n in zip(cells[q_column], lines, strict=True)]) * m3s
    for k, n in enumerate(lines):
        if k > 0 and t[k] <= t[k - 1]:
            order = "later" if time_column == DATE_COLUMN else "greater"
            _fail(name, path, n,
                  f"{time_column} = {cells[time_column][k].strip()} is not {order} than the "
                  f"previous time {cells[time_column][k - 1].strip()} (times must increase "
                  "strictly)")
        if Q[k] < 0.0:
            _fail(name, path, n, f"{q_column} = {cells[q_column][k].strip()} is negative")
        if Q[k] > MAX_DISCHARGE_M3S:
            _fail(name, path, n,
                  f"{q_column} = {Q[k] / m3s:g}{'' if m3s == 1.0 else f' ({Q[k]:g} m3/s)'} "
                  "is above "
                  f"{MAX_DISCHARGE_M3S:g} m3/s, more than any flood on record; check the "
                  f"units ({q_unit}) and the value")
    if len(lines) < 2:
        _fail(name, path, None, f"needs at least 2 data rows, found {len(lines)}")
    if conversions is not None:
        said = []
        if time_column == DATE_COLUMN:
            said.append(f"time from the ISO 8601 dates of column 'time', in seconds from "
                        f"{origin}")
        elif time_column != TIME_COLUMN:
            seconds, unit = TIME_UNITS[time_column]
            said.append(f"time from column {time_column!r} in {unit} (x {seconds:g} s)")
        if q_column != DISCHARGE_COLUMN:
            said.append(f"discharge from column {q_column!r} in {q_unit} "
                        f"(x {m3s:.11g} m3/s)")
        if said:
            conversions.append(f"{name}: {path.name}: " + "; ".join(said))
    return Hydrograph(t, Q)


def _one_column(header, names, what, name, path, line) -> str:
    """The one column of ``names`` the header holds; none or two are errors."""
    present = [column for column in names if column in header]
    if not present:
        _fail(name, path, line, f"missing {what} column: one of {', '.join(map(repr, names))} "
                                f"(found: {', '.join(header)})")
    if len(present) > 1:
        _fail(name, path, line, f"{len(present)} {what} columns "
                                f"({', '.join(map(repr, present))}); keep one")
    return present[0]


def _cells(data, k, column, name, path) -> list[str]:
    """The text of column ``k`` in every data row; an empty cell is an error."""
    out = []
    for n, row in data:
        if k >= len(row) or not row[k].strip():
            _fail(name, path, n, f"no value in column {column!r}")
        out.append(row[k])
    return out


def _seconds_from_dates(texts, lines, start, name, path) -> tuple[np.ndarray, str]:
    """Seconds from ``start`` (or the first date) of ISO 8601 instants, and that origin in
    words. An instant without a UTC offset is UTC; a file may not mix the two."""
    instants = []
    first_kind = None
    for text, n in zip(texts, lines, strict=True):
        try:
            instant = datetime.fromisoformat(text.strip())
        except ValueError:
            _fail(name, path, n, f"time = {text.strip()!r} is not an ISO 8601 date and time "
                                 "(e.g. 2024-05-01T06:00:00Z)")
        aware = instant.tzinfo is not None
        if first_kind is None:
            first_kind = (aware, lines[0], text.strip())
        elif aware != first_kind[0]:
            has = {True: "has a", False: "has no"}
            _fail(name, path, n,
                  f"time = {text.strip()} {has[aware]} UTC offset, but line {first_kind[1]} "
                  f"({first_kind[2]}) {has[first_kind[0]]} UTC offset; give every date an "
                  "offset, or none (then all are UTC)")
        instants.append(instant if aware else instant.replace(tzinfo=UTC))
    if start is not None:
        origin, said = start, f"scenario.start ({start.isoformat()})"
    else:
        origin, said = instants[0], f"the first row ({instants[0].isoformat()})"
    return np.array([(i - origin).total_seconds() for i in instants]), said


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
