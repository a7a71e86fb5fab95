"""Analytic verification of the solver: dam breaks and Thacker's basin.

Fast cases run by default at coarse spacing; the convergence studies at the issue's spacings
are marked slow (``pytest -m slow``).
"""

import numpy as np
import pytest

from floodsph import testing as exact
from floodsph import verification as cases
from floodsph.refinement import Refinement


def test_ritter_dam_break_coarse():
    r = cases.ritter(10.0)
    assert r.mass_error_rel < 1e-12
    assert r.l1 < 0.025  # measured 2.1 % at 10 m (3.7 % before the own-image push was floored)


def test_stoker_dam_break_coarse():
    r = cases.stoker(10.0)
    assert r.l1 < 0.015  # measured 0.8 %
    assert abs(r.front_error_m) <= 2 * 10.0


def test_thacker_basin_one_period_coarse():
    r = cases.thacker(200.0)
    assert r.mass_error_rel < 1e-12
    assert r.l1 < 0.03  # measured 2.7 % at 200 m (2.9 % without the shore balance)
    assert abs(r.front_error_m) <= 0.25 * 200.0  # measured 43 m behind (98 m without it)


@pytest.mark.slow
def test_stoker_at_5m_meets_targets():
    r = cases.stoker(5.0)
    assert r.l1 <= 0.03
    assert abs(r.front_error_m) <= 2 * 5.0


@pytest.mark.slow
def test_thacker_at_100m_meets_targets():
    r = cases.thacker(100.0)
    assert r.mass_error_rel < 1e-12
    assert r.l1 <= 0.05
    assert abs(r.front_error_m) <= 2 * 100.0


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="uniform resolution: L1 2.1 / 1.1 / 0.8 % at 10 / 5 / "
                   "2.5 m meets 1.5 % at 5 m, but the order is 0.67 and the front (0.1 m) is "
                   "197 / 43 / 32 m behind; the thin front needs splitting")
def test_ritter_convergence_meets_targets():
    results = [cases.ritter(dx) for dx in (10.0, 5.0, 2.5)]
    errors = [r.l1 for r in results]
    assert results[1].l1 <= 0.015
    assert exact.observed_order(errors, [10.0, 5.0, 2.5]) >= 0.8
    assert all(abs(r.front_error_m) <= 2 * r.spacing for r in results)
    assert np.all(np.diff(errors) < 0)


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="split+coalesce: L1 0.97 / 0.81 / 0.61 % at 10 / 5 / "
                   "2.5 m (order 0.34: split noise where the particles first split, 900-1100 m, "
                   "dominates); front 9 / 12 / 9 m behind (two spacings only at 10 m)")
def test_refined_ritter_convergence_meets_targets():
    results = [cases.ritter(dx, refinement=Refinement()) for dx in (10.0, 5.0, 2.5)]
    errors = [r.l1 for r in results]
    assert results[1].l1 <= 0.015
    assert exact.observed_order(errors, [10.0, 5.0, 2.5]) >= 0.8
    assert all(abs(r.front_error_m) <= 2 * r.spacing for r in results)


@pytest.mark.slow
def test_refined_ritter_at_5m_beats_the_uniform_run():
    """Splitting resolves the thin front: at 5 m the L1 error meets the 1.5 % target
    (measured 0.81 %, uniform 1.1 %) and the front is within 3 spacings (12 m behind,
    uniform 43 m)."""
    r = cases.ritter(5.0, refinement=Refinement())
    assert r.mass_error_rel < 1e-12 and r.splits > 0 and r.merges > 0
    assert r.l1 <= 0.015
    assert abs(r.front_error_m) <= 3 * 5.0
