"""The crest of a wall that water may overtop, and the breach that lowers it over time.

A crest wall (``[[walls]] crest_m``, ``docs/structures.md`` §1) has a crest elevation z_0(s)
[m] along its chainage s [m] (the distance along the polyline from its first vertex): one
value, or one per vertex and linear in between. A breach (``[walls.breach]``, §3) centred at
chainage s_c lowers it to a trapezoid: at time t, with the formed fraction
r = progression((t - t_start) / t_f) (``floodsph.breach.formulas.progression``: linear, or the
HEC-RAS sine wave r = (1 - cos(pi tau)) / 2),

    bottom  z_b(t) = z_top - r (z_top - z_inv),  z_top = z_0(s_c)
    width   b(t)   = r b_final
    crest   z(s, t) = min(z_0(s), z_b(t) + max(|s - s_c| - b(t) / 2, 0) / m)

with m the side slope (H:V; m = 0: vertical sides). The breach thus starts as a notch at the
crest and deepens and widens in proportion until, at t_start + t_f, its bottom is at the
invert and b_final wide, as in HEC-RAS's breach progression (HEC-RAS Hydraulic Reference
Manual, "Dam and levee breaching"). With ``froehlich = true`` the final average width and the
formation time are Froehlich's (2008) for the reservoir volume given and the breach height
z_top - z_inv (overtopping, k0 = 1.3), the bottom width B_avg - m h_b
(``floodsph.breach.formulas``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from floodsph.breach import formulas
from floodsph.errors import InputError


@dataclass(frozen=True)
class Breach:
    """A resolved wall breach: chainage of its centre [m], final bottom width [m] and invert
    [m], side slope (H:V), start [s], formation time [s] and growth (``"linear"``, ``"sine"``)."""

    centre_m: float
    bottom_width_m: float
    invert_m: float
    side_slope: float
    start_s: float
    formation_s: float
    growth: str = "linear"

    def fraction(self, t: float) -> float:
        """The formed fraction r of the final breach at time t [s] (0 before the start)."""
        return formulas.progression((t - self.start_s) / self.formation_s, self.growth)


def chainage(polyline: np.ndarray) -> np.ndarray:
    """Distance along the polyline [m] of each of its vertices, from the first."""
    seg = np.hypot(*np.diff(np.asarray(polyline, dtype=np.float64), axis=0).T)
    return np.concatenate([[0.0], np.cumsum(seg)])


class Crest:
    """The crest elevation of a wall along its chainage, lowered by its breach if any.

    Parameters
    ----------
    polyline : (k, 2) array
        The wall's vertices in local coordinates [m].
    crest : float or sequence of k floats
        The crest elevation [m], constant or per vertex.
    breach : Breach or None
    """

    def __init__(self, polyline, crest, breach: Breach | None = None):
        self.polyline = np.asarray(polyline, dtype=np.float64)
        self.s = chainage(self.polyline)
        self.length = float(self.s[-1])
        z = np.broadcast_to(np.asarray(crest, dtype=np.float64), (self.s.shape[0],))
        self.z = np.array(z)
        self.breach = breach

    def base(self, s) -> np.ndarray:
        """z_0(s): the crest without the breach [m] at chainages s [m]."""
        return np.interp(s, self.s, self.z)

    def at(self, s, t: float) -> np.ndarray:
        """z(s, t): the crest [m] at chainages s [m] at time t [s] (module docstring)."""
        z0 = self.base(np.asarray(s, dtype=np.float64))
        b = self.breach
        if b is None:
            return z0
        r = b.fraction(t)
        if r <= 0.0:
            return z0
        top = float(self.base(b.centre_m))
        bottom = top - r * (top - b.invert_m)
        off = np.maximum(np.abs(np.asarray(s) - b.centre_m) - 0.5 * r * b.bottom_width_m, 0.0)
        if b.side_slope > 0.0:
            cut = bottom + off / b.side_slope
        else:
            cut = np.where(off > 0.0, np.inf, bottom)
        return np.minimum(z0, cut)


def resolve_breach(entry, crest: Crest, name: str) -> Breach:
    """The :class:`Breach` of a ``[walls.breach]`` entry (``floodsph.scenario.config.WallBreach``)
    on its wall, with the checks that need the wall's length: the centre on the wall, the
    invert below the crest there, the final bottom no wider than the wall. ``name`` is the
    key path of the table for messages (``scenario.toml: walls[0].breach``)."""
    if entry.centre_m > crest.length:
        raise InputError(f"{name}.centre_m: {entry.centre_m:g} m is beyond the end of the wall, "
                         f"which is {crest.length:.6g} m long (centre_m is the distance along "
                         "the wall from its first vertex)")
    top = float(crest.base(entry.centre_m))
    if entry.invert_m >= top:
        raise InputError(f"{name}.invert_m: {entry.invert_m:g} m is not below the crest at the "
                         f"breach centre ({top:g} m): the breach would open nothing")
    width, formation = entry.bottom_width_m, entry.formation_s
    if entry.froehlich:
        height = top - entry.invert_m
        average = formulas.froehlich2008_average_width(entry.reservoir_volume_m3, height,
                                                       "overtopping")
        width = formulas.bottom_width(average, entry.side_slope, height)
        formation = formulas.froehlich2008_formation_time(entry.reservoir_volume_m3, height)
    if width > crest.length:
        raise InputError(f"{name}.bottom_width_m: the breach is {width:.6g} m wide at the "
                         f"bottom but the wall is only {crest.length:.6g} m long")
    growth = getattr(entry.growth, "value", entry.growth)
    return Breach(centre_m=float(entry.centre_m), bottom_width_m=float(width),
                  invert_m=float(entry.invert_m), side_slope=float(entry.side_slope),
                  start_s=float(entry.start_s), formation_s=float(formation), growth=growth)


def check_crest_above_bed(crest: Crest, bed_at, name: str) -> None:
    """Refuse a crest below the DEM bed at every vertex (``bed_at(x, y)`` [m]): such a wall
    would pass water as if it were not there, which is surely a datum mistake."""
    bed = np.asarray(bed_at(crest.polyline[:, 0], crest.polyline[:, 1]), dtype=np.float64)
    if np.all(crest.z < bed):
        worst = float(np.max(bed - crest.z))
        raise InputError(f"{name}.crest_m: the crest lies below the DEM bed at every vertex "
                         f"(by up to {worst:.3g} m); crest_m is an elevation in the DEM's "
                         "vertical datum, not a height above the ground")
