"""``workflows/lattice_stability.py``: the curvature of the SPH energy on the square lattice."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import load_workflow

from floodsph.model import Numerics

lattice = load_workflow("lattice_stability",
                        Path(__file__).resolve().parents[1] / "workflows" / "lattice_stability.py")


def test_the_seeding_lattice_is_a_minimum_of_the_sph_energy_at_the_default_kappa_only():
    """On a periodic 6 x 6 patch the lowest curvature, translations left out, is positive at
    the default kappa = 1.2 (a minimum: still water stays still) and negative at 1.3 (a
    saddle). The values, +0.0052 and -0.0456 in units of m g d0 / (2 dx^2), are those of the
    full 72 x 72 Hessian taken by central differences without the symmetry shortcut."""
    stable = lattice.lowest_curvature(Numerics.kappa, 6)
    saddle = lattice.lowest_curvature(1.3, 6)
    assert stable > 0.0 > saddle
    assert stable == pytest.approx(0.0052, abs=5e-4)
    assert saddle == pytest.approx(-0.0456, abs=5e-4)
    with pytest.raises(ValueError, match="patch 6 too small for kappa 1.6"):
        lattice.lowest_curvature(1.6, 6)
