"""The force stage: the accelerations a^{n+1} of the water at the new positions.

``docs/method.md`` §5, step 4: the bed sampled at the particles, then under the variational
momentum the pressure and shock-capturing pair forces (``floodsph.sph.forces``, renormalised
by ``floodsph.sph.consistency``, balanced at walls by ``floodsph.sph.shadow`` and at shores
by ``floodsph.sph.shore``) and the bed slope; under the balanced momentum the level gradient
of ``floodsph.sph.level_momentum`` for slow water, blended with the variational forces as the
water speeds up (``floodsph.sph.momentum_blend``).
"""

from __future__ import annotations

import numpy as np

from floodsph.constants import GRAVITY
from floodsph.model.domain import Domain
from floodsph.model.list_stages import block_pairs, wall_lists
from floodsph.model.state import State
from floodsph.model.workspace import Workspace
from floodsph.sph import bed as bedmod
from floodsph.sph import (
    consistency,
    forces,
    level_momentum,
    level_offsets,
    momentum_blend,
    shadow,
    shore,
)
from floodsph.sph.sums import SUMS
from floodsph.sph.velocity_gradient import velocity_gradient


def evaluate_forces(domain: Domain, state: State, work: Workspace) -> None:
    """The accelerations (ax, ay) and the velocity divergence of the listed particles
    (module docstring)."""
    p = state.particles
    t = domain.terrain
    if state.bed.shape[0] != p.n:
        state.bed = np.empty((p.n, bedmod.BED_COLUMNS))
        state.pair_sums = np.empty((p.n, SUMS))
    assert work.nl is not None  # the lists of the density solve
    rows = work.nl.rows
    bedmod.sample_bed(rows, p.x, p.y, t.dx, t.dy,  # type: ignore[call-arg]  # numba's *args
                      *t.bed_grids(), state.bed)
    if work.blocked_for is not work.nl:  # the density loop rebuilt the lists last
        block_pairs(domain, state, work)
    if not domain.balanced:
        _variational_forces(domain, state, work, rows)
        return
    if state.eta.shape[0] != p.n:
        state.eta = np.empty(p.n)
        state.ghost = np.zeros(p.n)
    level_offsets.levels(p.x, p.y, p.rho, p.eta_offset, t.elevation, t.dx, t.dy, state.eta)
    momentum_blend.release(rows, p.u, p.v, state.eta, p.eta_seed, p.bank_held)
    weight = np.empty(rows.shape[0])
    momentum_blend.variational_weights(rows, p.u, p.v, weight)
    taken = weight > 0.0
    moving = rows[taken]
    if moving.size:
        _variational_forces(domain, state, work, moving)
        a_var = (p.ax[moving], p.ay[moving], p.divv[moving])
    slow = rows[weight < 1.0]
    if slow.size:
        _balanced_forces(domain, state, work, slow)
    if moving.size:
        momentum_blend.blend(moving, weight[taken], *a_var, p.ax, p.ay, p.divv)


def _variational_forces(domain: Domain, state: State, work: Workspace,
                        rows: np.ndarray) -> None:
    """The variational momentum's accelerations of the particles ``rows``
    (``floodsph.sph.forces``, renormalised by ``floodsph.sph.consistency``, balanced at
    shores by ``floodsph.sph.shore``, and the bed)."""
    p = state.particles
    t = domain.terrain
    nl, near = work.nl, work.walls_near
    assert nl is not None and near is not None  # the lists of the density solve
    if domain.scheme == forces.MUSCL:
        velocity_gradient(rows, p.x, p.y, p.u, p.v, p.m, p.rho, p.h, nl.start,
                          nl.nbr, state.blocked, p.dudx, p.dudy, p.dvdx, p.dvdy)
    forces.internal_acceleration(rows, p.x, p.y, p.u, p.v, p.m, p.rho, p.alpha, p.h, p.kxx,
                                 p.kxy, p.kyy, p.dudx, p.dudy, p.dvdx, p.dvdy, nl.start,
                                 nl.nbr, state.blocked, wall_lists(domain, state, work),
                                 domain.scheme, state.pair_sums, p.ax, p.ay, p.divv)
    consistency.update_renormalisation(rows, p.h, state.pair_sums, domain.shores, p.kxx,
                                       p.kxy, p.kyy)
    if state.walled.shape[0] != p.n:
        state.walled = np.zeros(p.n, dtype=np.bool_)
    if domain.integral_walls:
        shadow.balance_walls(rows, p.x, p.y, p.rho, p.h, near.wstart, near.wseg, domain.seg,
                             state.pair_sums, p.ax, p.ay, state.walled)
    if domain.shores:
        shore.balance_shores(rows, p.x, p.y, p.u, p.v, p.rho, p.h, state.bed, t.dx, t.dy,
                             t.elevation, state.pair_sums, state.walled, p.ax, p.ay)
    forces.add_bed_acceleration(rows, p.u, p.v, state.bed, domain.numerics.max_slope, p.ax,
                                p.ay, GRAVITY, 0.0)


def _balanced_forces(domain: Domain, state: State, work: Workspace, rows: np.ndarray) -> None:
    """The balanced momentum's accelerations of the particles ``rows``
    (``floodsph.sph.level_momentum``), on the levels of all particles (``state.eta``)."""
    p = state.particles
    t = domain.terrain
    nl = work.nl
    assert nl is not None  # the lists of the density solve
    level_momentum.balanced_acceleration(rows, p.x, p.y, p.u, p.v, p.m, p.rho, p.alpha, p.h,
                                         state.eta, state.bed, nl.start, nl.nbr,
                                         state.blocked, wall_lists(domain, state, work),
                                         t.elevation, domain.held, p.bank_held, t.dx, t.dy,
                                         p.ax, p.ay, p.divv, state.ghost)
    forces.add_bed_acceleration(rows, p.u, p.v, state.bed, domain.numerics.max_slope, p.ax,
                                p.ay, 0.0, -GRAVITY)
