"""The members: their scenarios built from the base and the samples, checked, written, run.

Member ``m0003`` lives in ``members/m0003/``, which is its run folder: it holds the member's
``scenario.toml`` (the base scenario resolved, with the sampled values filled in, its name
``<base name>-m0003`` and ``output.directory`` this folder) and, for a raster scaled by a
factor, the scaled raster the scenario points at (:mod:`floodsph.ensemble.rasters`); the run
writes everything else.

Before any member runs, :func:`build_members` checks

1. each key path against the base scenario (:mod:`floodsph.ensemble.keys`); keys that fix the
   map grid or the run folder (:data:`FIXED_KEYS`) cannot be sampled, because every member
   must map onto the base scenario's grid;
2. each parameter's values alone, then each member's values together, with the scenario's own
   validation (``floodsph.scenario.reader.scenario_from_dict``), and a parametric breach's derived
   set-up (``floodsph.breach.params.resolve``).

Relative paths among sampled values (``distribution = "choice"`` of files) are relative to the
ensemble file. The members' maps must be GeoTIFFs (the aggregation reads them), so
``"geotiff"`` is added to ``output.formats`` if the base leaves it out.

:func:`run_member` is what a dask worker executes for one member; it is the one place that
calls :func:`floodsph.run.pipeline.run_scenario`.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from floodsph.ensemble.keys import MISSING, KeyPath, KeyPathError, assign, base_value, lookup
from floodsph.ensemble.manifest import NOT_RUN
from floodsph.ensemble.rasters import RASTER_KEYS, raster_name
from floodsph.ensemble.sampling import Samples
from floodsph.ensemble.spec import EnsembleSpec, Mode, Parameter
from floodsph.errors import InputError
from floodsph.scenario.config import Scenario
from floodsph.scenario.reader import scenario_from_dict
from floodsph.scenario.schema import is_number, join

MEMBERS_DIR = "members"
SCENARIO_NAME = "scenario.toml"
#: Keys (and everything under them) that no parameter may sample.
FIXED_KEYS = ("scenario.name", "terrain.dem", "terrain.crs", "terrain.dem_variable",
              "terrain.extent", "output.directory", "output.resolution_m", "output.formats")


def member_id(index: int) -> str:
    """``m0000``, ``m0001``, ... (the contract's member names)."""
    return f"m{index:04d}"


@dataclass(frozen=True)
class Binding:
    """A parameter resolved against the base scenario: ``base`` is the value a factor
    multiplies (None in value mode); ``raster`` is True for a raster scaled by a factor."""

    parameter: Parameter
    base: Any
    raster: bool

    def value(self, drawn):
        """The scenario value for a drawn number (a raster factor keeps the base path)."""
        if self.parameter.mode is Mode.VALUE or self.raster:
            return self.base if self.raster else drawn
        return self.base * drawn

    def describe(self, drawn) -> str:
        """``key = value`` as in messages; ``key = base x factor = value`` for factors."""
        key = self.parameter.key.text
        if self.parameter.mode is Mode.VALUE:
            return f"{key} = {drawn!r}"
        if self.raster:
            return f"{key} = {self.base} x {drawn!r}"
        return f"{key} = {self.base!r} x {drawn!r} = {self.value(drawn)!r}"


@dataclass(frozen=True)
class ScaledRaster:
    """A raster to scale into a member's folder: ``source`` x ``factor`` -> ``target``."""

    source: Path
    target: Path
    factor: float
    where: str


@dataclass(frozen=True)
class Member:
    """One member: its id, run folder, scenario (the TOML text to write) and rasters."""

    id: str
    folder: Path
    scenario_text: str
    rasters: tuple[ScaledRaster, ...] = ()

    @property
    def scenario_path(self) -> Path:
        return self.folder / SCENARIO_NAME


def _fail(spec: EnsembleSpec, where: str, message: str) -> InputError:
    return InputError(f"{spec.path.name}: {where}: {message}")


def bind_parameters(spec: EnsembleSpec, base: dict) -> list[Binding]:
    """Check every parameter's key path (and factor) against the resolved ``base`` dict."""
    out = []
    for p in spec.parameters:
        where = join(p.where, "key")
        for fixed in FIXED_KEYS:
            if p.key.text == fixed or p.key.text.startswith((fixed + ".", fixed + "[")):
                raise _fail(spec, where, f"{fixed} cannot be sampled: every member maps onto "
                                         "the base scenario's grid, into its own folder")
        try:
            value = base_value(base, p.key) if p.mode is Mode.FACTOR else lookup(base, p.key)
        except KeyPathError as exc:
            raise _fail(spec, where, f"{p.key}: {exc}") from None
        except InputError as exc:
            raise _fail(spec, where, f"{p.key}: the base breach cannot be resolved: "
                                     f"{exc}") from None
        if p.mode is Mode.VALUE:
            out.append(Binding(p, None, False))
            continue
        _check_factors(spec, p)
        raster = p.key.pattern in RASTER_KEYS and isinstance(value, str)
        if value is MISSING:
            raise _fail(spec, join(p.where, "mode"),
                        f"{p.key} has no value in the base scenario to multiply; give the "
                        'values themselves (mode = "value")')
        if not raster and not is_number(value):
            raise _fail(spec, join(p.where, "mode"),
                        f'mode = "factor" needs a number or a raster at {p.key} '
                        f"({', '.join(RASTER_KEYS)}); the base scenario has {value!r}")
        out.append(Binding(p, value, raster))
    return out


def _check_factors(spec: EnsembleSpec, p: Parameter) -> None:
    """A factor parameter's choice values must be numbers."""
    values = getattr(p.distribution, "values", ())
    for k, v in enumerate(values):
        if not is_number(v):
            raise _fail(spec, join(join(p.where, "values"), k),
                        f'mode = "factor" needs numbers, got {v!r}')


def base_dict(base: Scenario) -> dict:
    """The base scenario as the members start from it (geotiff maps always written)."""
    data = base.to_dict()
    formats = data["output"].setdefault("formats", [])
    if "geotiff" not in formats:
        formats.append("geotiff")
    return data


def build_members(spec: EnsembleSpec, base: Scenario, samples: Samples,
                  folder: Path) -> list[Member]:
    """Every member of ``spec`` in the ensemble ``folder`` (nothing is written yet).

    Raises InputError naming the parameter (or the member's values) that the scenario
    refuses; see the module docstring.
    """
    data = base_dict(base)
    bindings = bind_parameters(spec, data)
    members_dir = Path(folder).resolve() / MEMBERS_DIR
    for binding, column in zip(bindings, zip(*samples.rows, strict=True), strict=True):
        for m, drawn in enumerate(column):
            _check_alone(spec, base, data, binding, drawn, member_id(m))
    out = []
    for m, drawn in enumerate(samples.rows):
        mid = member_id(m)
        member_folder = members_dir / mid
        values = data
        for binding, value in zip(bindings, drawn, strict=True):
            values = assign(values, binding.parameter.key, binding.value(value))
        values = assign(values, KeyPath.parse("scenario.name"), f"{base.name}-{mid}")
        values = assign(values, KeyPath.parse("output.directory"), str(member_folder))
        try:
            scenario = _validate(spec, base, values)
        except InputError as exc:
            sampled = "; ".join(b.describe(v) for b, v in zip(bindings, drawn, strict=True))
            raise InputError(f"{spec.path.name}: member {mid}: the base scenario refuses its "
                             f"sampled values together ({sampled}): {exc}") from None
        resolved = scenario.to_dict()
        rasters = []
        for binding, value in zip(bindings, drawn, strict=True):
            if binding.raster:
                target = member_folder / raster_name(binding.parameter.key)
                resolved = assign(resolved, binding.parameter.key, str(target))
                rasters.append(ScaledRaster(Path(binding.base), target, float(value),
                                            f"{spec.path.name}: {binding.parameter.where}"))
        out.append(Member(mid, member_folder, _toml(spec, mid, bindings, drawn, resolved),
                          tuple(rasters)))
    return out


def _check_alone(spec, base, data, binding: Binding, drawn, mid: str) -> None:
    """The scenario's verdict on one parameter's value with every other input as the base."""
    p = binding.parameter
    if binding.raster and not (drawn > 0):
        raise _fail(spec, p.where, f"{binding.describe(drawn)} (member {mid}): a raster "
                                   "factor must be > 0")
    try:
        _validate(spec, base, assign(data, p.key, binding.value(drawn)))
    except InputError as exc:
        raise _fail(spec, p.where, f"{binding.describe(drawn)} (member {mid}) is refused by "
                                   f"the base scenario: {exc}") from None


def _validate(spec: EnsembleSpec, base: Scenario, data: dict) -> Scenario:
    """``data`` through the scenario's validation, and its breaches through their set-up."""
    from floodsph.breach.params import resolve

    scenario = scenario_from_dict(data, source=base.path.name, base_dir=spec.path.parent)
    for inflow in scenario.inflows:
        if inflow.breach is not None:
            resolve(inflow.breach)
    return scenario


def _toml(spec: EnsembleSpec, mid: str, bindings, drawn, resolved: dict) -> str:
    from tomli_w import dumps

    lines = [f"# Member {mid} of the ensemble {spec.name!r} ({spec.path}); sampled values:"]
    lines += [f"#   {b.describe(v)}" for b, v in zip(bindings, drawn, strict=True)]
    lines.append("# This folder is the member's run folder.")
    return "\n".join(lines) + "\n\n" + dumps(resolved)


def write_member(member: Member) -> None:
    """Create the member's folder with its scaled rasters and ``scenario.toml``."""
    from floodsph.ensemble.rasters import scale_raster

    member.folder.mkdir(parents=True, exist_ok=True)
    for r in member.rasters:
        scale_raster(r.source, r.target, r.factor, r.where)
    member.scenario_path.write_text(member.scenario_text, encoding="utf-8")


def completed_manifest(member: Member) -> dict | None:
    """The member's ``run.json`` if its folder holds a completed run of this very scenario.

    That is: ``scenario.toml`` reads as the member's, and ``run.json`` says ``completed`` for
    the scenario that file loads into.
    """
    from floodsph.run.manifest import read_manifest
    from floodsph.scenario.reader import load_scenario

    manifest = read_manifest(member.folder)
    if manifest is None or manifest.get("status") != "completed":
        return None
    path = member.scenario_path
    if not path.is_file() or path.read_text(encoding="utf-8") != member.scenario_text:
        return None
    try:
        expected = load_scenario(path).to_dict()
    except InputError:
        return None
    same = _plain_json(manifest.get("scenario")) == _plain_json(expected)
    return manifest if same else None


def _plain_json(value):
    return json.loads(json.dumps(value, sort_keys=True, default=str))


#: How often a running member asks whether the ensemble is stopping [s of wall time].
STOP_POLL_S = 1.0


@dataclass(frozen=True)
class MemberTask:
    """What a worker needs to run one member: its folder, numba threads, whether a completed
    run there may be replaced, and the name of the ``distributed.Event`` that is set when the
    ensemble stops (None: not asked)."""

    id: str
    folder: str
    threads: int
    overwrite: bool
    stop_event: str | None = None


@dataclass(frozen=True)
class MemberResult:
    """How a member's run ended: ``status`` from its run.json (or ``"failed"``), its wall
    time [s] and the one-line error of a failed run."""

    id: str
    status: str
    wall_time_s: float | None
    error: str | None = None


def run_member(task: MemberTask) -> MemberResult:
    """Run one member in its folder (on a dask worker); a failure is returned, not raised."""
    from floodsph.run.pipeline import error_message, run_scenario
    from floodsph.scenario.reader import load_scenario

    start = time.monotonic()
    folder = Path(task.folder)
    stopping = _stop_request(task.stop_event)
    if stopping is not None and stopping(poll=True):
        return MemberResult(task.id, NOT_RUN, None)  # the ensemble stopped before its turn
    try:
        scenario = load_scenario(folder / SCENARIO_NAME)
        manifest = run_scenario(scenario, out_dir=folder, progress=False,
                                overwrite=task.overwrite, threads=task.threads,
                                stop_requested=stopping)
    except Exception as exc:  # recorded as the member's failure; the ensemble goes on
        return MemberResult(task.id, "failed", time.monotonic() - start, error_message(exc))
    return MemberResult(task.id, manifest["status"], manifest.get("wall_time_s"),
                        manifest.get("error"))


def _stop_request(event_name: str | None):
    """``stop_requested()`` for :func:`floodsph.run.pipeline.run_scenario`: the reason once
    the ensemble's ``distributed.Event`` is set, asked at most every :data:`STOP_POLL_S`."""
    if event_name is None:
        return None
    from distributed import Event

    event = Event(event_name)
    last = [-STOP_POLL_S]

    def requested(poll: bool = False) -> str | None:
        now = time.monotonic()
        if not poll and now - last[0] < STOP_POLL_S:
            return None
        last[0] = now
        return "the ensemble's stop request" if event.is_set() else None

    return requested
