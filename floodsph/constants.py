"""Physical constants (SI units). Tunables live in the scenario's numerics, never here."""

GRAVITY = 9.81
"""Gravitational acceleration g [m s-2]."""

RHO_WATER = 1000.0
"""Density of water rho_w [kg m-3]; SPH areal density is rho = rho_w * d [kg m-2]."""
