"""The global time step: every particle advanced by the same dt (``docs/method.md`` §5).

``FloodModel.step`` calls :func:`global_step` unless ``numerics.time_stepping`` is
``TimeStepping.LOCAL`` (then ``floodsph.model.local_stepping.big_step``). Both drive the same
stages (``floodsph.model.stages``): the opening half kick, the drift with the boundaries
(:func:`~floodsph.model.stages.move`), refinement
(:func:`~floodsph.model.stages.synchronise`), lists, density and forces
(:func:`~floodsph.model.stages.interactions`), and the closing kick with Manning friction
(``floodsph.sph.time_step.close_step``).
"""

from __future__ import annotations

from floodsph.model.stages import (
    Parts,
    advance_clock,
    boundaries_dt,
    interactions,
    move,
    synchronise,
)
from floodsph.sph import bed as bedmod
from floodsph.sph import time_step


def global_step(parts: Parts, dt_max: float | None) -> float:
    """One step of dt = the state's next step (at most ``dt_max``) for every particle; the
    next step is set from the new state; returns the step taken [s]."""
    domain, state, work = parts.domain, parts.state, parts.work
    p = state.particles
    dt = state.dt if dt_max is None else min(state.dt, dt_max)
    half = 0.5 * dt
    time_step.kick(p.u, p.v, p.ax, p.ay, half)
    move(parts, dt)
    synchronise(parts)
    interactions(domain, state, work, parts.boundaries)
    num = domain.numerics
    dt_water = time_step.close_step(p.u, p.v, p.ax, p.ay, half, p.rho, p.h,
                                    state.bed[: p.n, bedmod.MANNING], dt,
                                    num.friction_depth_floor_m, num.cfl)
    advance_clock(state, dt)
    state.dt = boundaries_dt(domain, parts.boundaries, float(dt_water))
    return dt
