"""Error measures of a numerical solution against an exact one: the relative L1 norm, the
position of a wet/dry front, and the observed order of convergence."""

from __future__ import annotations

import math

import numpy as np


def l1_relative(d_num, d_exact, weights=None):
    """Relative L1 error  sum(|d_num - d_exact| w) / sum(|d_exact| w)  [-].

    ``weights`` w are the cell areas or particle areas (m/rho) of the samples; None means 1.
    Raises ValueError if the weighted norm of ``d_exact`` is zero.
    """
    d_num, d_exact = np.asarray(d_num, dtype=float), np.asarray(d_exact, dtype=float)
    w = np.ones_like(d_exact) if weights is None else np.asarray(weights, dtype=float)
    norm = np.sum(np.abs(d_exact) * w)
    if not norm > 0.0:
        raise ValueError("l1_relative: the weighted exact field is zero; relative error undefined")
    return float(np.sum(np.abs(d_num - d_exact) * w) / norm)


def front_position(x, d, threshold):
    """Largest ``x`` [m] at which ``d > threshold`` (a wet/dry front), NaN if no sample is wet.

    ``x`` and ``d`` are arrays of the same shape (grid nodes or particles, any order).
    """
    x, d = np.asarray(x, dtype=float), np.asarray(d, dtype=float)
    if x.shape != d.shape:
        raise ValueError(f"front_position: x shape {x.shape} differs from d shape {d.shape}")
    wet = d > threshold
    return float(np.max(x[wet])) if np.any(wet) else math.nan


def observed_order(errors, spacings):
    """Observed convergence order p: least-squares slope of log(error) against log(spacing).

    For errors e_k = C dx_k^p this returns p exactly. Needs at least two distinct positive
    spacings and positive errors.
    """
    e, h = np.asarray(errors, dtype=float), np.asarray(spacings, dtype=float)
    if e.shape != h.shape or e.ndim != 1 or e.size < 2:
        raise ValueError("observed_order: need two 1-D arrays of equal length >= 2")
    if np.any(e <= 0.0) or np.any(h <= 0.0) or np.ptp(h) == 0.0:
        raise ValueError("observed_order: errors and spacings must be positive, spacings distinct")
    return float(np.polyfit(np.log(h), np.log(e), 1)[0])
