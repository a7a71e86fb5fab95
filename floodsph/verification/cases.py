"""Analytic verification cases run through the real solver path (terrain, particles, model).

Each case builds a ``FloodModel`` on an analytic bed with ``Terrain.from_function``, runs it
and returns the error against the exact solution of ``floodsph.verification.exact``, with the cost
counters a speed-against-error study needs and the depth profile at the end time. Used by the
slow tests, ``benchmarks/speed_vs_error.py`` and ``benchmarks/validation_pages.py``.

Errors are measured on the Shepard-interpolated depth field of the output maps
(``floodsph.output.rasterise.interpolate``, dry = 0 where the kernel support is below half):

* Ritter (dry-bed dam break): d0 = 10 m, dam at x = 1000 m in a 2000 m x 100 m closed channel,
  t = 50 s; L1 relative over four lines along the channel; front = last x with d > 0.1 m.
* Stoker (wet-bed dam break): 10 m / 2 m, same channel and time; the bore position is where
  the depth crosses the mean of the middle and downstream depths.
* Thacker (planar surface in a paraboloid): h0 = 10 m, a = 3000 m, eta = 1500 m, one period;
  L1 relative over the exact wet disc on a 50 m grid.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from floodsph.inputs.initial_water import particles_at
from floodsph.model.builder import set_up_model
from floodsph.model.terrain import Terrain
from floodsph.output.rasterise import interpolate
from floodsph.scenario.numerics import Numerics, Refinement, TimeStepping
from floodsph.verification import exact, metrics


@dataclass(frozen=True)
class DamBreak:
    """A dam break in a closed, flat, frictionless channel along x [m, s]."""

    d_left: float
    """depth upstream of the dam [m]"""
    d_right: float
    """depth downstream of the dam [m]; 0 is Ritter's dry bed"""
    x_dam: float = 1000.0
    length: float = 2000.0
    width: float = 100.0
    t_end: float = 50.0
    cell: float = 10.0
    """cell of the analytic bed's grid [m]"""


@dataclass(frozen=True)
class Basin:
    """Thacker's paraboloid b = h0 (x^2 + y^2)/a^2 in a square of side 2 half_width [m]."""

    h0: float = 10.0
    a: float = 3000.0
    eta: float = 1500.0
    half_width: float = 5000.0
    cell: float = 50.0


RITTER = DamBreak(10.0, 0.0)
STOKER = DamBreak(10.0, 2.0)
THACKER = Basin()


@dataclass
class Profile:
    """Depth [m] along a line at the end time: the run's (Shepard-interpolated) and the exact
    solution's, at positions ``x`` [m] along the line."""

    x: np.ndarray
    d: np.ndarray
    d_exact: np.ndarray
    line: str


@dataclass
class CaseResult:
    case: str
    spacing: float
    particles: int
    steps: int
    wall_s: float
    particle_steps: int
    interactions: int
    l1: float
    front_error_m: float
    mass_error_rel: float
    refinement: str = "none"
    particles_max: int = 0
    splits: int = 0
    merges: int = 0
    time_stepping: str = "global"
    profile: Profile | None = None

    @property
    def particle_steps_per_s(self) -> float:
        return self.particle_steps / self.wall_s

    @property
    def interactions_per_s(self) -> float:
        return self.interactions / self.wall_s


def _lattice_model(bed, xlim, ylim, cell, depth, dx, kappa, u=0.0, v=0.0, **numerics):
    """A FloodModel on an analytic bed with particles on a lattice of spacing dx where the
    depth exceeds 1 mm (water seeded at rest carries its level d + b, as in a scenario);
    ``numerics``: fields of its ``Numerics`` (``refinement`` default
    ``Refinement.NONE``: uniform resolution, another mode adds a refiner; ``time_stepping``
    default ``TimeStepping.GLOBAL``, the step the validation pages' figures were measured
    with)."""
    from floodsph.model.refinement import Refiner

    terrain = Terrain.from_function(bed, xlim, ylim, cell)
    X, Y = np.meshgrid(np.arange(dx / 2, terrain.width, dx), np.arange(dx / 2, terrain.height, dx))
    x, y = X.ravel(), Y.ravel()
    xw, yw = x + terrain.x0, y + terrain.y0
    u0 = np.broadcast_to(u(xw, yw) if callable(u) else u, x.shape)
    v0 = np.broadcast_to(v(xw, yw) if callable(v) else v, x.shape)
    d0 = depth(xw, yw)
    level = np.where((u0 == 0.0) & (v0 == 0.0), d0 + bed(xw, yw), np.nan)
    p = particles_at(x, y, d0, dx, kappa, u=u0, v=v0, d_min=1e-3, eta_seed=level)
    num = Numerics(particle_spacing_m=dx, kappa=kappa,
                   **{"refinement": Refinement.NONE, "time_stepping": TimeStepping.GLOBAL,
                      **numerics})
    return set_up_model(terrain, p, num, refiner=Refiner.of(num))


def _run(model, t_end):
    """Run to t_end; return (wall seconds, particle-steps, neighbour interactions).

    Particle-steps are the model's ``particle_updates``: particles times steps with one global
    step, the particles updated in each finest step with local time stepping."""
    pst = model.state.counters["particle_updates"]
    pairs = 0
    t0 = time.perf_counter()
    while model.t < t_end - 1e-9:
        pairs += model.work.nl.count()
        model.step(t_end - model.t)
    return time.perf_counter() - t0, model.state.counters["particle_updates"] - pst, pairs


