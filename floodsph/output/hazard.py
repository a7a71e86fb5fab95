"""Flood hazard ratings to people: UK HR classes and Australian H1-H6 classes.

UK (Defra/EA FD2320/TR2 2005, FD2321/TR1 2006):

    HR = d (v + 0.5) + DF                      d [m], v [m/s], HR and DF [m2/s]

with the debris factor DF from a depth band and the land use, and four classes: HR < 0.75
low hazard (caution), 0.75 <= HR <= 1.25 danger for some, 1.25 < HR <= 2.0 danger for most,
HR > 2.0 danger for all. Debris bands: d <= 0.25 m; 0.25 < d <= 0.75 m; d > 0.75 m or
(d > 0.25 m and v > 2 m/s). The default land use ``"conservative"`` is Flood Modeller's
simplified DF = 0 for d <= 0.25 m else 1 (help.floodmodeller.com/docs/hazard-mapping); the
others are the report's pasture/arable, woodland and urban columns.

Australia (AIDR Guideline 7-3, 2017, Table 6; Smith et al. 2014): the class is the smallest
k in 1..5 with d v <= (dv)_k, d <= d_k and v <= v_k, else 6.

Both tables are data files, ``floodsph/data/hazard_uk.csv`` and ``hazard_arr.csv``, with
their sources. Class 0 means dry (d <= the wet threshold) in both.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit, prange

from floodsph.errors import InputError

DATA = Path(__file__).resolve().parent.parent / "data"
LAND_USES = ("pasture", "woodland", "urban", "conservative")

UK_COLOURS = ((255, 255, 255), (255, 255, 153), (255, 178, 76), (230, 76, 0), (153, 0, 0))
"""RGB colour of UK classes 0 (dry) to 4."""
ARR_COLOURS = ((255, 255, 255), (204, 229, 255), (153, 204, 102), (255, 230, 77),
               (255, 153, 51), (230, 51, 26), (128, 0, 38))
"""RGB colour of Australian classes 0 (dry) and H1 to H6."""


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


@dataclass(frozen=True)
class HazardTables:
    """The numbers of both classifications as arrays for the numba kernels.

    Attributes
    ----------
    uk_upper : (4,) upper HR bound of UK classes 1-4 (class 1 exclusive, others inclusive).
    debris_upper : (3,) upper depth [m] of the debris bands.
    debris_df : (3,) debris factor [m2/s] of the bands for the chosen land use.
    debris_speed : speed [m/s] above which the deepest band applies for d > debris_upper[0].
    arr_limits : (6, 3) limits (d v [m2/s], d [m], v [m/s]) of H1-H6.
    uk_names, arr_names : class names, index = class (0 = dry).
    land_use : the debris land use.
    """

    uk_upper: np.ndarray
    debris_upper: np.ndarray
    debris_df: np.ndarray
    debris_speed: float
    arr_limits: np.ndarray
    uk_names: tuple[str, ...]
    arr_names: tuple[str, ...]
    land_use: str

    @classmethod
    def load(cls, land_use: str = "conservative") -> HazardTables:
        """Read the tables from ``floodsph/data``; ``land_use`` picks the debris column."""
        if land_use not in LAND_USES:
            raise InputError(f"hazard land use must be one of {', '.join(LAND_USES)}, "
                             f"got {land_use!r}")
        uk = _rows(DATA / "hazard_uk.csv")
        classes = [r for r in uk if r["kind"] == "class"]
        debris = [r for r in uk if r["kind"] == "debris"]
        arr = _rows(DATA / "hazard_arr.csv")
        return cls(
            uk_upper=np.array([float(r["upper"]) for r in classes]),
            debris_upper=np.array([float(r["upper"]) for r in debris]),
            debris_df=np.array([float(r[land_use]) for r in debris]),
            debris_speed=float(debris[-1]["speed_above"]),
            arr_limits=np.array([[float(r["dv_max"]), float(r["d_max"]), float(r["v_max"])]
                                 for r in arr]),
            uk_names=("Dry",) + tuple(r["label"] for r in classes),
            arr_names=("Dry",) + tuple(r["label"] for r in arr),
            land_use=land_use,
        )


@njit(inline="always", cache=True)
def debris_factor(d, v, debris_upper, debris_df, debris_speed):
    """DF [m2/s] of depth d [m] and speed v [m/s] from the three debris bands."""
    if d <= debris_upper[0]:
        return debris_df[0]
    if d > debris_upper[1] or v > debris_speed:
        return debris_df[2]
    return debris_df[1]


@njit(inline="always", cache=True)
def uk_class(d, v, uk_upper, debris_upper, debris_df, debris_speed):
    """UK class 1-4 of a wet (d, v): HR = d (v + 0.5) + DF against the class bounds."""
    hr = d * (v + 0.5) + debris_factor(d, v, debris_upper, debris_df, debris_speed)
    if hr < uk_upper[0]:
        return 1
    for k in range(1, uk_upper.shape[0]):
        if hr <= uk_upper[k]:
            return k + 1
    return uk_upper.shape[0]


@njit(inline="always", cache=True)
def arr_class(d, v, arr_limits):
    """Australian class 1-6 of a wet (d, v): the first class whose three limits all hold."""
    for k in range(arr_limits.shape[0]):
        if d * v <= arr_limits[k, 0] and d <= arr_limits[k, 1] and v <= arr_limits[k, 2]:
            return k + 1
    return arr_limits.shape[0]


@njit(parallel=True, cache=True)
def _classify(d, v, wet_threshold, uk_upper, debris_upper, debris_df, debris_speed,
              arr_limits, out_uk, out_arr):
    """UK and Australian classes of each (d [m], v [m/s]) into out_uk and out_arr (0 where
    d <= wet_threshold [m]), with :func:`uk_class` and :func:`arr_class` (module docstring)."""
    for i in prange(d.shape[0]):
        if d[i] > wet_threshold:
            out_uk[i] = uk_class(d[i], v[i], uk_upper, debris_upper, debris_df, debris_speed)
            out_arr[i] = arr_class(d[i], v[i], arr_limits)
        else:
            out_uk[i] = 0
            out_arr[i] = 0


def hazard_rating_uk(d, v, tables: HazardTables) -> np.ndarray:
    """HR = d (v + 0.5) + DF [m2/s] for arrays of depth d [m] and speed v [m/s]."""
    d = np.asarray(d, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    df = np.where(d <= tables.debris_upper[0], tables.debris_df[0],
                  np.where((d > tables.debris_upper[1]) | (v > tables.debris_speed),
                           tables.debris_df[2], tables.debris_df[1]))
    return d * (v + 0.5) + df


def classify(d, v, tables: HazardTables, wet_threshold: float = 0.0):
    """(UK class 0-4, Australian class 0-6) as uint8 arrays; 0 where d <= wet_threshold."""
    d = np.asarray(d, dtype=np.float64)
    v = np.broadcast_to(np.asarray(v, dtype=np.float64), d.shape)
    dd = np.ascontiguousarray(d.ravel())
    vv = np.ascontiguousarray(v.ravel())
    out_uk = np.zeros(dd.shape, dtype=np.uint8)
    out_arr = np.zeros(dd.shape, dtype=np.uint8)
    _classify(dd, vv, float(wet_threshold), tables.uk_upper, tables.debris_upper,
              tables.debris_df, tables.debris_speed, tables.arr_limits, out_uk, out_arr)
    return out_uk.reshape(d.shape), out_arr.reshape(d.shape)
