"""Sampling: seeded and reproducible, one Latin-hypercube sample per stratum, and each
distribution's values equal to its inverse CDF computed independently (stdlib formulas)."""

from __future__ import annotations

import math
from dataclasses import replace
from statistics import NormalDist

import numpy as np
import pytest
from ensemble_cases import ensemble_text, write_case

from floodsph.ensemble.distributions import Choice, LogNormal, Normal, Triangular, Uniform
from floodsph.ensemble.sampling import draw_samples, unit_samples
from floodsph.ensemble.spec import Sampling, load_ensemble

THREE = """
[[ensemble.parameters]]
key = "initial_water[0].level_m"
distribution = "uniform"
low = 101.0
high = 103.0

[[ensemble.parameters]]
key = "terrain.manning"
distribution = "normal"
mean = 0.03
std = 0.005

[[ensemble.parameters]]
key = "numerics.cfl"
distribution = "lognormal"
median = 0.3
sigma = 0.2
"""


@pytest.fixture
def spec(tmp_path):
    return load_ensemble(write_case(tmp_path, ensemble_text(THREE, members=10, seed=7)))


def test_same_seed_same_samples(spec):
    first = draw_samples(spec)
    assert draw_samples(replace(spec)).rows == first.rows
    assert draw_samples(replace(spec, seed=8)).rows != first.rows
    assert first.keys == ("initial_water[0].level_m", "terrain.manning", "numerics.cfl")


def test_latin_hypercube_puts_one_member_in_each_stratum(spec):
    """Through each distribution's CDF, the 10 values fall one into each tenth of [0, 1)."""
    rows = np.array(draw_samples(spec).rows)
    cdfs = [lambda x: (x - 101.0) / 2.0, NormalDist(0.03, 0.005).cdf,
            lambda x: NormalDist().cdf(math.log(x / 0.3) / 0.2)]
    for j, cdf in enumerate(cdfs):
        strata = sorted(int(cdf(v) * 10) for v in rows[:, j])
        assert strata == list(range(10)), (j, strata)


def test_monte_carlo_is_not_stratified_but_nested():
    """Monte Carlo draws are independent: the first 8 of 64 are the 8-member ensemble."""
    u64 = unit_samples(Sampling.MONTE_CARLO, 64, 2, seed=5)
    assert np.array_equal(unit_samples(Sampling.MONTE_CARLO, 8, 2, seed=5), u64[:8])
    strata = (u64[:, 0] * 64).astype(int)
    assert len(set(strata)) < 64


def test_uniform_and_normal_inverse_cdf():
    u = np.array([0.1, 0.5, 0.975])
    assert Uniform(2.0, 6.0).ppf(u) == pytest.approx([2.4, 4.0, 5.9])
    assert Normal(10.0, 2.0).ppf(u) == pytest.approx(
        [10.0 + 2.0 * NormalDist().inv_cdf(p) for p in u], rel=1e-12)


def test_lognormal_takes_the_median_and_the_sigma_of_ln():
    u = np.array([0.5, NormalDist().cdf(1.0)])
    assert LogNormal(0.035, 0.3).ppf(u) == pytest.approx([0.035, 0.035 * math.exp(0.3)],
                                                         rel=1e-12)


def test_triangular_inverse_cdf():
    a, c, b = 1.0, 2.0, 5.0
    u = np.array([0.1, 0.25, 0.8])
    left = (c - a) / (b - a)
    expected = [a + math.sqrt(p * (b - a) * (c - a)) if p < left
                else b - math.sqrt((1 - p) * (b - a) * (b - c)) for p in u]
    assert Triangular(a, c, b).ppf(u) == pytest.approx(expected, rel=1e-12)


def test_choice_follows_the_cumulative_weights():
    choice = Choice(("narrow", "wide"), (1.0, 3.0))
    assert choice.ppf(np.array([0.0, 0.2499, 0.25, 0.9999])) == [
        "narrow", "narrow", "wide", "wide"]
