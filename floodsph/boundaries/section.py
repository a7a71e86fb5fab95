"""The geometry of a boundary section A-B: its opening and the coordinates of points across
and along it (the inflows of ``floodsph.boundaries.inflow`` and the imposed levels of
``floodsph.boundaries.level``)."""

from __future__ import annotations

import numpy as np


def section_opening(a: np.ndarray, tangent: np.ndarray, length: float) -> np.ndarray:
    """The section as a (2, 2) array [A, B] [m], B = A + length t (walls along it are cut
    open)."""
    return np.stack([a, a + length * tangent])


def section_coordinates(a: np.ndarray, normal: np.ndarray, tangent: np.ndarray, x, y):
    """(s, tau) [m] of points (x, y): s = (x - A) . n, the distance along the inward unit
    normal n, and tau = (x - A) . t, along the section's unit tangent t from A."""
    rx = x - a[0]
    ry = y - a[1]
    s = rx * normal[0] + ry * normal[1]
    return s, rx * tangent[0] + ry * tangent[1]
