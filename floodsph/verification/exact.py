"""Exact shallow-water solutions for verifying the SPH solver (error measures:
``floodsph.verification.metrics``).

All functions are vectorised over their coordinate arrays (NumPy broadcasting) and use SI
units: lengths and depths [m], times [s], velocities [m/s], g [m/s2]. Only NumPy and SciPy are
used, so importing this module never compiles anything.

The solutions satisfy the frictionless shallow-water equations

    d_t + (d u)_x + (d v)_y = 0,
    u_t + u u_x + v u_y + g (d + b)_x = 0,   v_t + u v_x + v v_y + g (d + b)_y = 0,

with depth ``d``, velocity ``(u, v)`` and bed elevation ``b`` (Vacondio et al. 2013, eqs. of
motion in Lagrangian form; the same equations written in Eulerian form).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from floodsph.constants import GRAVITY

__all__ = [
    "ritter",
    "ritter_front",
    "stoker",
    "stoker_middle_state",
    "stoker_bore_position",
    "thacker_planar",
    "thacker_period",
    "thacker_shoreline",
    "lake_at_rest",
]


def _check_time(t: float) -> float:
    t = float(t)
    if not t >= 0.0:
        raise ValueError(f"time t must be >= 0 s, got {t}")
    return t


def _rarefaction(xi, c_l: float, g: float):
    """Centred rarefaction fan of a left state at rest, ``xi = (x - x_dam)/t`` [m/s].

    Along the C+ characteristics the Riemann invariant u + 2c = 2 c_l is constant and the fan
    is self-similar, u - c = xi, hence c = (2 c_l - xi)/3, d = c^2/g, u = 2 (c_l + xi)/3.
    """
    return (2.0 * c_l - xi) ** 2 / (9.0 * g), 2.0 * (c_l + xi) / 3.0


# ----------------------------------------------------------------------------------------------
# Dam breaks
# ----------------------------------------------------------------------------------------------


def ritter(x, t, d0, x_dam=0.0, g=GRAVITY):
    """Dry-bed dam break (Ritter 1892): depth and velocity at positions ``x`` and time ``t``.

    Water of depth ``d0`` at rest for x < x_dam, dry bed for x > x_dam, flat frictionless bed,
    dam removed instantly at t = 0. With c0 = sqrt(g d0) and xi = (x - x_dam)/t:

    ======================  ===========================  ====================
    region                  d                            u
    ======================  ===========================  ====================
    xi <= -c0               d0                           0
    -c0 < xi < 2 c0         (2 c0 - xi)^2 / (9 g)        2 (c0 + xi) / 3
    xi >= 2 c0              0                            0
    ======================  ===========================  ====================

    Valid until the rarefaction head (x_dam - c0 t) reaches a wall or the column's end.

    Parameters
    ----------
    x : array_like
        Positions [m].
    t : float
        Time since the dam break [s], >= 0. At t = 0 the initial step is returned
        (d = d0 for x <= x_dam, else 0; u = 0).
    d0 : float
        Initial upstream depth [m], > 0.
    x_dam : float
        Dam position [m].
    g : float
        Gravitational acceleration [m/s2].

    Returns
    -------
    d, u : ndarray
        Depth [m] and velocity [m/s], shaped like ``x``.

    References
    ----------
    Ritter, A. (1892). Die Fortpflanzung der Wasserwellen. Z. Verein Deutscher Ingenieure 36.
    Delestre, O. et al. (2013). SWASHES: a compilation of shallow water analytic solutions
    for hydraulic and environmental studies. Int. J. Numer. Meth. Fluids 72, section 4.1.
    """
    t = _check_time(t)
    if not d0 > 0.0:
        raise ValueError(f"upstream depth d0 must be > 0 m, got {d0}")
    x = np.asarray(x, dtype=float)
    if t == 0.0:
        d = np.where(x <= x_dam, float(d0), 0.0)
        return d, np.zeros_like(d)
    c0 = math.sqrt(g * d0)
    xi = (x - x_dam) / t
    d_fan, u_fan = _rarefaction(xi, c0, g)
    d = np.where(xi <= -c0, d0, np.where(xi < 2.0 * c0, d_fan, 0.0))
    u = np.where((xi > -c0) & (xi < 2.0 * c0), u_fan, 0.0)
    return d, u


def ritter_front(t, d0, x_dam=0.0, g=GRAVITY):
    """Wet/dry front position of the Ritter dam break, x_f = x_dam + 2 sqrt(g d0) t [m].

    ``t`` may be an array [s]. Reference: Ritter (1892); see :func:`ritter`.
    """
    return x_dam + 2.0 * np.sqrt(g * d0) * np.asarray(t, dtype=float)


def stoker_middle_state(d_left, d_right, g=GRAVITY):
    """Middle state (d_m, u_m) and bore speed s of the wet-bed dam break (Stoker 1957).

    The left state (d_l, 0) connects to the middle state through a rarefaction, on which the
    Riemann invariant is constant:

        u_m + 2 c_m = 2 c_l,    c = sqrt(g d).                                          (1)

    The middle state connects to the still right state (d_r, 0) through a bore moving at
    speed s > 0. Conservation of mass and momentum across the bore (jump conditions in the
    bore frame) give

        d_m (s - u_m) = d_r s,                                                          (2)
        d_m (s - u_m)^2 + g d_m^2 / 2 = d_r s^2 + g d_r^2 / 2.                          (3)

    Substituting (2) into (3), d_r s^2 (d_r - d_m)/d_m = g (d_r - d_m)(d_r + d_m)/2, so for
    d_m != d_r

        s = sqrt(g d_m (d_m + d_r) / (2 d_r)),   u_m = s (1 - d_r / d_m),               (4)

    equivalently u_m = s - g d_r (1 + sqrt(1 + 8 s^2/(g d_r))) / (4 s). The function
    f(d_m) = 2 (c_l - c_m) - u_m(d_m) from (1) and (4) is positive at d_m = d_r and negative
    at d_m = d_l, and its root is found with Brent's method.

    Parameters
    ----------
    d_left, d_right : float
        Upstream and downstream depths [m], with 0 < d_right < d_left.
    g : float
        Gravitational acceleration [m/s2].

    Returns
    -------
    d_m, u_m, s : float
        Middle depth [m], middle velocity [m/s] and bore speed [m/s].

    References
    ----------
    Stoker, J. J. (1957). Water Waves. Interscience, New York, ch. 10.
    Delestre, O. et al. (2013). SWASHES, Int. J. Numer. Meth. Fluids 72, section 4.1.1.
    """
    d_l, d_r = float(d_left), float(d_right)
    if not (0.0 < d_r < d_l):
        raise ValueError(f"need 0 < d_right < d_left, got d_left={d_l}, d_right={d_r}")
    c_l = math.sqrt(g * d_l)

    def bore(d_m):
        s = math.sqrt(g * d_m * (d_m + d_r) / (2.0 * d_r))
        return s, s * (1.0 - d_r / d_m)

    def f(d_m):
        return 2.0 * (c_l - math.sqrt(g * d_m)) - bore(d_m)[1]

    d_m = brentq(f, d_r, d_l, xtol=1e-15 * d_l, rtol=4.0 * np.finfo(float).eps, maxiter=200)
    s, u_m = bore(d_m)
    return d_m, u_m, s


def stoker(x, t, d_left, d_right, x_dam=0.0, g=GRAVITY):
    """Wet-bed dam break (Stoker 1957): depth and velocity at positions ``x`` and time ``t``.

    Still water of depth d_l for x < x_dam and d_r < d_l for x > x_dam, flat frictionless
    bed. With c_l = sqrt(g d_l), the middle state (d_m, u_m), c_m = sqrt(g d_m) and the bore
    speed s from :func:`stoker_middle_state`:

    ================================================  =====================  ==============
    region                                            d                      u
    ================================================  =====================  ==============
    x <= x_dam - c_l t                                d_l                    0
    x_dam - c_l t < x < x_dam + (u_m - c_m) t         (2 c_l - xi)^2/(9 g)   2(c_l + xi)/3
    x_dam + (u_m - c_m) t <= x < x_dam + s t          d_m                    u_m
    x >= x_dam + s t                                  d_r                    0
    ================================================  =====================  ==============

    with xi = (x - x_dam)/t. ``d_right = 0`` gives :func:`ritter`. At t = 0 the initial step
    is returned. Valid until a wave reaches a boundary.

    Parameters
    ----------
    x : array_like
        Positions [m].
    t : float
        Time [s], >= 0.
    d_left, d_right : float
        Upstream and downstream depths [m], 0 <= d_right < d_left.
    x_dam : float
        Dam position [m].
    g : float
        Gravitational acceleration [m/s2].

    Returns
    -------
    d, u : ndarray
        Depth [m] and velocity [m/s], shaped like ``x``.

    References
    ----------
    Stoker, J. J. (1957). Water Waves. Interscience, New York, ch. 10.
    Delestre, O. et al. (2013). SWASHES, Int. J. Numer. Meth. Fluids 72, section 4.1.1.
    """
    if float(d_right) == 0.0:
        return ritter(x, t, d_left, x_dam=x_dam, g=g)
    t = _check_time(t)
    d_m, u_m, s = stoker_middle_state(d_left, d_right, g)
    x = np.asarray(x, dtype=float)
    if t == 0.0:
        d = np.where(x <= x_dam, float(d_left), float(d_right))
        return d, np.zeros_like(d)
    c_l = math.sqrt(g * d_left)
    xi = (x - x_dam) / t
    xi_tail = u_m - math.sqrt(g * d_m)
    d_fan, u_fan = _rarefaction(xi, c_l, g)
    fan = (xi > -c_l) & (xi < xi_tail)
    middle = (xi >= xi_tail) & (xi < s)
    d = np.where(xi <= -c_l, d_left, np.where(fan, d_fan, np.where(middle, d_m, d_right)))
    u = np.where(fan, u_fan, np.where(middle, u_m, 0.0))
    return d, u


def stoker_bore_position(t, d_left, d_right, x_dam=0.0, g=GRAVITY):
    """Bore position x_b = x_dam + s t [m] of the Stoker dam break; ``t`` may be an array [s].

    s is the bore speed of :func:`stoker_middle_state` (eq. 4 there); with d_right = 0 the
    "bore" is the Ritter dry front, s = 2 sqrt(g d_left).
    """
    if float(d_right) == 0.0:
        return ritter_front(t, d_left, x_dam, g)
    s = stoker_middle_state(d_left, d_right, g)[2]
    return x_dam + s * np.asarray(t, dtype=float)


# ----------------------------------------------------------------------------------------------
# Thacker's planar oscillation in a paraboloid
# ----------------------------------------------------------------------------------------------


def thacker_period(h0=10.0, a=3000.0, g=GRAVITY):
    """Period T = 2 pi / omega [s] of Thacker's planar oscillation, omega = sqrt(2 g h0)/a.

    h0 [m] is the depth of the paraboloid at its centre, a [m] the radius of the still-water
    shoreline. Reference: Thacker, W. C. (1981), J. Fluid Mech. 107, 499-508.
    """
    return 2.0 * math.pi * a / math.sqrt(2.0 * g * h0)


def thacker_shoreline(t, h0=10.0, a=3000.0, eta=1500.0, g=GRAVITY):
    """Centre and radius of the wet disc of Thacker's planar oscillation.

    Completing the square in d = H - b (see :func:`thacker_planar`) gives

        d = h0 [1 - ((x - x_c)^2 + (y - y_c)^2) / a^2],
        x_c = eta cos(omega t),  y_c = -eta sin(omega t),

    so the wet region is the disc of radius a [m] centred at (x_c, y_c) [m], which moves
    with the uniform velocity (u, v). ``t`` may be an array [s].

    Returns
    -------
    x_c, y_c, radius : ndarray, ndarray, float
    """
    w = math.sqrt(2.0 * g * h0) / a
    t = np.asarray(t, dtype=float)
    return eta * np.cos(w * t), -eta * np.sin(w * t), float(a)


def thacker_planar(x, y, t, h0=10.0, a=3000.0, eta=1500.0, g=GRAVITY):
    """Thacker's frictionless planar-surface oscillation in a paraboloidal basin.

    Bed (minimum 0 at the origin; Thacker, J. Fluid Mech. 107 (1981) 499-508):

        b(x, y) = h0 (x^2 + y^2) / a^2.

    SWASHES writes the same basin as z = -h0 (1 - r^2/a^2), i.e. b - h0: the two forms
    differ by the constant h0, and the free surface below is given for the notes' form.
    With omega = sqrt(2 g h0) / a, the free surface stays a plane that rotates around the
    basin:

        H(x, y, t) = h0 + 2 eta (h0/a) [ (x/a) cos(omega t) - (y/a) sin(omega t) - eta/(2a) ],
        d = max(H - b, 0),
        u = -eta omega sin(omega t),  v = -eta omega cos(omega t)   where d > 0, else 0.

    Substitution verifies the equations: with uniform (u, v), continuity reduces to
    d_t + u d_x + v d_y = 0, and u_t = -g H_x = -eta omega^2 cos(omega t),
    v_t = -g H_y = eta omega^2 sin(omega t) since omega^2 = 2 g h0 / a^2. The wet region is a
    disc of radius a (:func:`thacker_shoreline`) holding the constant volume pi a^2 h0 / 2.

    Parameters
    ----------
    x, y : array_like
        Positions [m] (broadcast together).
    t : float or array_like
        Time [s].
    h0 : float
        Still-water depth at the centre of the basin [m].
    a : float
        Radius of the still-water shoreline [m].
    eta : float
        Radius of the orbit of the wet disc's centre [m], eta < a keeps the origin wet.
    g : float
        Gravitational acceleration [m/s2].

    Returns
    -------
    d, u, v, bed : ndarray
        Depth [m], velocity components [m/s] and bed elevation [m], broadcast shape of x, y, t.

    References
    ----------
    Thacker, W. C. (1981). Some exact solutions to the nonlinear shallow-water wave
    equations. J. Fluid Mech. 107, 499-508.
    Delestre, O. et al. (2013). SWASHES, Int. J. Numer. Meth. Fluids 72, section 4.2.2.
    """
    x, y, t = np.broadcast_arrays(*(np.asarray(q, dtype=float) for q in (x, y, t)))
    w = math.sqrt(2.0 * g * h0) / a
    cos, sin = np.cos(w * t), np.sin(w * t)
    bed = h0 * (x**2 + y**2) / a**2
    level = h0 + 2.0 * eta * (h0 / a) * (x / a * cos - y / a * sin - eta / (2.0 * a))
    d = np.maximum(level - bed, 0.0)
    wet = d > 0.0
    u = np.where(wet, -eta * w * sin, 0.0)
    v = np.where(wet, -eta * w * cos, 0.0)
    return d, u, v, bed


def lake_at_rest(bed, level):
    """Still water over any bed: d = max(level - bed, 0) [m], u = v = 0 [m/s].

    The steady state every well-balanced scheme must preserve (Audusse et al. 2004, SIAM J.
    Sci. Comput. 25; Vacondio et al. 2012 for SPH). ``bed`` [m] and ``level`` [m] broadcast.

    Returns
    -------
    d, u, v : ndarray
    """
    d = np.maximum(np.asarray(level, dtype=float) - np.asarray(bed, dtype=float), 0.0)
    return d, np.zeros_like(d), np.zeros_like(d)
