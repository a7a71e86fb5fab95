"""The boundary state of an inflow section from the discharge and the interior water.

At an inflow section with inward unit normal n, let w = u . n be the normal velocity and
c = sqrt(g d) the celerity. Where the flow is subcritical (w < c) one characteristic, of speed
w - c < 0, leaves the domain through the section and carries the Riemann invariant

    w - 2 sqrt(g d) = w_I - 2 sqrt(g d_I)                                    (1)

from the interior state (d_I, w_I) (``docs/method.md`` §8, with the outward normal
-n). The discharge per unit width q = Q / L is the second condition,

    d_B w_B = q.                                                              (2)

With w_B = q / d_B, f(d) = q / d - 2 sqrt(g d) - (w_I - 2 sqrt(g d_I)) falls monotonically
from +inf to -inf, so (1)-(2) has exactly one root for q > 0. If that root is supercritical
(w_B >= sqrt(g d_B)) or the interior is dry, the section passes critical flow

    d_c = (q^2 / g)^(1/3),   w_c = q / d_c                                     (3)

(``docs/method.md`` §8; critical depth: Chow, Open-channel
hydraulics, 1959, eq. 4-5 for a rectangular section).
"""

from __future__ import annotations

import math

import numpy as np

from floodsph.constants import GRAVITY

SUBCRITICAL = "subcritical"
CRITICAL = "critical"
CLOSED = "closed"


def critical_depth(q: float) -> float:
    """Critical depth d_c = (q^2 / g)^(1/3) [m] of a unit discharge q [m2/s], eq. (3)."""
    return (q * q / GRAVITY) ** (1.0 / 3.0)


def inflow_state(q: float, d_i: float, w_i: float) -> tuple[float, float, str]:
    """Depth d_B [m] and inward normal velocity w_B [m/s] at an inflow section.

    Parameters
    ----------
    q : float
        Discharge per unit width through the section [m2/s], q >= 0.
    d_i : float
        Interior depth next to the section [m]; 0 when the interior is dry.
    w_i : float
        Interior velocity along the inward normal [m/s].

    Returns
    -------
    (d_B, w_B, regime): regime is ``"subcritical"`` (root of (1)-(2)), ``"critical"``
    (eq. (3)) or ``"closed"`` (q = 0: the section holds the interior water like a gate,
    w_B = 0 and d_B from (1), or d_B = 0 on a dry interior).
    """
    if q <= 0.0:
        if d_i <= 0.0:
            return 0.0, 0.0, CLOSED
        root = math.sqrt(d_i) - w_i / (2.0 * math.sqrt(GRAVITY))
        return max(root, 0.0) ** 2, 0.0, CLOSED
    d_c = critical_depth(q)
    if d_i <= 0.0:
        return d_c, q / d_c, CRITICAL
    invariant = w_i - 2.0 * math.sqrt(GRAVITY * d_i)
    d = _root(q, invariant, d_c)
    w = q / d
    if w >= math.sqrt(GRAVITY * d):
        return d_c, q / d_c, CRITICAL
    return d, w, SUBCRITICAL


def _root(q: float, invariant: float, d_c: float) -> float:
    """Root of f(d) = q/d - 2 sqrt(g d) - invariant (f decreasing): Newton in a bracket."""
    lo, hi = 0.0, max(d_c, 1e-6)
    while q / hi - 2.0 * math.sqrt(GRAVITY * hi) - invariant > 0.0:
        lo, hi = hi, 2.0 * hi
    d = hi
    for _ in range(200):
        f = q / d - 2.0 * math.sqrt(GRAVITY * d) - invariant
        if f > 0.0:
            lo = d
        else:
            hi = d
        step = f / (-q / (d * d) - math.sqrt(GRAVITY / d))
        new = d - step
        if not lo < new < hi:
            new = 0.5 * (lo + hi)
        if abs(new - d) <= 1e-15 * d:
            return new
        d = new
    return d


def level_state(d_0: np.ndarray, d_i: np.ndarray, w_i: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """Depth d_B [m] and inward normal velocity w_B [m/s] where a water level is imposed.

    ``d_0`` is the imposed depth, level minus bed [m] (0 where the level is below the bed);
    ``d_i`` and ``w_i`` the interior depth [m] (0 where dry) and velocity along the inward
    normal [m/s]; all arrays of one value per boundary column. Cases, in order:

    * d_0 = 0: no water at the boundary, d_B = w_B = 0 (interior water that reaches the line
      leaves as over a free overfall);
    * dry interior: the boundary water spreads onto the dry bed as Ritter's dam break, whose
      state at the dam is critical: d_B = 4 d_0 / 9, w_B = 2 sqrt(g d_0) / 3 (Stoker, Water
      waves, 1957, section 10.6);
    * subcritical: d_B = d_0 and, from the outgoing invariant (1),
      w_B = w_I - 2 sqrt(g d_I) + 2 sqrt(g d_0), positive when water enters;
    * that w_B supercritical inwards (w_B >= sqrt(g d_0)): both characteristics enter, the
      boundary passes the critical flow from water at rest at level d_0, as in the dry case;
    * that w_B supercritical outwards (w_B <= -sqrt(g d_0)): both characteristics leave, the
      boundary takes the interior state, d_B = d_I, w_B = w_I.
    """
    d_0 = np.maximum(np.asarray(d_0, dtype=np.float64), 0.0)
    d_i = np.asarray(d_i, dtype=np.float64)
    w_i = np.asarray(w_i, dtype=np.float64)
    c_0 = np.sqrt(GRAVITY * d_0)
    w_sub = w_i - 2.0 * np.sqrt(GRAVITY * np.maximum(d_i, 0.0)) + 2.0 * c_0
    d_b = d_0.copy()
    w_b = w_sub
    critical = (d_i <= 0.0) | (w_sub >= c_0)
    d_b = np.where(critical, 4.0 / 9.0 * d_0, d_b)
    w_b = np.where(critical, 2.0 / 3.0 * c_0, w_b)
    leaving = ~critical & (w_sub <= -c_0)
    d_b = np.where(leaving, d_i, d_b)
    w_b = np.where(leaving, w_i, w_b)
    dry = d_0 <= 0.0
    return np.where(dry, 0.0, d_b), np.where(dry, 0.0, w_b)
