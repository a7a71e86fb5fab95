"""Physical constants (SI units), and the bound on the numbers of the inputs. Tunables live in
the scenario's numerics, never here."""

GRAVITY = 9.81
"""Gravitational acceleration g [m s-2]."""

RHO_WATER = 1000.0
"""Density of water rho_w [kg m-3]; SPH areal density is rho = rho_w * d [kg m-2]."""

LARGEST_VALUE = 1.0e12
"""The largest magnitude any number of a scenario may have. No quantity of a flood scenario in
SI units comes near it (projected coordinates stay below 1e8 m, the largest reservoirs hold
2e11 m3, 1e12 s is 30,000 years), while a value beyond it (1e308) overflows to infinity in
the first product it enters."""
