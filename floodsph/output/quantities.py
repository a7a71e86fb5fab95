"""What a map holds: its quantity, read from its metadata, so that only like maps are compared.

A map's quantity is decided from, in this order:

1. its CF ``standard_name`` (a NetCDF variable's attribute, or a band tag);
2. its names: the band description, the NetCDF variable and the ``long_name``, searched for
   the words of :data:`QUANTITIES` (``max_depth``, ``arrival``, ``speed``, ...);
3. its units (``m`` depth, ``s`` arrival time, ``m s-1`` speed, ``m2 s-1`` unit discharge);
4. its data type alone: an integer map is a class map, of no known scheme.

A float map with none of these (a benchmark raster without metadata) has no quantity of its
own: :func:`floodsph.output.compare.compare` takes it as the other map's quantity, or as depth
when neither map says.
"""

from __future__ import annotations

import re
from dataclasses import dataclass


@dataclass(frozen=True)
class Quantity:
    """One quantity a flood map can hold.

    name : the key compare's summary uses (``depth``, ``arrival``, ...).
    label : how messages name it, with its article (``a depth`` map, ``an arrival-time`` map).
    units : its SI units, written as the run's maps write them (UDUNITS).
    words : names and words that say a map holds it (searched in the map's names).
    standard_names : CF standard names that mean it.
    threshold : a cell is wet where the value is above the wet threshold (depths); else
        where it has a value (NaN = never wet).
    classes : an integer class map (nearest-neighbour resampling, class agreement).
    """

    name: str
    label: str
    units: str
    words: tuple[str, ...]
    standard_names: tuple[str, ...] = ()
    threshold: bool = False
    classes: bool = False


QUANTITIES = (
    Quantity("time_of_max", "a time-of-maximum-depth", "s", ("time_of_max", "time of max"),
             ("time_of_maximum_flood_depth",)),
    Quantity("arrival", "an arrival-time", "s", ("arrival", "rises_above"),
             ("time_when_flood_water_rises_above_threshold",)),
    Quantity("duration", "a wet-duration", "s", ("duration", "time wet")),
    Quantity("unit_discharge", "a unit-discharge", "m2 s-1",
             ("unit_discharge", "unit discharge")),
    Quantity("speed", "a speed", "m s-1", ("speed", "velocity"), ("flood_water_speed",)),
    Quantity("level", "a water-level", "m", ("max_level", "level", "water_surface",
                                           "water-surface", "elevation"),
             ("water_surface_height_above_reference_datum",)),
    Quantity("depth", "a depth", "m", ("depth", "thickness"), ("flood_water_thickness",),
             threshold=True),
    Quantity("hazard_uk", "a UK-hazard-class", "1", ("hazard_uk", "uk flood hazard"),
             classes=True),
    Quantity("hazard_arr", "an ARR-hazard-class", "1", ("hazard_arr", "australian flood hazard"),
             classes=True),
)
"""The quantities, in the order their words are searched (``time_of_max_depth`` says
``depth`` too, so the time of the maximum comes first)."""

CLASS = Quantity("class", "an integer class", "1", (), classes=True)
"""An integer map that names no known class scheme."""

BY_NAME = {q.name: q for q in (*QUANTITIES, CLASS)}

UNITS = {"m": "depth", "s": "arrival", "m s-1": "speed", "m/s": "speed",
         "m2 s-1": "unit_discharge", "m2/s": "unit_discharge", "m^2/s": "unit_discharge"}
"""Units -> quantity, for a map whose names say nothing."""


@dataclass(frozen=True)
class MapMetadata:
    """What a map file says about itself (empty strings where it says nothing)."""

    description: str = ""
    variable: str = ""
    long_name: str = ""
    standard_name: str = ""
    units: str = ""
    integer: bool = False


def identify(meta: MapMetadata) -> tuple[Quantity | None, str]:
    """The quantity of a map and the evidence for it (``"standard_name 'flood_water_speed'"``);
    ``(None, "")`` for a float map that says nothing (see the module docstring)."""
    if meta.standard_name:
        for q in QUANTITIES:
            if meta.standard_name in q.standard_names:
                return q, f"standard_name {meta.standard_name!r}"
    for what, text in (("band description", meta.description), ("variable", meta.variable),
                       ("long_name", meta.long_name)):
        words = text.lower()
        for q in QUANTITIES:
            if q.classes != meta.integer:
                continue
            if any(re.search(rf"(^|[^a-z]){re.escape(w)}", words) for w in q.words):
                return q, f"{what} {text!r}"
    if meta.integer:
        return CLASS, "integer data"
    unit = meta.units.strip()
    if unit in UNITS:
        return BY_NAME[UNITS[unit]], f"units {unit!r}"
    return None, ""
