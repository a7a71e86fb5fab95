"""Seeded unit samples (Latin hypercube or Monte Carlo) and the parameter values they give.

Both designs draw an (n members x d parameters) array u in [0, 1) from
``numpy.random.default_rng(seed)``, so the same seed always gives the same samples:

* ``latin-hypercube`` (McKay, Beckman & Conover 1979, Technometrics 21, 239-245;
  ``scipy.stats.qmc.LatinHypercube``): each parameter's [0, 1) is cut into n strata of
  width 1/n and every stratum holds exactly one member, at a random place inside it, the
  strata of different parameters paired by independent random permutations. Each marginal is
  covered evenly even for a few members, so estimates converge faster than Monte Carlo for
  the additive part of the response;
* ``monte-carlo``: independent uniform draws. The first k members of an n-member Monte Carlo
  ensemble are those of the k-member ensemble with the same seed.

Each column is then mapped through its distribution's inverse CDF
(:mod:`floodsph.ensemble.distributions`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from floodsph.ensemble.spec import EnsembleSpec, Sampling


def unit_samples(sampling: Sampling, members: int, dimensions: int, seed: int) -> np.ndarray:
    """(members, dimensions) samples in [0, 1) of the design ``sampling``."""
    rng = np.random.default_rng(seed)
    if dimensions == 0:
        return np.empty((members, 0))
    if sampling is Sampling.LATIN_HYPERCUBE:
        from scipy.stats import qmc

        return qmc.LatinHypercube(d=dimensions, seed=rng).random(members)
    return rng.random((members, dimensions))


@dataclass(frozen=True)
class Samples:
    """The drawn values: ``rows[m][j]`` is member m's value of parameter j (for a
    ``mode = "factor"`` parameter, the factor), with the parameters' key paths."""

    keys: tuple[str, ...]
    rows: tuple[tuple, ...]


def draw_samples(spec: EnsembleSpec) -> Samples:
    """The parameter values of every member of ``spec`` (same spec, same values)."""
    u = unit_samples(spec.sampling, spec.members, len(spec.parameters), spec.seed)
    columns = [p.distribution.ppf(u[:, j]) for j, p in enumerate(spec.parameters)]
    rows = tuple(tuple(column[m] for column in columns) for m in range(spec.members))
    return Samples(tuple(p.key.text for p in spec.parameters), rows)
