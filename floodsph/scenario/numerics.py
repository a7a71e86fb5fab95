"""``Numerics``: every setting of the solver, the scenario's ``[numerics]`` table as it is.

A field of :class:`Numerics` is named as its key in the scenario file
(``docs/scenario-reference.md``, ``[numerics]``): ``particle_spacing_m`` in the TOML is
``numerics.particle_spacing_m`` in the model. Its default and its bounds are written here once;
``floodsph.scenario.reader`` reads the table straight into it, and
``floodsph.model.flood_model.FloodModel`` and ``floodsph.model.refinement.Refiner`` read it. A
few fields are not scenario keys (``metadata["scenario"]`` False): the solver's inner tunables,
set by tests and studies only; they are neither read from nor written to scenario files.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass, field, fields
from enum import Enum

from floodsph.errors import InputError


class Refinement(Enum):
    """Dynamic particle refinement (Vacondio et al. 2013): splitting and coalescing."""

    SPLIT_COALESCE = "split+coalesce"
    SPLIT = "split"
    NONE = "none"

    @property
    def splits(self) -> bool:
        return self is not Refinement.NONE

    @property
    def coalesces(self) -> bool:
        return self is Refinement.SPLIT_COALESCE


class TimeStepping(Enum):
    """One time step for every particle, or each at its own (``floodsph.sph.local_steps``)."""

    GLOBAL = "global"
    LOCAL = "local"


class Stabilisation(Enum):
    """Numerical dissipation of the momentum equation (``floodsph.sph.forces``)."""

    LAX_FRIEDRICHS = "lax-friedrichs"
    RIEMANN = "riemann"
    MUSCL = "muscl"


class Momentum(Enum):
    """The pressure and bed forces: the variational form on the summation depth with the bed
    pointwise (``floodsph.sph.forces``), or the level's renormalised differences, which hold a
    lake at rest exactly (``floodsph.sph.level_momentum``)."""

    VARIATIONAL = "variational"
    BALANCED = "balanced"


class WallModel(Enum):
    """How walls hold water: mirror images (``floodsph.walls.images``), or the experimental
    boundary integral (``floodsph.sph.shadow``; measured in ``docs/still-water.md``)."""

    MIRROR = "mirror"
    INTEGRAL = "integral"


class NumericsError(InputError, ValueError):
    """A value of :class:`Numerics` out of its bounds; ``key`` is the field (= TOML key)."""

    def __init__(self, key: str, problem: str):
        super().__init__(f"numerics.{key}: {problem}")
        self.key = key
        self.problem = problem


def _setting(default, kind, *, gt=None, ge=None, le=None, optional=False, scenario=True):
    """A field of :class:`Numerics`: its default, its type (float, int or an Enum), its bounds,
    whether it may be None and whether it is a key of the scenario's ``[numerics]``."""
    return field(default=default, metadata={"kind": kind, "gt": gt, "ge": ge, "le": le,
                                            "optional": optional, "scenario": scenario})


SMOOTHING_EXCESS = 3.0
"""Default of ``Numerics.refine_smoothing_excess``: split particles relax to h = sqrt(3) kappa
sqrt(m / rho), not to the lattice value: on the coarse Ritter case (tests/sph/test_refine.py) and
the first 60 s of Malpasset this beat both no relaxation (L1 2.3 %, front 252 m behind; 128 s
of wall time) and relaxation to the lattice value (L1 3.7 %; 77 s): L1 1.8 %, front 19 m,
50 s. The Ritter convergence study is sensitive to it (``benchmarks/ritter_sensitivity.py``)."""


