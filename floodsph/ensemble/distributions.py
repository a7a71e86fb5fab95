"""The distributions a sampled parameter follows, each mapping u in [0, 1) to a value.

Every distribution turns the unit samples of :mod:`floodsph.ensemble.sampling` into values
with its inverse CDF (``scipy.stats``), so a Latin hypercube in u stays a Latin hypercube in
the values:

=============  ==========================  ===============================================
distribution   parameters                  value
=============  ==========================  ===============================================
uniform        low < high                  low + u (high - low)
normal         mean, std > 0               mean + std Phi^-1(u)
lognormal      median > 0, sigma > 0       median exp(sigma Phi^-1(u)) (sigma of ln x)
triangular     low <= mode <= high,        the triangle's inverse CDF
               low < high
choice         values, weights (> 0,       values[k] for the k whose cumulative weight
               default equal)              interval holds u
=============  ==========================  ===============================================

The triangle's mode may be written ``peak`` instead of ``mode``: a parameter table that also
says ``mode = "factor"`` cannot hold two ``mode`` keys (TOML).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from floodsph.scenario.schema import Reader, describe, is_number, join


@dataclass(frozen=True)
class Uniform:
    low: float
    high: float

    name = "uniform"

    def ppf(self, u: np.ndarray) -> list:
        from scipy import stats

        return _floats(stats.uniform(loc=self.low, scale=self.high - self.low).ppf(u))

    def to_dict(self) -> dict:
        return {"distribution": self.name, "low": self.low, "high": self.high}


@dataclass(frozen=True)
class Normal:
    mean: float
    std: float

    name = "normal"

    def ppf(self, u: np.ndarray) -> list:
        from scipy import stats

        return _floats(stats.norm(loc=self.mean, scale=self.std).ppf(u))

    def to_dict(self) -> dict:
        return {"distribution": self.name, "mean": self.mean, "std": self.std}


@dataclass(frozen=True)
class LogNormal:
    median: float
    sigma: float

    name = "lognormal"

    def ppf(self, u: np.ndarray) -> list:
        from scipy import stats

        return _floats(stats.lognorm(s=self.sigma, scale=self.median).ppf(u))

    def to_dict(self) -> dict:
        return {"distribution": self.name, "median": self.median, "sigma": self.sigma}


@dataclass(frozen=True)
class Triangular:
    low: float
    mode: float
    high: float

    name = "triangular"

    def ppf(self, u: np.ndarray) -> list:
        from scipy import stats

        width = self.high - self.low
        shape = (self.mode - self.low) / width
        return _floats(stats.triang(c=shape, loc=self.low, scale=width).ppf(u))

    def to_dict(self) -> dict:
        return {"distribution": self.name, "low": self.low, "peak": self.mode,
                "high": self.high}


@dataclass(frozen=True)
class Choice:
    values: tuple
    weights: tuple[float, ...]

    name = "choice"

    def ppf(self, u: np.ndarray) -> list:
        edges = np.cumsum(self.weights) / math.fsum(self.weights)
        index = np.minimum(np.searchsorted(edges, u, side="right"), len(self.values) - 1)
        return [self.values[k] for k in index]

    def to_dict(self) -> dict:
        return {"distribution": self.name, "values": list(self.values),
                "weights": list(self.weights)}


Distribution = Uniform | Normal | LogNormal | Triangular | Choice


def _floats(values: np.ndarray) -> list[float]:
    return [float(v) for v in np.atleast_1d(values)]


#: distribution name -> the parameter keys it needs (besides key, distribution and mode).
PARAMETERS = {
    "uniform": ("low", "high"),
    "normal": ("mean", "std"),
    "lognormal": ("median", "sigma"),
    "triangular": ("low", "mode", "high"),
    "choice": ("values",),
}
#: Keys a distribution may also take.
OPTIONAL = {"triangular": ("peak",), "choice": ("weights",)}


def read_distribution(r: Reader, table: dict, where: str):
    """The distribution of the parameter table ``table`` at key path ``where``.

    Raises InputError naming the key for an unknown distribution, a missing or non-numeric
    parameter, or impossible parameters (``low >= high``, ``std <= 0``, ...).
    """
    name = r.string(table, where, "distribution")
    if name not in PARAMETERS:
        raise r.fail(join(where, "distribution"),
                     f"expected one of {', '.join(map(repr, PARAMETERS))}, got {describe(name)}")
    if name == "choice":
        return _choice(r, table, where)
    if name == "triangular" and is_number(table.get("mode")) and "peak" in table:
        raise r.fail(join(where, "peak"), "give the triangle's mode as mode or as peak, not both")
    numbers = {}
    for key in PARAMETERS[name]:
        given = key
        if name == "triangular" and key == "mode" and not is_number(table.get("mode")):
            given = "peak"
        if given not in table:
            needs = " and ".join(PARAMETERS[name]).replace("mode", "mode (or peak)")
            raise r.fail(join(where, key), f"required key is missing: a {name} distribution "
                                           f"needs {needs}")
        numbers[key] = r.number(table, where, given)
    if name in ("uniform", "triangular") and not numbers["low"] < numbers["high"]:
        raise r.fail(join(where, "high"), f"must be > low = {numbers['low']:g}, got "
                                          f"{numbers['high']:g}")
    if name == "uniform":
        return Uniform(numbers["low"], numbers["high"])
    if name == "normal":
        r.number(table, where, "std", gt=0.0)
        return Normal(numbers["mean"], numbers["std"])
    if name == "lognormal":
        r.number(table, where, "median", gt=0.0)
        r.number(table, where, "sigma", gt=0.0)
        return LogNormal(numbers["median"], numbers["sigma"])
    if not numbers["low"] <= numbers["mode"] <= numbers["high"]:
        peak = "mode" if is_number(table.get("mode")) else "peak"
        raise r.fail(join(where, peak), f"must lie between low = {numbers['low']:g} and "
                                        f"high = {numbers['high']:g}, got {numbers['mode']:g}")
    return Triangular(numbers["low"], numbers["mode"], numbers["high"])


def _choice(r: Reader, table: dict, where: str) -> Choice:
    values = table.get("values")
    if not isinstance(values, list) or not values:
        raise r.fail(join(where, "values"), "required: a non-empty array of the values to "
                                            f"choose from, got {describe(values)}")
    weights = table.get("weights", [1.0] * len(values))
    wk = join(where, "weights")
    if not isinstance(weights, list) or len(weights) != len(values):
        raise r.fail(wk, f"expected an array of {len(values)} numbers (one per value), got "
                         f"{describe(weights)}")
    for k, w in enumerate(weights):
        if not is_number(w) or not (math.isfinite(w) and w > 0):
            raise r.fail(join(wk, k), f"expected a number > 0, got {describe(w)}")
    return Choice(tuple(values), tuple(float(w) for w in weights))
