"""Local time stepping: one big step of 2^k finest steps, each particle at its own stride.

``FloodModel.step`` calls :func:`big_step` when ``numerics.time_stepping`` is
``TimeStepping.LOCAL``. Each particle does the kick, drift, density, forces and closing kick
of the global step (``floodsph.model.stepping``, over the same stages of
``floodsph.model.stages``) at its own power-of-two multiple of the finest step (its stride;
the kernels and the method are ``floodsph.sph.local_steps``'s). The particles whose steps end
at a finest step are updated there, with lists built for them alone; at the end of the big
step every particle is synchronised, refined and given the next finest step.
"""

from __future__ import annotations

import math

import numpy as np

from floodsph.model.stages import Parts, advance_clock, interactions, move, stable_dt, synchronise
from floodsph.sph import local_steps
from floodsph.sph.bed import MANNING


def big_step(parts: Parts, dt_max: float | None) -> float:
    """One big step of 2^k finest steps dt_f = the state's next step, k <= ``step_levels``
    (fewer when ``dt_max`` is shorter), each particle at its own stride (module docstring of
    ``floodsph.sph.local_steps``); a single step of ``dt_max`` if that is below dt_f."""
    domain, state, work = parts.domain, parts.state, parts.work
    p = state.particles
    dt_f = state.dt if dt_max is None else min(state.dt, dt_max)
    levels = domain.numerics.step_levels
    if dt_max is not None:
        levels = min(levels, int(math.floor(math.log2(dt_max / dt_f) + 1e-12)))
    n_sub = 2 ** levels
    stride = np.empty(p.n, dtype=np.int64)
    local_steps.strides(p.u, p.v, p.rho, p.h, domain.numerics.cfl, dt_f, n_sub, stride)
    nl = work.nl
    assert nl is not None  # the lists of the last step, built before the first
    local_steps.limit_strides(stride, nl.start, nl.nbr, p.n, p.stride)
    zone = np.zeros(p.n, dtype=bool)
    for boundary in parts.boundaries:
        zone |= boundary.protected(p.x, p.y)
    p.stride[zone] = 1
    half = 0.5 * dt_f
    # every particle's step begins at finest step 0
    end: np.ndarray | None = np.arange(p.n, dtype=np.int64)
    for sub in range(n_sub):
        work.lists_fresh = False
        # the steps that end at finest step sub begin anew: no particle has been added or
        # removed since (the boundaries do that in the drift, and refinement at the end)
        begin = end
        local_steps.kick(begin, p.stride, half, p.u, p.v, p.ax, p.ay)
        move(parts, dt_f)
        p.stride[p.stride == 0] = 1  # water that entered in this substep: finest stride
        last = sub == n_sub - 1
        if last:
            synchronise(parts, n_sub)  # new particles inherit their parents' strides
        end = None if last else local_steps.step_ends(p.stride, sub + 1)
        interactions(domain, state, work, parts.boundaries, rows=end)
        end = np.arange(p.n, dtype=np.int64) if end is None else end
        local_steps.close_steps(end, p.stride, dt_f, p.u, p.v, p.ax, p.ay, p.rho,
                                state.bed[:, MANNING],
                                domain.numerics.friction_depth_floor_m)
        advance_clock(state, dt_f, end.size)
    state.dt = stable_dt(domain, state, parts.boundaries)
    return n_sub * dt_f
