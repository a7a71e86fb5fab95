"""The side of its line an inflow enters on, and the directions that cannot be meant.

An ``[[inflows]]`` section A-B injects water across the line, on the side of its inward unit
normal n = +-(-t_y, t_x), t = (B - A) / |B - A|. With ``direction`` given, n is the normal on
the side the direction points to (n . direction > 0); without it, n points to the lower ground
of the two cells probed at ``max(2 spacing, 2 cells)`` either side of the line's midpoint.

Refused (the run would inject water nowhere, or the user's vector says nothing):

* a zero-length line;
* a ``direction`` parallel to the line (|n . d| <= 1e-9 |d|): it names neither side;
* a ``direction`` that points off the DEM or onto nodata at the probe: water would enter
  outside the domain;
* no ``direction`` and level ground on both sides.

Warned of (it may be meant, an inflow into a lake, but is more often a sign flipped): a
``direction`` pointing into the initial water (a modelled reservoir) while the other side is
dry, so that the breach flows back into the reservoir. The ground's slope is not judged: a
breach often spills from a reservoir's low bed onto higher ground.

:func:`inward_normal` is the one place this is decided: ``floodsph check`` and ``run`` reach
it through :func:`check_inflows` (``floodsph.inputs.prepare``), the model through
``floodsph.boundaries.Inflow``.
"""

from __future__ import annotations

import math

import numpy as np

from floodsph.errors import InputError, warn


def inward_normal(a, b, terrain, direction, spacing: float, name: str) -> np.ndarray:
    """The unit normal of the line A-B (local coordinates [m]) towards the domain.

    ``name`` is the key path of the inflow for messages (``"scenario.toml: inflows[0]"``).
    Raises :class:`~floodsph.errors.InputError` on the refusals above.
    """
    mid, normal, probe = _geometry(a, b, terrain, spacing, name)
    ahead, behind = (ground(terrain, mid + sign * probe * normal) for sign in (1.0, -1.0))
    if direction is None:
        if ahead == behind:
            raise InputError(f"{name}: the ground is level on both sides of the line; "
                             "give direction = [dx, dy] to say where water enters")
        return normal if ahead < behind else -normal
    d = np.asarray(direction, dtype=np.float64)
    side = float(np.dot(normal, d))
    if abs(side) <= 1e-9 * float(np.hypot(*d)):
        raise InputError(f"{name}.direction: {list(direction)} is parallel to the line; give a "
                         "direction across it")
    if side < 0.0:
        normal, ahead = -normal, behind
    if math.isinf(ahead):
        raise InputError(f"{name}.direction: {list(direction)} points off the DEM (or onto "
                         f"nodata) {probe:g} m from the line's midpoint: the water would enter "
                         "outside the domain; reverse it")
    return normal


def check_inflows(scenario, terrain, depth, spacing: float, source: str,
                  warnings: list[str] | None) -> None:
    """Check the side of every ``[[inflows]]`` line before a run (:func:`inward_normal`) and
    warn of a given ``direction`` into the initial water (``depth`` [m], row 0 = south)."""
    for i, inflow in enumerate(scenario.inflows):
        name = f"{source}: inflows[{i}]"
        a, b = (terrain.to_local(*np.asarray(p, dtype=np.float64)) for p in inflow.line)
        normal = inward_normal(a, b, terrain, inflow.direction, spacing, name)
        if inflow.direction is None:
            continue
        mid, _, probe = _geometry(a, b, terrain, spacing, name)
        points = [mid + sign * probe * normal for sign in (1.0, -1.0)]
        wet_ahead, wet_behind = (_wet(terrain, depth, p) for p in points)
        if wet_ahead and not wet_behind:
            warn(f"{name}.direction: {list(inflow.direction)} points into the initial water "
                 "(a reservoir?) while the other side of the line is dry: the inflow adds to "
                 "that water instead of flowing away from it", warnings)


def _geometry(a, b, terrain, spacing: float, name: str):
    """(midpoint, a unit normal, probe distance) of the line A-B."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    length = float(np.hypot(*(b - a)))
    if not length > 0.0:
        raise InputError(f"{name}.line: the two end points coincide (zero-length line)")
    tangent = (b - a) / length
    probe = max(2.0 * spacing, 2.0 * max(terrain.dx, terrain.dy))
    return a + 0.5 * length * tangent, np.array([-tangent[1], tangent[0]]), probe


def ground(terrain, point) -> float:
    """Bed elevation at a local point; +inf off the DEM or on nodata (no water there)."""
    cell = _cell(terrain, point)
    return math.inf if cell is None else float(terrain.elevation[cell])


def _wet(terrain, depth, point) -> bool:
    cell = _cell(terrain, point)
    return cell is not None and depth[cell] > 0.0


def _cell(terrain, point) -> tuple[int, int] | None:
    col = int(math.floor(point[0] / terrain.dx))
    row = int(math.floor(point[1] / terrain.dy))
    ny, nx = terrain.shape
    if not (0 <= col < nx and 0 <= row < ny) or not terrain.valid[row, col]:
        return None
    return row, col
