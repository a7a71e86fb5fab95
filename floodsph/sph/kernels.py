"""The 2-D cubic B-spline smoothing kernel and its radial derivative.

With q = r/h and sigma = 10 / (7 pi h^2) (normalised so that the integral over the plane is 1):

    W(r, h) = sigma (1 - 1.5 q^2 + 0.75 q^3)     0 <= q <= 1
            = sigma 0.25 (2 - q)^3               1 <  q <= 2
            = 0                                  q > 2

    dW/dr   = sigma / h (-3 q + 2.25 q^2)         0 <= q <= 1
            = -sigma / h 0.75 (2 - q)^2          1 <  q <= 2

For the pressure force, (dW/dr) / r is evaluated from r, 1/r and 1/h without divisions:

    (dW/dr) / r = sigma / h^4 (-3 + 2.25 q)          0 <= q <= 1
                = -sigma / h^3 0.75 (2 - q)^2 / r    1 <  q <= 2

Units: W [m^-2], dW/dr [m^-3], (dW/dr) / r [m^-4]. Support radius 2h.

Reference: Monaghan & Lattanzio (1985); the 2-D normalisation 10/(7 pi h^2) as used by
Vacondio et al., Adv. Water Resour. 58 (2013) 10-23 (``docs/method.md`` §2).
"""

from __future__ import annotations

import math

from numba import njit

SIGMA_2D = 10.0 / (7.0 * math.pi)
"""Normalisation constant of the 2-D cubic spline, W(0, h) = SIGMA_2D / h^2."""


BEYOND_SUPPORT = 1.0 + 1e-9
"""A pair at r^2 >= BEYOND_SUPPORT (2 h)^2 is beyond the support of every kernel here, in
floating point too: r = sqrt(r^2) then exceeds 2 h by 5e-10 relative, far above the rounding
of q = r / h or r (1 / h) (1e-16), so q >= 2 and W, dW/dr and their quotients by r evaluate
to exactly zero (:func:`beyond_support`)."""


@njit(inline="always", cache=True)
def beyond_support(rx, ry, h):
    """True when the separation (rx, ry) [m] is beyond the support 2h [m] by the margin
    ``BEYOND_SUPPORT``: every kernel term of the pair is exactly zero, and a sum may skip it
    bit for bit (a sum that starts at +0 is never -0, so adding a zero of either sign leaves
    it unchanged). Used to skip mirror images before their sight test and pair terms."""
    return rx * rx + ry * ry >= BEYOND_SUPPORT * 4.0 * h * h


def seeded_smoothing_length(kappa, spacing):
    """h0 = kappa dx [m]: the smoothing length of particles seeded at ``spacing`` dx [m]
    (``numerics.kappa``, ``docs/method.md`` §2). The one place it is computed: the seeding,
    the wall layout and index, the sinks' reach and the run-time estimate all take it here.
    Works on numbers and arrays alike."""
    return kappa * spacing


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
def w_dwdr_cubic(r, h):
    """W(r, h) [m^-2] and dW/dr (r, h) [m^-3] of the 2-D cubic spline in one evaluation.

    Both branches are evaluated and one selected (no data-dependent jump in pair loops).
    """
    q = r / h
    s = SIGMA_2D / (h * h)
    s3 = SIGMA_2D / (h * h * h)
    t = max(2.0 - q, 0.0)
    inner = q <= 1.0
    w = s * (1.0 - 1.5 * q * q + 0.75 * q * q * q) if inner else s * 0.25 * t * t * t
    dw = s3 * (-3.0 * q + 2.25 * q * q) if inner else -s3 * 0.75 * t * t
    return w, dw


@njit(inline="always", cache=True)
def dwdr_over_r_cubic(r, inv_r, inv_h):
    """(dW/dr) / r [m^-4] of the 2-D cubic spline from r [m], 1/r and 1/h [m^-1] (<= 0).

    Both branches are evaluated and one selected (no data-dependent jump in pair loops).
    """
    q = r * inv_h
    s = SIGMA_2D * inv_h * inv_h * inv_h
    t = max(2.0 - q, 0.0)
    return s * inv_h * (-3.0 + 2.25 * q) if q <= 1.0 else -s * 0.75 * t * t * inv_r


@njit(inline="always", cache=True)
def dwdr_over_r_floored(r, inv_r, inv_h):
    """(dW/dr) / r [m^-4] of the cubic spline with |dW/dr| held at its peak below q = 2/3.

        dW/dr = -sigma / h^3        0 <= q < 2/3     (sigma = 10 / (7 pi), h^3 as above)
              = the cubic's         q >= 2/3

    The cubic's gradient falls to zero as r -> 0, so a pair force built on it stops
    repelling when two points come closer than 2h/3. Holding the gradient at its peak there
    is the remedy of Thomas & Couchman, MNRAS 257 (1992) 11-31, for particle clumping. The
    solver uses it only between a particle and its own wall images (``floodsph.sph.forces``),
    where it makes the wall's push grow monotonically as the particle nears the wall.
    """
    q = r * inv_h
    if q >= 2.0 / 3.0:
        return dwdr_over_r_cubic(r, inv_r, inv_h)
    return -SIGMA_2D * inv_h * inv_h * inv_h * inv_r
