"""Manning values that are really Strickler or Chezy coefficients.

Manning's n [s m^-1/3] of natural surfaces spans about 0.01 (smooth concrete) to 0.2 (dense
brush and trees at flood stage; Chow 1959, Open-Channel Hydraulics, table 5-6). The Strickler
coefficient K_st = 1/n [m^1/3 s^-1] and Chezy's C [m^1/2 s^-1] of the same surfaces lie
between about 10 and 100, so a "Manning" value of 1 or more is one of those and is refused,
with the conversion n = 1/K_st. Values between ``N_HIGH`` and ``N_STRICKLER`` are meant
sometimes (blockage by buildings or debris in the "high roughness" practice) and warned of.
"""

from __future__ import annotations

import numpy as np

from floodsph.errors import InputError, warn

N_DEFAULT = 0.035
"""The Manning n [s m^-1/3] of ``terrain.manning`` when the scenario gives none, of the order
of grass-covered floodplains (Chow 1959, table 5-6)."""

N_STRICKLER = 1.0
"""n at or above this [s m^-1/3] is refused as a Strickler or Chezy coefficient."""

N_HIGH = 0.2
"""n above this (and below ``N_STRICKLER``) is warned of: above every tabulated surface."""


def strickler_text(value: float) -> str:
    """Why ``value`` >= ``N_STRICKLER`` is no Manning n, and the conversion."""
    return (f"n = {value:g} is not a Manning coefficient [s m^-1/3] (natural surfaces have "
            f"0.01-{N_HIGH:g}) but looks like a Strickler K_st or Chezy C; convert with "
            f"n = 1/K_st (K_st = {value:g} gives n = {1.0 / value:.3g})")


def high_text(value: float) -> str:
    return (f"n = {value:g} is above {N_HIGH:g}, rougher than any tabulated natural surface "
            "(Chow 1959); check its units (buildings are better drawn as closed [[walls]])")


def check_manning_number(value: float, what: str, warnings: list[str] | None) -> None:
    """Refuse a uniform n >= ``N_STRICKLER``, warn of one above ``N_HIGH``; ``what`` names
    the key (``terrain.manning``)."""
    if value >= N_STRICKLER:
        raise InputError(f"{what}: {strickler_text(value)}")
    if value > N_HIGH:
        warn(f"{what}: {high_text(value)}", warnings)


def check_manning_grid(n: np.ndarray, valid: np.ndarray, what: str,
                       warnings: list[str] | None) -> None:
    """The same for an n grid on the DEM cells ``valid``, naming the count of cells."""
    inside = n[valid & np.isfinite(n)]
    strickler = inside[inside >= N_STRICKLER]
    if strickler.size:
        raise InputError(
            f"{what}: {strickler.size} DEM cells have n >= {N_STRICKLER:g}; the largest, "
            f"{strickler_text(float(strickler.max()))}")
    high = inside[inside > N_HIGH]
    if high.size:
        warn(f"{what}: {high.size} DEM cells have n > {N_HIGH:g}; the largest, "
             f"{high_text(float(high.max()))}", warnings)