@dataclass(frozen=True)
class Numerics:
    """Numerical settings of the solver (defaults are the recommended production values).

    Scenario keys (``[numerics]``):

    particle_spacing_m : initial particle spacing [m]; None (the scenario's default) means the
        DEM cell size, which ``floodsph.model.from_scenario.build_model`` fills in: the model
        needs a number.
    cfl : Courant number of dt = cfl min h / (|v| + c).
    refinement : splitting and coalescing of particles (``floodsph.model.refinement``).
    threads : numba threads of a run; 0 means all cores.
    kappa : h0 / particle spacing. 1.2 (SWE-SPHysics' suggested value, ``docs/method.md`` §2): on
        the square lattice the water is seeded on, still water is then a minimum of the SPH
        energy and stays still; at 1.3, 1.25, 1.15 or 1.4-2 the lattice is a saddle of it and
        a still lake stirs itself up within minutes (``benchmarks/lattice_stability.py``).
    stabilisation : numerical dissipation, parameter-free Lax-Friedrichs (default) or Riemann.
    density_tol : Newton-Raphson tolerance on |R| / rho of the density solve.
    friction_depth_floor_m : depth floor [m] of the Manning term.
    max_slope : bed slopes steeper than this are limited in the bed term.
    refine_area_max : split above this particle area, in units of particle_spacing_m^2.
    refine_area_min : merge candidates are below this area, same units; below
        refine_area_max / 2, so that a merged pair is not split again at once.
    refine_d_min_m : no splitting of particles shallower than this [m].
    refine_max_level : at most this many generations of splitting.
    time_stepping : each particle at its own power-of-two multiple of the finest step
        (``floodsph.sph.local_steps``; the default: on Malpasset 1.7 times as fast as one
        global step, with maximum-depth maps that agree to CSI 0.977), or one step for all
        particles.
    step_levels : K of local stepping: a big step holds up to 2^K finest steps.
    wall_model : "mirror" (mirror images, the default) or "integral" (the experimental
        boundary integral of ``floodsph.sph.shadow``).
    momentum : "balanced" (the default): -g grad eta as renormalised differences of the
        free-surface level eta, a lake at rest an exact equilibrium
        (``floodsph.sph.level_momentum``), with the "lax-friedrichs" stabilisation and
        "mirror" walls only; or "variational": -g grad of the summation depth with the bed
        pointwise (``floodsph.sph.forces``), which the other stabilisations and wall models
        need.

    Inner tunables (not scenario keys):

    density_max_iter : iteration cap of the density solve.
    h_ratio : h is kept within [h0 / h_ratio, h0 h_ratio].
    neighbour_skin : relative margin of the neighbour lists.
    reorder_interval : steps between spatial re-sorts of the particle arrays (0: never).
    refine_no_merge_steps : particles born within this many steps are not merged.
    refine_merge_interval : look for merges every this many steps.
    refine_depth_jump : no merge when |d_a - d_b| > refine_depth_jump max(d_a, d_b).
    refine_speed_jump : no merge when |v_a - v_b| > refine_speed_jump sqrt(g max(d_a, d_b)).
    refine_smoothing_excess : split particles relax to h^2 rho = refine_smoothing_excess
        kappa^2 m (``floodsph.model.refinement.relax_smoothing``; 1 is the lattice value).
    """

    particle_spacing_m: float | None = _setting(None, float, gt=0.0, optional=True)
    cfl: float = _setting(0.3, float, gt=0.0, le=1.0)
    refinement: Refinement = _setting(Refinement.SPLIT_COALESCE, Refinement)
    threads: int = _setting(0, int, ge=0)
    kappa: float = _setting(1.2, float, gt=0.0)
    stabilisation: Stabilisation = _setting(Stabilisation.LAX_FRIEDRICHS, Stabilisation)
    density_tol: float = _setting(1e-3, float, gt=0.0)
    friction_depth_floor_m: float = _setting(0.01, float, gt=0.0)
    max_slope: float = _setting(1.0, float, gt=0.0)
    refine_area_max: float = _setting(2.0, float, gt=0.0)
    refine_area_min: float = _setting(0.9, float, gt=0.0)
    refine_d_min_m: float = _setting(0.01, float, ge=0.0)
    refine_max_level: int = _setting(3, int, ge=0)
    time_stepping: TimeStepping = _setting(TimeStepping.LOCAL, TimeStepping)
    step_levels: int = _setting(3, int, ge=0, le=6)
    wall_model: WallModel = _setting(WallModel.MIRROR, WallModel)
    momentum: Momentum = _setting(Momentum.BALANCED, Momentum)
    density_max_iter: int = _setting(20, int, ge=1, scenario=False)
    h_ratio: float = _setting(10.0, float, ge=1.0, scenario=False)
    neighbour_skin: float = _setting(0.1, float, ge=0.0, scenario=False)
    reorder_interval: int = _setting(25, int, ge=0, scenario=False)
    refine_no_merge_steps: int = _setting(10, int, ge=0, scenario=False)
    refine_merge_interval: int = _setting(5, int, ge=1, scenario=False)
    refine_depth_jump: float = _setting(0.5, float, ge=0.0, scenario=False)
    refine_speed_jump: float = _setting(0.5, float, ge=0.0, scenario=False)
    refine_smoothing_excess: float = _setting(SMOOTHING_EXCESS, float, ge=1.0, scenario=False)

    def __post_init__(self):
        for f in fields(self):
            problem = _problem(getattr(self, f.name), f.metadata)
            if problem is not None:
                raise NumericsError(f.name, problem)
        if not self.refine_area_min < self.refine_area_max / 2.0:
            raise NumericsError(
                "refine_area_min", f"must be below refine_area_max / 2 = "
                f"{self.refine_area_max / 2.0:g} so that a merged pair is not split again "
                f"at once; got {self.refine_area_min:g}")
        if self.momentum is Momentum.BALANCED:
            if self.stabilisation is not Stabilisation.LAX_FRIEDRICHS:
                raise NumericsError(
                    "stabilisation", f"\"{self.stabilisation.value}\" needs momentum = "
                    "\"variational\" (the balanced momentum, the default, takes "
                    "\"lax-friedrichs\" only)")
            if self.wall_model is not WallModel.MIRROR:
                raise NumericsError(
                    "wall_model", f"\"{self.wall_model.value}\" needs momentum = "
                    "\"variational\" (the balanced momentum, the default, takes \"mirror\" "
                    "walls only)")


def _problem(value, meta) -> str | None:
    """What is wrong with ``value`` for a field of metadata ``meta``, or None."""
    kind = meta["kind"]
    if issubclass(kind, Enum):
        if isinstance(value, kind):
            return None
        allowed = ", ".join(repr(e.value) for e in kind)
        return f"expected a {kind.__module__}.{kind.__name__} ({allowed}), got {value!r}"
    if value is None:
        return None if meta["optional"] else "must be given, got None"
    if isinstance(value, bool) or not isinstance(value, int if kind is int else int | float):
        return f"expected {'an integer' if kind is int else 'a number'}, got {value!r}"
    text = (lambda v: f"{v:g}") if kind is float else str
    for bound, fails, word in (("gt", operator.le, ">"), ("ge", operator.lt, ">="),
                               ("le", operator.gt, "<=")):
        limit = meta[bound]
        if limit is not None and fails(value, limit):
            return f"must be {word} {text(limit)}, got {text(value)}"
    return None


SCENARIO_KEYS = tuple(f.name for f in fields(Numerics) if f.metadata["scenario"])
"""The keys of the scenario's ``[numerics]`` table (the fields of :class:`Numerics` that are
scenario keys)."""
