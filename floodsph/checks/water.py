"""A scenario must hold water: initial water bodies that are dry, and a run with no water.

An ``[[initial_water]]`` body holds no water when its polygon covers no DEM cell centre with
data, or its level lies below the bed everywhere inside it (a level in the wrong datum or
unit), or its depth raster is zero on the DEM. Alone, such a body makes a run that "completes"
with dry maps, so a scenario with no water at t = 0 and no inflow bringing any before the end
time is refused. When other water exists the run means something, and the dry body may be
meant (an ensemble member with a low reservoir level), so it is warned of instead.
"""

from __future__ import annotations

import numpy as np

from floodsph.errors import InputError, warn
from floodsph.io.polygons import points_in_polygon


def dry_body_reason(terrain, wet, body, polygon_local, key: str) -> str:
    """Why the body ``key`` (``initial_water[0]``) holds no water: a key path and a reason.

    ``polygon_local`` is its polygon in local coordinates (None for a depth raster), ``wet``
    the cells that may hold water (None: the valid ones).
    """
    if body.depth is not None:
        return f"{key}.depth: the depth raster {body.depth} has no water on the DEM cells"
    wet = terrain.valid if wet is None else wet
    xc, yc = terrain.cell_centres()
    X, Y = np.meshgrid(xc, yc)
    inside = points_in_polygon(X, Y, polygon_local)
    if not inside.any():
        return f"{key}.polygon: the polygon contains no DEM cell centre"
    if not (inside & wet).any():
        return f"{key}.polygon: the polygon covers only DEM nodata"
    bed = float(terrain.elevation[inside & wet].min())
    return (f"{key}.level_m: {body.level_m:g} m is below the bed everywhere inside the polygon "
            f"(lowest bed there {bed:.6g} m)")


def check_has_water(scenario, dry: list[str], initial_water: bool, volume_inflow_m3: float,
                    source: str, warnings: list[str] | None) -> None:
    """Refuse a scenario with no water at t = 0 and no inflow volume before the end time;
    warn of each dry body (``dry``: :func:`dry_body_reason` texts) when other water exists."""
    if initial_water or volume_inflow_m3 > 0.0:
        for reason in dry:
            warn(f"{source}: {reason}, so this body holds no water (the run goes on with the "
                 "other water)", warnings)
        return
    if dry:
        raise InputError(f"{source}: {dry[0]}, so it holds no water, and the scenario has no "
                         "other water and no inflow: the run would stay dry")
    if scenario.inflows:
        raise InputError(
            f"{source}: inflows: the hydrographs bring no water before end_time_s = "
            f"{scenario.end_time_s:g} s and there is no [[initial_water]]: the run would stay dry")
    raise InputError(f"{source}: the scenario holds no water: give [[initial_water]] or "
                     "[[inflows]]")
