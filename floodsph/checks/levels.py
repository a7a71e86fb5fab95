"""Where a level boundary lies, and the levels that cannot be meant.

A ``[[level_boundaries]]`` entry is a side of the DEM rectangle or a line A-B on the DEM
(``docs/level-boundary.md``); :func:`level_section` turns either into the section in local
coordinates and its inward unit normal (towards the modelled water). Refused: a line with an
end point off the DEM rectangle, or shorter than half the particle spacing; the side of a
line is decided as for an inflow (``floodsph.checks.inflows.inward_normal``).

Refused too: a level file's level beyond +-``ELEVATION_LIMIT_M`` (a constant ``level_m`` is
checked by the reader).

Warned of (a falling tide may be meant, a datum error is more likely): a series whose highest
level lies below the bed all along the section, so that the boundary never holds water and
only lets water out, as over a free overfall.
"""

from __future__ import annotations

import math

import numpy as np

from floodsph.checks.elevation import ELEVATION_LIMIT_M
from floodsph.checks.inflows import ground, inward_normal
from floodsph.errors import InputError, warn

SIDE_NORMALS = {"west": (1.0, 0.0), "east": (-1.0, 0.0), "south": (0.0, 1.0),
                "north": (0.0, -1.0)}
"""The inward unit normal of each side of the DEM rectangle."""


def side_line(side: str, width: float, height: float) -> np.ndarray:
    """The (2, 2) segment [A, B] [m, local] along ``side`` of the DEM rectangle [0, W] x [0, H]."""
    ends = {"west": ((0.0, 0.0), (0.0, height)), "east": ((width, 0.0), (width, height)),
            "south": ((0.0, 0.0), (width, 0.0)), "north": ((0.0, height), (width, height))}
    return np.array(ends[side], dtype=np.float64)


def level_section(entry, terrain, spacing: float, where: str) -> tuple[np.ndarray, np.ndarray]:
    """The section [A, B] (local [m]) of a ``[[level_boundaries]]`` entry and its inward normal.

    ``entry`` has ``side`` or ``line`` (model CRS) and ``direction``; ``where`` names it
    (``"scenario.toml: level_boundaries[0]"``). Raises InputError on the refusals above.
    """
    if entry.side is not None:
        return side_line(entry.side, terrain.width, terrain.height), np.array(
            SIDE_NORMALS[entry.side])
    line = np.column_stack(terrain.to_local(*np.asarray(entry.line, dtype=np.float64).T))
    tol = 1e-9 * max(terrain.width, terrain.height)
    for point, world in zip(line, entry.line, strict=True):
        if not (-tol <= point[0] <= terrain.width + tol
                and -tol <= point[1] <= terrain.height + tol):
            raise InputError(f"{where}.line: the point {list(world)} lies off the DEM; the "
                             "section must lie on the DEM (its border included)")
    length = float(np.hypot(*(line[1] - line[0])))
    if length < 0.5 * spacing:
        raise InputError(f"{where}.line: the line is {length:.3g} m long, shorter than half "
                         f"the particle spacing ({0.5 * spacing:g} m); draw it across the whole "
                         "channel or lower numerics.particle_spacing_m")
    return line, inward_normal(line[0], line[1], terrain, entry.direction, spacing, where)


def lowest_bed(line, normal, terrain, spacing: float) -> float:
    """The lowest bed [m] along the section, probed every spacing half a spacing inside it
    (+inf where the probes are all off the DEM or on nodata)."""
    a, b = np.asarray(line, dtype=np.float64)
    length = float(np.hypot(*(b - a)))
    count = max(1, int(round(length / spacing)))
    fractions = (np.arange(count) + 0.5) / count
    points = a + fractions[:, None] * (b - a) + 0.5 * spacing * np.asarray(normal)
    return min((ground(terrain, point) for point in points), default=math.inf)


def check_level_boundaries(scenario, terrain, series, spacing: float, source: str,
                           warnings: list[str] | None) -> None:
    """Check every ``[[level_boundaries]]`` section (:func:`level_section`) and warn of a
    series (``series``, one :class:`~floodsph.io.level_series.LevelSeries` per entry) that
    stays below the bed all along its section."""
    for i, (entry, levels) in enumerate(zip(scenario.level_boundaries, series, strict=True)):
        where = f"{source}: level_boundaries[{i}]"
        beyond = np.abs(levels.level) > ELEVATION_LIMIT_M
        if beyond.any():
            raise InputError(f"{where}.file: {entry.file}: level_m = "
                             f"{levels.level[beyond][0]:g} m (at time_s = "
                             f"{levels.t[beyond][0]:g}) is beyond +-{ELEVATION_LIMIT_M:g} m, "
                             "no water surface on Earth")
        line, normal = level_section(entry, terrain, spacing, where)
        bed = lowest_bed(line, normal, terrain, spacing)
        if levels.highest() <= bed:
            warn(f"{where} ({entry.name}): the highest level, {levels.highest():g} m, is at or "
                 f"below the bed all along the section (lowest {bed:g} m): the boundary never "
                 "holds water and only lets water out; check the levels' vertical datum",
                 warnings)
