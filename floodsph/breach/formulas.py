"""Empirical dam-breach regressions and the breach weir equation (SI units throughout).

Symbols: ``V_w`` reservoir volume above the breach invert at failure [m3], ``h_b`` breach height
[m], ``h_w`` head of water above the breach invert at failure [m], g = 9.81 m/s2. Sources in
``docs/breach.md`` (HEC-RAS 1D Technical Reference, "Estimating breach
parameters" and its example application; Wahl 2004, USBR DSO-04-04).
"""

from __future__ import annotations

import math

from floodsph.constants import GRAVITY

#: Froehlich (2008) failure-mode factor k0 for the average breach width.
FROEHLICH2008_K0 = {"overtopping": 1.3, "piping": 1.0}
#: Froehlich (2008) breach side slopes, z horizontal : 1 vertical.
FROEHLICH2008_SIDE_SLOPE = {"overtopping": 1.0, "piping": 0.7}

#: Default rectangular broad-crested weir coefficient [m^0.5/s]: critical flow over a broad
#: crest gives (2/3)^1.5 sqrt(g) = 1.705; Fread's DAMBRK/BREACH value 3.1 ft^0.5/s = 1.71 SI.
#: (HEC-RAS suggests 2.0-3.2 ft^0.5/s = 1.10-1.77 SI for breaches, 2.6 = 1.44 SI by default.)
WEIR_COEFFICIENT = 1.7
#: Ratio of the side (triangular) to the rectangular weir coefficient in Fread's trapezoidal
#: breach weir, 2.45 / 3.1 (US units; the ratio is unit-free). With C_w = 1.7 the side
#: coefficient is 1.344 m^0.5/s (Fread's 2.45 ft^0.5/s = 1.35 SI).
SIDE_TO_WEIR_RATIO = 2.45 / 3.1


def froehlich2008_average_width(volume_m3, breach_height_m, mode):
    """Average breach width, Froehlich (2008): B_avg = 0.27 k0 V_w^0.32 h_b^0.04 [m].

    k0 = 1.3 for overtopping, 1.0 for piping. Froehlich, D.C. (2008) "Embankment dam breach
    parameters and their uncertainties", J. Hydraul. Eng. 134(12), 1708-1721.
    """
    return 0.27 * FROEHLICH2008_K0[mode] * volume_m3**0.32 * breach_height_m**0.04


def froehlich2008_formation_time(volume_m3, breach_height_m):
    """Breach formation time, Froehlich (2008): t_f = 63.2 sqrt(V_w / (g h_b^2)) [s]."""
    return 63.2 * math.sqrt(volume_m3 / (GRAVITY * breach_height_m**2))


def bottom_width(average_width_m, side_slope, breach_height_m):
    """Bottom width of a trapezoidal breach with the given average width [m].

    The average width of a trapezoid of height h_b, bottom width B and side slopes z:1 is
    B + z h_b, so B = B_avg - z h_b, clipped at 0 (a triangular breach).
    """
    return max(average_width_m - side_slope * breach_height_m, 0.0)


def froehlich1995_peak(volume_m3, head_m):
    """Peak breach outflow, Froehlich (1995): Q_p = 0.607 V_w^0.295 h_w^1.24 [m3/s].

    Froehlich, D.C. (1995) "Peak outflow from breached embankment dam", J. Water Resour. Plann.
    Manage. 121(1), 90-97.
    """
    return 0.607 * volume_m3**0.295 * head_m**1.24


def macdonald1984_peak(volume_m3, head_m):
    """Peak breach outflow, MacDonald & Langridge-Monopolis (1984), earthfill dams [m3/s].

    Q_p = 1.154 (V_w h_w)^0.412. Some secondary sources (e.g. pe-calc.com) print the coefficient
    as 1.175; the 1.154 value is the published one and is used here (``docs/breach.md`` §3).
    MacDonald, T.C. & Langridge-Monopolis, J. (1984) "Breaching characteristics of dam
    failures", J. Hydraul. Eng. 110(5), 567-586.
    """
    return 1.154 * (volume_m3 * head_m) ** 0.412


def progression(tau, shape):
    """Fraction of the final breach size formed at normalised time tau = (t - t_start)/t_f.

    ``"linear"``: r = tau; ``"sine"``: r = (1 - cos(pi tau))/2 = sin^2(pi tau / 2), slow at
    the start and the end and fastest half-way (the HEC-RAS "sine wave" progression). r = 0
    for tau <= 0 and 1 for tau >= 1.
    """
    if tau <= 0.0:
        return 0.0
    if tau >= 1.0:
        return 1.0
    if shape == "linear":
        return tau
    return 0.5 * (1.0 - math.cos(math.pi * tau))


def trapezoid_weir_discharge(level_m, bottom_m, bottom_width_m, side_slope, weir_coefficient):
    """Free broad-crested weir flow through a trapezoidal breach [m3/s].

    Q = C_w b y^1.5 + C_s z y^2.5 with y = H - z_b the head on the breach bottom (0 when
    negative), b the bottom width, z the side slope (H:V, both sides) and
    C_s = (2.45/3.1) C_w. This is the breach weir of Fread's NWS DAMBRK/BREACH models
    (Fread 1984, 1988: Q = 3.1 b y^1.5 + 2.45 z y^2.5 in ft-s units), with the rectangular
    coefficient exposed as ``weir_coefficient``. Assumptions: no tailwater submergence, no
    approach-velocity correction, no orifice (pressure) flow phase for piping.
    """
    y = level_m - bottom_m
    if y <= 0.0:
        return 0.0
    return weir_coefficient * (bottom_width_m * y**1.5 + SIDE_TO_WEIR_RATIO * side_slope * y**2.5)
