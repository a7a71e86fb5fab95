"""Flooded area by class: by maximum depth in fixed depth bands, and by hazard class.

The depth bands (:data:`DEPTH_BREAKS_M`) are round numbers, finer where the water is shallow,
where the harm a flood does to people, cars and buildings changes fastest; the lowest band
starts at the run's wet threshold. A cell counts with its full area ``dx * dy`` [m2] in the
band or class of its value. The bands and their colours are shared by the quick-look depth
map (:mod:`floodsph.output.pictures`) and the run report (:mod:`floodsph.output.report`), so a
table row and the map legend always agree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

DEPTH_BREAKS_M = (0.15, 0.3, 0.5, 1.0, 2.0, 5.0)
"""Upper limits [m] of the depth bands below the deepest (which is open above 5 m)."""
DEPTH_COLOURS = ("#c6dbef", "#9ecae1", "#6baed6", "#4292c6", "#2171b5", "#08519c", "#08306b")
"""One colour per band, light (shallow) to dark (deep): the sequential blues of ColorBrewer
(Harrower & Brewer 2003, The Cartographic Journal 40(1), 27-37)."""


@dataclass(frozen=True)
class AreaRow:
    """One band or class: its name, colour (``#rrggbb``), cell count and area [m2]."""

    label: str
    colour: str
    cells: int
    area_m2: float


@dataclass(frozen=True)
class DepthBand:
    """Depths ``lower <= d < upper`` [m] (``upper`` inf for the deepest band): a depth on a
    limit belongs to the deeper band, as in the picture's colour scale."""

    lower: float
    upper: float
    colour: str

    @property
    def label(self) -> str:
        if math.isinf(self.upper):
            return f"more than {self.lower:g} m"
        return f"{self.lower:g} to {self.upper:g} m"


def depth_bands(wet_threshold: float) -> list[DepthBand]:
    """The bands of :data:`DEPTH_BREAKS_M` above the wet threshold [m], the first one from the
    threshold (bands wholly below it are left out, with their colours)."""
    kept = [k for k, b in enumerate(DEPTH_BREAKS_M) if b > wet_threshold]
    first = kept[0] if kept else len(DEPTH_BREAKS_M)
    lowers = [wet_threshold, *DEPTH_BREAKS_M[first:]]
    uppers = [*DEPTH_BREAKS_M[first:], math.inf]
    return [DepthBand(lo, up, DEPTH_COLOURS[first + k])
            for k, (lo, up) in enumerate(zip(lowers, uppers, strict=True))]


def area_by_depth(max_depth, cell_area_m2: float, wet_threshold: float) -> list[AreaRow]:
    """Cells and area [m2] of the maximum-depth map in each band of :func:`depth_bands`, over
    the wet cells (depth above the wet threshold; NaN = never wet, counted nowhere)."""
    d = np.asarray(max_depth, dtype=np.float64)
    wet = np.nan_to_num(d) > wet_threshold
    rows = []
    for band in depth_bands(wet_threshold):
        n = int(np.count_nonzero(wet & (d >= band.lower) & (d < band.upper)))
        rows.append(AreaRow(band.label, band.colour, n, n * cell_area_m2))
    return rows


def area_by_class(classes, names, colours, cell_area_m2: float) -> list[AreaRow]:
    """Cells and area [m2] of each class 1, 2, ... of a class map (0 = dry is left out);
    ``names`` and ``colours`` (RGB 0-255) are indexed by class value."""
    c = np.asarray(classes)
    return [AreaRow(names[k], hex_colour(colours[k]), int(np.count_nonzero(c == k)),
                    int(np.count_nonzero(c == k)) * cell_area_m2)
            for k in range(1, len(names))]


def hex_colour(rgb) -> str:
    """``(r, g, b)`` 0-255 as ``#rrggbb``."""
    return "#" + "".join(f"{int(v):02x}" for v in rgb[:3])
