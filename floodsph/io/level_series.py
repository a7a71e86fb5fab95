"""Water-level time series eta(t) of a level boundary: read the ``time_s,level_m`` CSV, evaluate.

The CSV (``docs/level-boundary.md``) has a header line naming the columns ``time_s`` (seconds
from the start of the run) and ``level_m`` (the water-surface elevation [m], in the DEM's
vertical datum), in any order; other columns are ignored and blank lines skipped. Times must
increase strictly (the levels' range is checked with the section, ``floodsph.checks.levels``).

Between rows the level is linear in time; before the first row and after the last it is held
at the first and last level (a tide table that ends early keeps its last level rather than
stopping the run). A constant ``level_m`` is the series of one row.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from floodsph.errors import InputError
from floodsph.io.hydrograph import read_csv_columns

TIME_COLUMN = "time_s"
LEVEL_COLUMN = "level_m"


@dataclass(frozen=True, eq=False)
class LevelSeries:
    """A level table eta(t) [m]: linear between rows, held constant beyond its ends.

    Attributes
    ----------
    t : numpy.ndarray
        Row times [s], strictly increasing, at least one.
    level : numpy.ndarray
        Water-surface elevation at the row times [m].
    """

    t: np.ndarray
    level: np.ndarray

    def __post_init__(self):
        for name in ("t", "level"):
            values = np.array(getattr(self, name), dtype=np.float64).reshape(-1)
            values.flags.writeable = False
            object.__setattr__(self, name, values)

    @classmethod
    def constant(cls, level_m: float) -> LevelSeries:
        """The series of a level that never changes [m]."""
        return cls(np.zeros(1), np.array([level_m]))

    def at(self, t: float) -> float:
        """eta(t) [m]: linear interpolation, the end values held outside the table."""
        return float(np.interp(t, self.t, self.level))

    def highest(self) -> float:
        """The highest level the series reaches [m]."""
        return float(self.level.max())


def read_level_series(path, name: str) -> LevelSeries:
    """Read a ``time_s,level_m`` CSV (module docstring) into a :class:`LevelSeries`.

    ``name`` is the key path for messages (``"scenario.toml: level_boundaries[0].file"``).

    Raises
    ------
    InputError
        A missing file or column, a value that is no number, fewer than one row or times
        that do not increase strictly; the message names the key, the file and the line.
    """
    values, lines = read_csv_columns(path, name, (TIME_COLUMN, LEVEL_COLUMN))
    t, level = values[TIME_COLUMN], values[LEVEL_COLUMN]
    if t.size == 0:
        raise InputError(f"{name}: {path}: no rows below the header (expected "
                         f"{TIME_COLUMN},{LEVEL_COLUMN} rows)")
    for k in range(1, t.size):
        if t[k] <= t[k - 1]:
            raise InputError(f"{name}: {path}, line {lines[k]}: {TIME_COLUMN} = {t[k]:g} does "
                             f"not follow {t[k - 1]:g}; times must increase strictly")
    return LevelSeries(t, level)
