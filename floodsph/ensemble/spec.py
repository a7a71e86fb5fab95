"""The ensemble file: one TOML ``[ensemble]`` table, read into a frozen, validated spec.

Keys (contract: ``ensemble-format.md``)::

    [ensemble]
    name = "valley-breach-mc"     # required; default output folder out/<name> beside the file
    base = "scenario.toml"        # required: the base scenario, relative to this file
    members = 64                  # required, >= 1
    sampling = "latin-hypercube"  # or "monte-carlo"
    seed = 1                      # required, integer >= 0

    [[ensemble.parameters]]       # repeatable
    key = "terrain.manning"       # a key path into the base scenario (floodsph.ensemble.keys)
    distribution = "uniform"      # and its parameters (floodsph.ensemble.distributions)
    low = 0.8
    high = 1.2
    mode = "factor"               # "factor" multiplies the base value; "value" (default)

    [ensemble.output]
    depth_thresholds_m = [0.1, 0.5, 1.0, 2.0]
    quantiles = [0.05, 0.5, 0.95]

Every problem is an :class:`~floodsph.errors.InputError` naming the file and the key path
(``ensemble.toml: ensemble.parameters[1].std: must be > 0, got 0``). Whether a key path exists
in the base scenario, and whether the scenario accepts the sampled values, is checked when the
members are built (:mod:`floodsph.ensemble.members`), still before any member runs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum
from pathlib import Path

from floodsph.ensemble.distributions import OPTIONAL, PARAMETERS, Distribution, read_distribution
from floodsph.ensemble.keys import KeyPath, KeyPathError
from floodsph.scenario.schema import Reader, describe, is_number, join, read_toml

ENSEMBLE_KEYS = ("name", "base", "members", "sampling", "seed", "parameters", "output")
OUTPUT_KEYS = ("depth_thresholds_m", "quantiles")
DEFAULT_THRESHOLDS_M = (0.1, 0.5, 1.0, 2.0)
DEFAULT_QUANTILES = (0.05, 0.5, 0.95)


class Sampling(Enum):
    """How the unit samples are drawn (``floodsph.ensemble.sampling``)."""

    LATIN_HYPERCUBE = "latin-hypercube"
    MONTE_CARLO = "monte-carlo"


class Mode(Enum):
    """What a sampled number is: the value itself, or a factor on the base value."""

    VALUE = "value"
    FACTOR = "factor"


@dataclass(frozen=True)
class Parameter:
    """One sampled input: its key path, distribution and mode; ``where`` is its own key path
    in the ensemble file (``ensemble.parameters[0]``), for messages."""

    key: KeyPath
    distribution: Distribution
    mode: Mode
    where: str

    def to_dict(self) -> dict:
        return {"key": self.key.text, **self.distribution.to_dict(), "mode": self.mode.value}


@dataclass(frozen=True)
class EnsembleOutput:
    """``[ensemble.output]``: max-depth thresholds [m] and quantile probabilities (0..1)."""

    depth_thresholds_m: tuple[float, ...] = DEFAULT_THRESHOLDS_M
    quantiles: tuple[float, ...] = DEFAULT_QUANTILES


@dataclass(frozen=True)
class EnsembleSpec:
    """A validated ensemble file; ``path`` and ``base`` are absolute."""

    path: Path
    name: str
    base: Path
    members: int
    seed: int
    sampling: Sampling = Sampling.LATIN_HYPERCUBE
    parameters: tuple[Parameter, ...] = ()
    output: EnsembleOutput = EnsembleOutput()

    @property
    def output_directory(self) -> Path:
        """The default ensemble folder: ``out/<name>`` beside the ensemble file."""
        return self.path.parent / "out" / self.name

    def to_dict(self) -> dict:
        """The resolved ensemble (absolute base path, defaults filled) as plain data."""
        return {
            "name": self.name,
            "base": str(self.base),
            "members": self.members,
            "sampling": self.sampling.value,
            "seed": self.seed,
            "parameters": [p.to_dict() for p in self.parameters],
            "output": {"depth_thresholds_m": list(self.output.depth_thresholds_m),
                       "quantiles": list(self.output.quantiles)},
        }


def load_ensemble(path: str | Path) -> EnsembleSpec:
    """Read and validate an ensemble TOML file (InputError naming the file and key)."""
    path = Path(path)
    data = read_toml(path, "ensemble")
    return ensemble_from_dict(data, source=str(path), base_dir=path.resolve().parent)


def ensemble_from_dict(data: dict, *, source: str, base_dir: Path) -> EnsembleSpec:
    """Validate parsed TOML ``data``; ``source`` names the file in messages."""
    r = Reader(source, Path(base_dir))
    r.check_keys(data, "", ("ensemble",))
    if "ensemble" not in data:
        raise r.fail("ensemble", "required table [ensemble] is missing")
    p = "ensemble"
    t = r.sub_table(data, "", p, ENSEMBLE_KEYS)
    name = r.string(t, p, "name")
    if not name.strip() or name in (".", "..") or any(c in name for c in "/\\:"):
        raise r.fail(join(p, "name"), f"must be a non-empty folder name without / \\ :, got "
                                      f"{name!r}")
    parameters: list[Parameter] = []
    for i, table in enumerate(r.table_array(t, "parameters")):
        parameter = _parameter(r, table, join(join(p, "parameters"), i))
        if any(q.key.text == parameter.key.text for q in parameters):
            raise r.fail(join(parameter.where, "key"),
                         f"{parameter.key.text} is sampled twice (one parameter per key)")
        parameters.append(parameter)
    return EnsembleSpec(
        path=(Path(base_dir) / Path(source).name).resolve(),
        name=name,
        base=r.existing_file(t, p, "base"),
        members=r.integer(t, p, "members", ge=1),
        seed=r.integer(t, p, "seed", ge=0),
        sampling=r.choice(t, p, "sampling", Sampling, Sampling.LATIN_HYPERCUBE),
        parameters=tuple(parameters),
        output=_output(r, t, join(p, "output")),
    )


def _parameter(r: Reader, table, where: str) -> Parameter:
    table = r.table(table, where)
    distribution = read_distribution(r, table, where)
    name = distribution.name
    r.check_keys(table, where, ("key", "distribution", "mode", *PARAMETERS[name],
                                *OPTIONAL.get(name, ())))
    try:
        key = KeyPath.parse(r.string(table, where, "key"))
    except KeyPathError as exc:
        raise r.fail(join(where, "key"), str(exc)) from None
    mode_value = table.get("mode", Mode.VALUE.value)
    if name == "triangular" and is_number(mode_value):
        mode_value = Mode.VALUE.value
    mode = r.as_choice(mode_value, join(where, "mode"), Mode)
    return Parameter(key=key, distribution=distribution, mode=mode, where=where)


def threshold_label(t: float) -> str:
    """The depth threshold in file names: ``p_depth_gt_<label>m.tif`` (0.1 -> ``0.1``)."""
    return f"{t:g}"


def quantile_label(q: float) -> str:
    """The quantile in file names, as a percentage: 0.05 -> ``q05``, 0.975 -> ``q97.5``."""
    pct = 100.0 * q
    return f"q{round(pct):02d}" if abs(pct - round(pct)) < 1e-9 else f"q{pct:g}"


def _output(r: Reader, t: dict, where: str) -> EnsembleOutput:
    table = r.sub_table(t, "ensemble", "output", OUTPUT_KEYS)
    return EnsembleOutput(
        depth_thresholds_m=_numbers(r, table, where, "depth_thresholds_m",
                                    DEFAULT_THRESHOLDS_M, threshold_label, low=0.0,
                                    low_open=False),
        quantiles=_numbers(r, table, where, "quantiles", DEFAULT_QUANTILES, quantile_label,
                           low=0.0, high=1.0),
    )


def _numbers(r: Reader, table: dict, where: str, key: str, default: tuple, label, *,
             low: float, high: float = math.inf, low_open: bool = True) -> tuple[float, ...]:
    """A non-empty array of numbers in (low, high) (or [low, high) if not ``low_open``) whose
    file-name ``label``s differ."""
    if key not in table:
        return default
    path = join(where, key)
    values = table[key]
    if not isinstance(values, list) or not values:
        raise r.fail(path, f"expected a non-empty array of numbers, got {describe(values)}")
    out: list[float] = []
    for k, v in enumerate(values):
        inside = is_number(v) and (v > low if low_open else v >= low) and v < high
        if not inside:
            bounds = f"{'>' if low_open else '>='} {low:g}" + (
                f" and < {high:g}" if math.isfinite(high) else "")
            raise r.fail(join(path, k), f"expected a number {bounds}, got {describe(v)}")
        same = [w for w in out if label(w) == label(float(v))]
        if same:
            raise r.fail(join(path, k), f"{v!r} has the same file name ({label(float(v))}) as "
                                        f"{same[0]!r}: list each value once")
        out.append(float(v))
    return tuple(out)