def _labels(model) -> tuple[str, int, int, int, str]:
    """(refinement, particles_max, splits, merges, time_stepping) of a finished run, for
    ``CaseResult``."""
    c = model.state.counters
    num = model.numerics
    return (num.refinement.value, c["particles_max"], c["splits"], c["merges"],
            num.time_stepping.value)


def _depth_at(model, qx, qy):
    p = model.particles
    d = interpolate(qx, qy, p.x, p.y, p.u, p.v, p.m, p.rho, p.h)[0]
    return np.nan_to_num(d, nan=0.0)


def _channel_profile(model, xq):
    ys = np.array([12.5, 37.5, 62.5, 87.5])
    X, Y = np.meshgrid(xq, ys)
    return _depth_at(model, X.ravel(), Y.ravel()).reshape(X.shape).mean(axis=0)


def _dam_break(case: DamBreak, dx: float, kappa: float, numerics) -> tuple:
    """Run a dam break; returns (model, initial volume, wall, particle-steps, pairs, x, d, exact
    d) with the depth profile on 1 m bins along the channel."""
    model = _lattice_model(lambda x, y: 0 * x, (0, case.length), (0, case.width), case.cell,
                           lambda x, y: np.where(x < case.x_dam, case.d_left, case.d_right),
                           dx, kappa, **numerics)
    v0 = model.volume()
    wall, pst, pairs = _run(model, case.t_end)
    xq = np.arange(0.5, case.length, 1.0)
    d = _channel_profile(model, xq)
    d_ex, _ = exact.stoker(xq, case.t_end, case.d_left, case.d_right, x_dam=case.x_dam)
    return model, v0, wall, pst, pairs, xq, d, d_ex


def ritter(dx: float, kappa: float = Numerics.kappa, **numerics) -> CaseResult:
    """Dry-bed dam break (Ritter), ``RITTER``: d0 = 10 m, t = 50 s; ``numerics``: fields of the
    model's ``Numerics`` (``refinement`` default: ``Refinement.NONE``, uniform resolution)."""
    c = RITTER
    model, v0, wall, pst, pairs, xq, d, d_ex = _dam_break(c, dx, kappa, numerics)
    front = metrics.front_position(xq, d, 0.1) - metrics.front_position(xq, d_ex, 0.1)
    return CaseResult("ritter", dx, model.particles.n, model.steps, wall, pst, pairs,
                      metrics.l1_relative(d, d_ex), float(front),
                      abs(model.volume() - v0) / v0, *_labels(model),
                      Profile(xq, d, d_ex, "mean of four lines along the channel"))


def stoker(dx: float, kappa: float = Numerics.kappa, **numerics) -> CaseResult:
    """Wet-bed dam break (Stoker), ``STOKER``: 10 m over 2 m, t = 50 s."""
    c = STOKER
    model, v0, wall, pst, pairs, xq, d, d_ex = _dam_break(c, dx, kappa, numerics)
    d_m, _, _ = exact.stoker_middle_state(c.d_left, c.d_right)
    right = xq > c.x_dam
    bore = xq[right][d[right] > 0.5 * (d_m + c.d_right)].max()
    front = bore - exact.stoker_bore_position(c.t_end, c.d_left, c.d_right, x_dam=c.x_dam)
    return CaseResult("stoker", dx, model.particles.n, model.steps, wall, pst, pairs,
                      metrics.l1_relative(d, d_ex), float(front),
                      abs(model.volume() - v0) / v0, *_labels(model),
                      Profile(xq, d, d_ex, "mean of four lines along the channel"))


def thacker(dx: float, kappa: float = Numerics.kappa, periods: float = 1.0,
            **numerics) -> CaseResult:
    """Thacker's planar surface in a paraboloid (``THACKER``), frictionless, over ``periods``
    periods; the profile is along the x axis through the basin's centre."""
    c = THACKER
    h0, a, eta, w = c.h0, c.a, c.eta, c.half_width
    t_end = periods * exact.thacker_period(h0, a)
    model = _lattice_model(
        lambda x, y: h0 * (x**2 + y**2) / a**2, (-w, w), (-w, w), c.cell,
        lambda x, y: exact.thacker_planar(x, y, 0.0, h0, a, eta)[0], dx, kappa,
        u=lambda x, y: exact.thacker_planar(x, y, 0.0, h0, a, eta)[1],
        v=lambda x, y: exact.thacker_planar(x, y, 0.0, h0, a, eta)[2], **numerics)
    v0 = model.volume()
    wall, pst, pairs = _run(model, t_end)
    xq = np.arange(-w + c.cell / 2, w, c.cell)
    X, Y = np.meshgrid(xq, xq)
    d = _depth_at(model, X.ravel() + w, Y.ravel() + w)
    d_ex = exact.thacker_planar(X.ravel(), Y.ravel(), t_end, h0, a, eta)[0]
    wet = d_ex > 0
    l1 = float(np.abs(d - d_ex)[wet].sum() / d_ex[wet].sum())
    r_wet = np.hypot(X.ravel() - eta, Y.ravel())[(d > 1e-3)]
    shore = float(r_wet.max() - a) if r_wet.size else np.nan
    xl = np.arange(-w + 5.0, w, 10.0)
    line = Profile(xl, _depth_at(model, xl + w, np.full(xl.shape, w)),
                   exact.thacker_planar(xl, 0.0 * xl, t_end, h0, a, eta)[0], "y = 0")
    return CaseResult("thacker", dx, model.particles.n, model.steps, wall, pst, pairs, l1,
                      shore, abs(model.volume() - v0) / v0, *_labels(model), line)


CASES = {"ritter": ritter, "stoker": stoker, "thacker": thacker}
