"""Running flood envelopes on the map grid, updated inside the run (not from snapshots).

Maxima computed from saved snapshots miss the peaks between them (qgis-crayfish-plugin #202;
GeoClaw fgmax exists for that reason), so the run loop calls :meth:`Envelopes.update` at the
first step at or after every ``interval_s`` of simulated time (default 1 s; the time step is
not shortened to land on those marks). Each update rasterises the particles
(:func:`floodsph.output.rasterise.rasterise`) and, cell by cell, with d the depth [m],
s = |(u, v)| the speed [m/s], b the bed [m] and d_wet the wet threshold [m]:

* where the cell has particle support (d not NaN): ``max_depth`` = max d,
  ``time_of_max_depth`` = first t of that maximum, ``max_level`` = max (d + b);
* where it is also wet (d > d_wet): ``max_speed`` = max s, ``max_unit_discharge`` =
  max d s [m2/s], ``arrival_time`` = first t wet, ``duration`` += the time since the previous
  update (the wet state at t stands for the interval since the last update), and the UK
  and Australian hazard classes of the same (d, s) (:mod:`floodsph.output.hazard`) are kept
  as the maximum class over all updates (AIDR 7-3: peak hazard can precede peak depth).

So cells touched only by a film thinner than d_wet keep their max depth and level but are
dry (NaN arrival, speed, duration; class 0). Never-supported cells are NaN everywhere.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.output.hazard import HazardTables, arr_class, uk_class
from floodsph.output.rasterise import MIN_SUPPORT, rasterise

MAPS = {
    "max_depth": ("maximum water depth", "m", "time: maximum"),
    "max_speed": ("maximum depth-averaged speed", "m s-1", "time: maximum"),
    "max_unit_discharge": ("maximum unit discharge (depth x speed)", "m2 s-1", "time: maximum"),
    "max_level": ("maximum water-surface elevation", "m", "time: maximum"),
    "arrival_time": ("time since the start at which the cell first became wet", "s", None),
    "time_of_max_depth": ("time since the start of the maximum depth", "s", None),
    "duration": ("total time wet", "s", "time: sum"),
    "hazard_uk": ("UK flood hazard rating class (maximum over time)", "1", "time: maximum"),
    "hazard_arr": ("Australian flood hazard class H1-H6 (maximum over time)", "1",
                   "time: maximum"),
}
"""Map name -> (long name, units, CF cell_methods) for every envelope map, in file order."""

CLASS_MAPS = ("hazard_uk", "hazard_arr")
UPDATE_ORDER = ("max_depth", "time_of_max_depth", "max_level", "max_speed",
                "max_unit_discharge", "arrival_time", "duration", "hazard_uk", "hazard_arr")
"""The order of the map arguments of :func:`update_cells`."""


@njit(parallel=True, cache=True)
def update_cells(t, dt, d, u, v, bed, wet, uk_upper, debris_upper, debris_df, debris_speed,
                 arr_limits, max_depth, time_of_max_depth, max_level, max_speed,
                 max_unit_discharge, arrival_time, duration, hazard_uk, hazard_arr):
    """Fold one interpolated state (d, u, v at time t) into the envelope grids (flat, in place).

    Cell i reads d[i], u[i], v[i], bed[i] and writes only the i-th entry of each grid.
    """
    for i in prange(d.shape[0]):
        di = d[i]
        if math.isnan(di):
            continue
        if not di <= max_depth[i]:
            max_depth[i] = di
            time_of_max_depth[i] = t
        level = di + bed[i]
        if not level <= max_level[i]:
            max_level[i] = level
        if di <= wet:
            continue
        s = math.sqrt(u[i] * u[i] + v[i] * v[i])
        if not s <= max_speed[i]:
            max_speed[i] = s
        if not di * s <= max_unit_discharge[i]:
            max_unit_discharge[i] = di * s
        if math.isnan(arrival_time[i]):
            arrival_time[i] = t
            duration[i] = 0.0
        duration[i] += dt
        k = uk_class(di, s, uk_upper, debris_upper, debris_df, debris_speed)
        if k > hazard_uk[i]:
            hazard_uk[i] = k
        k = arr_class(di, s, arr_limits)
        if k > hazard_arr[i]:
            hazard_arr[i] = k


class Envelopes:
    """Maximum/arrival/duration/hazard maps on an :class:`~floodsph.output.grid.OutputGrid`.

    Parameters
    ----------
    grid : OutputGrid
        The map grid (row 0 = south) with its bed elevation.
    wet_threshold : float
        Depth d_wet [m] above which a cell is wet (arrival, duration, speed, hazard).
    land_use : str
        Debris-factor column of the UK hazard table (see :mod:`floodsph.output.hazard`).
    min_support : float
        Minimum kernel sum for a cell to be mapped (see :mod:`floodsph.output.rasterise`).
    interval_s : float
        Simulated time between updates [s]; used by :meth:`due` and :meth:`record`.
    """

    def __init__(self, grid, wet_threshold: float = 0.01, land_use: str = "conservative",
                 min_support: float = MIN_SUPPORT, interval_s: float = 1.0):
        self.grid = grid
        self.wet_threshold = float(wet_threshold)
        self.tables = HazardTables.load(land_use)
        self.min_support = float(min_support)
        self.interval_s = float(interval_s)
        self.t_last: float | None = None
        self.updates = 0
        self._maps = {name: np.full(grid.shape, np.nan) for name in MAPS}
        for name in CLASS_MAPS:
            self._maps[name] = np.zeros(grid.shape, dtype=np.uint8)
        self._bed = np.ascontiguousarray(grid.bed, dtype=np.float64)

    def update(self, t, dt_since_last, x, y, u, v, m, rho, h, level=None,
               walls=None) -> None:
        """Rasterise the particles at time t [s] and fold the state into every map.

        ``dt_since_last`` [s] is added to the duration of the cells wet now; ``level``: the
        particles' free-surface levels, mapped less the bed; ``walls``: the walls that hide
        cells from particles (``rasterise``).
        """
        d, uu, vv, _ = rasterise(self.grid, x, y, u, v, m, rho, h, self.min_support, level,
                                 walls)
        self.fold(t, dt_since_last, d, uu, vv)

    def fold(self, t, dt_since_last, d, u, v) -> None:
        """Fold gridded depth d [m] and velocity (u, v) [m/s] at time t into the maps."""
        g = self._maps
        tb = self.tables
        update_cells(float(t), float(dt_since_last), _flat(d), _flat(u), _flat(v),
                     self._bed.reshape(-1), self.wet_threshold, tb.uk_upper, tb.debris_upper,
                     tb.debris_df, tb.debris_speed, tb.arr_limits,
                     *(g[name].reshape(-1) for name in UPDATE_ORDER))
        self.t_last = float(t)
        self.updates += 1

    def record(self, model) -> None:
        """Update from a FloodModel (``model.t``, ``model.particles``); the simulation's
        schedule (``floodsph.simulation.recorders``) decides when."""
        p = model.particles
        dt = 0.0 if self.t_last is None else model.t - self.t_last
        self.update(model.t, dt, p.x, p.y, p.u, p.v, p.m, p.rho, p.h, model.surface_levels(),
                    model.map_walls())

    def maps(self) -> dict[str, np.ndarray]:
        """Copies of the maps by name (row 0 = south); float64 or uint8 for classes."""
        return {name: arr.copy() for name, arr in self._maps.items()}

    def state(self) -> dict[str, np.ndarray]:
        """Everything needed to resume (for checkpoints): the maps plus t_last and updates."""
        out = self.maps()
        out["t_last"] = np.array(np.nan if self.t_last is None else self.t_last)
        out["updates"] = np.array(self.updates)
        return out

    def restore(self, state: dict) -> None:
        """Inverse of :meth:`state`."""
        for name in MAPS:
            self._maps[name][...] = state[name]
        t_last = float(state["t_last"])
        self.t_last = None if math.isnan(t_last) else t_last
        self.updates = int(state["updates"])


def _flat(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).reshape(-1)
