"""The 2-D cubic B-spline smoothing kernel and its radial derivative.

With q = r/h and sigma = 10 / (7 pi h^2) (normalised so that the integral over the plane is 1):

    W(r, h) = sigma (1 - 1.5 q^2 + 0.75 q^3)     0 <= q <= 1
            = sigma 0.25 (2 - q)^3               1 <  q <= 2
            = 0                                  q > 2

    dW/dr   = sigma / h (-3 q + 2.25 q^2)         0 <= q <= 1
            = -sigma / h 0.75 (2 - q)^2          1 <  q <= 2

Units: W [m^-2], dW/dr [m^-3]. Support radius 2h.

Reference: Monaghan & Lattanzio (1985); the 2-D normalisation 10/(7 pi h^2) as used by
Vacondio et al., Adv. Water Resour. 58 (2013) 10-23 (method notes, section 1.3).
"""

from __future__ import annotations

import math

from numba import njit

SIGMA_2D = 10.0 / (7.0 * math.pi)
"""Normalisation constant of the 2-D cubic spline, W(0, h) = SIGMA_2D / h^2."""


@njit(inline="always", cache=True)
def w_cubic(r, h):
    """Kernel value W(r, h) [m^-2] of the 2-D cubic spline."""
    q = r / h
    s = SIGMA_2D / (h * h)
    if q <= 1.0:
        return s * (1.0 - 1.5 * q * q + 0.75 * q * q * q)
    if q <= 2.0:
        t = 2.0 - q
        return s * 0.25 * t * t * t
    return 0.0


@njit(inline="always", cache=True)
def dwdr_cubic(r, h):
    """Radial derivative dW/dr (r, h) [m^-3] of the 2-D cubic spline (<= 0)."""
    q = r / h
    s = SIGMA_2D / (h * h * h)
    if q <= 1.0:
        return s * (-3.0 * q + 2.25 * q * q)
    if q <= 2.0:
        t = 2.0 - q
        return -s * 0.75 * t * t
    return 0.0
