"""Exceedance-probability and quantile maps over the completed members, streamed from disk.

The members' maps are read one file at a time into a disk-backed stack per map (a ``.npy``
memory map of members x rows x columns in a scratch folder), and the statistics are taken
over blocks of rows whose stack slice fits in :data:`BLOCK_BYTES`, so memory holds one
member's map or one block at a time, besides the result maps. With N completed members, for
every cell of the base scenario's map grid:

* ``p_depth_gt[t]`` = #{members with max depth > t} / N, a dry cell (NaN max depth)
  counting as depth 0;
* ``max_depth_q[q]``, ``max_speed_q[q]``: the q-quantile over the N members, dry cells
  counting as 0 m and 0 m/s;
* ``arrival_time_q[q]``: the q-quantile over the members that wet the cell (finite arrival
  time), NaN where fewer than half of the N do;
* ``p_hazard_uk_ge[k]`` = #{members with UK hazard class >= k} / N, k = 1..4.

Quantiles are numpy's default (linear interpolation between order statistics, Hyndman &
Fan 1996 type 7). Cells outside the DEM (nodata) are NaN in every map.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from floodsph.errors import InputError

#: Upper size of one block of a stack in the statistics [bytes] (as float64).
BLOCK_BYTES = 64 * 2**20
#: UK hazard classes whose "class or worse" probability is mapped.
UK_CLASSES = (1, 2, 3, 4)


@dataclass(frozen=True)
class EnsembleMaps:
    """The ensemble's maps, south-up (row 0 = south), float32, NaN outside the DEM.

    ``p_depth_gt`` is (thresholds, ny, nx); the ``*_q`` maps are (quantiles, ny, nx);
    ``p_hazard_uk_ge`` is (4, ny, nx) for classes 1-4; ``members`` is N.
    """

    thresholds: tuple[float, ...]
    quantiles: tuple[float, ...]
    members: int
    p_depth_gt: np.ndarray
    max_depth_q: np.ndarray
    max_speed_q: np.ndarray
    arrival_time_q: np.ndarray
    p_hazard_uk_ge: np.ndarray


def dem_mask(terrain, grid) -> np.ndarray:
    """True on the map cells whose centre falls on a valid (data) DEM cell; south-up."""
    xc, yc = grid.cell_centres()
    ny, nx = terrain.shape
    cols = np.minimum((xc / terrain.dx).astype(np.int64), nx - 1)
    rows = np.minimum((yc / terrain.dy).astype(np.int64), ny - 1)
    return terrain.valid[np.ix_(rows, cols)]


def read_map(path: Path, grid) -> np.ndarray:
    """A member's map GeoTIFF as a south-up array, checked to be on ``grid``."""
    import rasterio
    from rasterio.errors import RasterioError

    try:
        with rasterio.open(path) as src:
            same = (src.width, src.height) == (grid.nx, grid.ny) and src.transform.almost_equals(
                grid.north_up_transform())
            if not same:
                raise InputError(f"{path}: the map is on a grid of {src.width} x {src.height} "
                                 f"cells at {tuple(src.transform)[:6]}, not the base "
                                 f"scenario's {grid.nx} x {grid.ny} at "
                                 f"{tuple(grid.north_up_transform())[:6]}")
            return src.read(1)[::-1]
    except RasterioError as exc:
        raise InputError(f"{path}: cannot read the member's map: {exc}") from None


class MapStack:
    """One map of every member, stacked on disk: a (members, ny, nx) ``.npy`` memory map."""

    def __init__(self, path: Path, members: int, shape: tuple[int, int], dtype):
        self.data = np.lib.format.open_memmap(path, mode="w+", dtype=dtype,
                                              shape=(members, *shape))

    def blocks(self):
        """``(row slice, stack block as float64)`` over blocks of rows (BLOCK_BYTES each)."""
        members, ny, nx = self.data.shape
        rows = max(1, BLOCK_BYTES // (members * nx * 8))
        for r0 in range(0, ny, rows):
            part = slice(r0, min(r0 + rows, ny))
            yield part, np.asarray(self.data[:, part, :], dtype=np.float64)


def exceedance(depth: np.ndarray, thresholds) -> np.ndarray:
    """Fraction of members (axis 0) with max depth > t, for each t; NaN (dry) counts as 0."""
    d = np.nan_to_num(depth, nan=0.0)
    return np.stack([(d > t).mean(axis=0) for t in thresholds])


def dry_zero_quantiles(values: np.ndarray, quantiles) -> np.ndarray:
    """Quantiles over members (axis 0) with NaN (dry) counting as 0."""
    return np.quantile(np.nan_to_num(values, nan=0.0), quantiles, axis=0)


def arrival_quantiles(arrival: np.ndarray, quantiles) -> np.ndarray:
    """Quantiles over the members with a finite arrival; NaN where fewer than half have one."""
    members = arrival.shape[0]
    wet = np.isfinite(arrival).sum(axis=0)
    enough = (2 * wet >= members) & (wet > 0)
    out = np.full((len(quantiles), *arrival.shape[1:]), np.nan)
    if enough.any():
        out[:, enough] = np.nanquantile(arrival[:, enough], quantiles, axis=0)
    return out


def class_at_least(hazard: np.ndarray, classes) -> np.ndarray:
    """Fraction of members (axis 0) with hazard class >= k, for each k."""
    return np.stack([(hazard >= k).mean(axis=0) for k in classes])


def aggregate(folders: list[Path], grid, inside: np.ndarray, thresholds, quantiles,
              scratch_dir: Path) -> EnsembleMaps:
    """The ensemble maps over the member run ``folders`` (module docstring).

    ``inside`` is the DEM mask on ``grid`` (:func:`dem_mask`); the stacks live in a temporary
    folder inside ``scratch_dir``, removed afterwards.
    """
    n = len(folders)
    shape = grid.shape
    nq = len(quantiles)
    out = {
        "p_depth_gt": np.empty((len(thresholds), *shape), np.float32),
        "max_depth_q": np.empty((nq, *shape), np.float32),
        "max_speed_q": np.empty((nq, *shape), np.float32),
        "arrival_time_q": np.empty((nq, *shape), np.float32),
        "p_hazard_uk_ge": np.empty((len(UK_CLASSES), *shape), np.float32),
    }
    statistics = {
        "max_depth": (("p_depth_gt", lambda b: exceedance(b, thresholds)),
                      ("max_depth_q", lambda b: dry_zero_quantiles(b, quantiles))),
        "max_speed": (("max_speed_q", lambda b: dry_zero_quantiles(b, quantiles)),),
        "arrival_time": (("arrival_time_q", lambda b: arrival_quantiles(b, quantiles)),),
        "hazard_uk": (("p_hazard_uk_ge", lambda b: class_at_least(b, UK_CLASSES)),),
    }
    with tempfile.TemporaryDirectory(prefix=".stacks-", dir=scratch_dir) as tmp:
        for name, targets in statistics.items():
            dtype = np.uint8 if name == "hazard_uk" else np.float32
            stack = MapStack(Path(tmp) / f"{name}.npy", n, shape, dtype)
            for k, folder in enumerate(folders):
                stack.data[k] = read_map(Path(folder) / f"{name}.tif", grid)
            for rows, block in stack.blocks():
                for target, statistic in targets:
                    out[target][:, rows, :] = statistic(block)
            del stack  # closes the memory map before its folder goes
    for maps in out.values():
        maps[:, ~inside] = np.nan
    return EnsembleMaps(tuple(thresholds), tuple(quantiles), n, **out)
