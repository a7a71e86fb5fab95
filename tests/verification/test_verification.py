"""Analytic verification of the solver: dam breaks and Thacker's basin.

Fast cases run by default at coarse spacing; the convergence studies at the issue's spacings
are marked slow (``pytest -m slow``).
"""

import numpy as np
import pytest

from floodsph.scenario.numerics import Refinement
from floodsph.verification import cases, metrics


def test_ritter_dam_break_coarse():
    r = cases.ritter(10.0)
    assert r.mass_error_rel < 1e-12
    assert r.l1 < 0.021  # measured 1.9 % at 10 m (2.3 % before the pressure renormalisation;
    # 2.1 % at kappa 1.3; 3.7 % at 1.3 before the own-image push was floored)


def test_stoker_dam_break_coarse():
    r = cases.stoker(10.0)
    assert r.l1 < 0.01  # measured 0.62 % (1.1 % before the pressure renormalisation; 0.8 % at
    # kappa 1.3 before it)
    assert abs(r.front_error_m) <= 2 * 10.0


def test_thacker_basin_one_period_coarse():
    r = cases.thacker(200.0)
    assert r.mass_error_rel < 1e-12
    assert r.l1 < 0.03  # measured 2.4 % at 200 m (2.7 % at kappa 1.3, 2.9 % there before the shore
    # balance)
    assert abs(r.front_error_m) <= 0.2 * 200.0  # measured 32.5 m (2.7 m before the pressure
    # renormalisation, 43 m at kappa 1.3, 98 m there before the balance)


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
@pytest.mark.xfail(strict=True, reason="uniform resolution: L1 1.9 / 0.96 / 0.74 % at 10 / 5 / "
                   "2.5 m meets 1.5 % at 5 m, but the order is 0.69 and the front (0.1 m) is "
                   "119 / 17 m behind and 26 m ahead; the thin front needs splitting")
def test_ritter_convergence_meets_targets():
    results = [cases.ritter(dx) for dx in (10.0, 5.0, 2.5)]
    errors = [r.l1 for r in results]
    assert results[1].l1 <= 0.015
    assert metrics.observed_order(errors, [10.0, 5.0, 2.5]) >= 0.8
    assert all(abs(r.front_error_m) <= 2 * r.spacing for r in results)
    assert np.all(np.diff(errors) < 0)


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="split+coalesce: L1 0.86 / 0.57 / 0.29 % at 10 / 5 / "
                   "2.5 m (order 0.78); front 23 m behind, 3 m ahead, 6 m behind (two spacings "
                   "only at 5 m); the targets lie within the split-and-merge noise "
                   "(benchmarks/ritter_sensitivity.py)")
def test_refined_ritter_convergence_meets_targets():
    results = [cases.ritter(dx, refinement=Refinement.SPLIT_COALESCE) for dx in (10.0, 5.0, 2.5)]
    errors = [r.l1 for r in results]
    assert results[1].l1 <= 0.015
    assert metrics.observed_order(errors, [10.0, 5.0, 2.5]) >= 0.8
    assert all(abs(r.front_error_m) <= 2 * r.spacing for r in results)


@pytest.mark.slow
def test_refined_ritter_at_5m_beats_the_uniform_run():
    """Splitting resolves the thin front: at 5 m the L1 error meets the 1.5 % target
    (measured 0.57 %, uniform 0.96 %) and the front is within 2 spacings (3 m ahead,
    uniform 17 m behind)."""
    r = cases.ritter(5.0, refinement=Refinement.SPLIT_COALESCE)
    assert r.mass_error_rel < 1e-12 and r.splits > 0 and r.merges > 0
    assert r.l1 <= 0.015
    assert abs(r.front_error_m) <= 2 * 5.0
