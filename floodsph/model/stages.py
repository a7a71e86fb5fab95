"""The stages of a time step, shared by the global and the local driver.

One step (kick-drift-kick leap-frog with a variable CFL step, ``docs/method.md`` §5):

1. kick   v^{n+1/2} = v^n + a^n dt / 2 (the drivers, ``floodsph.sph.time_step``)
2. drift  x^{n+1} = x^n + v^{n+1/2} dt; moves across walls are reflected; particles that
          leave an open border or enter nodata are removed and counted as outflow
          (:func:`move`)
3. density guess from continuity, neighbour lists, Newton-Raphson solve of rho and h
          (:func:`interactions`: ``floodsph.model.list_stages``, :func:`solve_density`)
4. forces a^{n+1} at (x^{n+1}, v^{n+1/2}) (``floodsph.model.force_stages``)
5. kick   v^{n+1} = v^{n+1/2} + a^{n+1} dt / 2, then implicit Manning friction over dt
6. next dt = cfl min h / (|v| + c) (:func:`stable_dt`)

Each stage takes what it reads and changes: the fixed :class:`Domain`, the run's
:class:`State`, the :class:`Workspace` of lists, and the open boundaries. The drivers
(``floodsph.model.stepping`` for the global step, ``floodsph.model.local_stepping`` for
local time stepping) take a :class:`Parts`, all of these together.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from floodsph.boundaries.protocol import Boundary, Site
from floodsph.constants import RHO_WATER
from floodsph.model.domain import Domain
from floodsph.model.force_stages import evaluate_forces
from floodsph.model.list_stages import block_pairs, update_lists, wall_lists
from floodsph.model.refinement import Refiner
from floodsph.model.refinement_site import RefinementSite
from floodsph.model.state import State
from floodsph.model.workspace import Workspace
from floodsph.sph import density, level_momentum, level_offsets, time_step
from floodsph.sph.cells import CellGrid

SETTLE_ROUNDS = 30
"""Rounds of list building and density solve when the model is set up (h may grow 10-fold)."""


class Parts(NamedTuple):
    """Everything a driver hands to the stages: the domain, the state, the workspace, the
    open boundaries with what they see (``site``), and the refiner (or None) with what it
    sees (``refinement_site``)."""

    domain: Domain
    state: State
    work: Workspace
    boundaries: Sequence[Boundary]
    site: Site
    refiner: Refiner | None
    refinement_site: RefinementSite


def begin_step(parts: Parts) -> None:
    """Before either driver: no lists built in this step yet, none at the current positions
    known, and the lists built if particles were added or removed between steps."""
    work = parts.work
    work.lists_fresh = False
    work.lists_here = False
    if work.nl is None:  # particles were added or removed between steps
        update_lists(parts.domain, parts.state, work)


def move(parts: Parts, dt: float) -> None:
    """Drift every particle by dt (walls reflect), let the open boundaries act, drop what
    left the domain, and advance density and h by the continuity guess. Under the balanced
    momentum the level offsets of moving water fade with the distance travelled, and still
    water held by its banks is damped and tethered (``floodsph.sph.level_offsets``)."""
    domain, state, work = parts.domain, parts.state, parts.work
    p = state.particles
    if domain.balanced:
        level_offsets.decay_offsets(p.u, p.v, p.h, dt, p.bank_held, p.eta_offset)
        level_offsets.hold_still(p.u, p.v, p.x, p.y, p.x_seed, p.y_seed, p.bank_held, dt,
                                 level_momentum.HOLD_TIME, level_momentum.HOLD_STIFFNESS)
    count_moves = parts.site.count_moves
    moves = None if count_moves is None else (p.x.copy(), p.y.copy())
    state.counters["wall_reflections"] += domain.wall_index.drift(p.x, p.y, p.u, p.v, dt)
    if moves is not None and count_moves is not None:
        count_moves(*moves, p.x, p.y, p.m)
    work.lists_here = False
    work.lap("kick_drift")
    for boundary in parts.boundaries:
        boundary.apply(state, parts.site, dt)
    remove_outside(domain, state, nodata=not domain.closed_sides)
    work.lap("boundaries")
    density.predict(p.rho, p.h, p.divv, dt)
    work.lap("density")


def synchronise(parts: Parts, steps_taken: int = 1) -> None:
    """Refinement, and the periodic re-sort, on synchronised particles; ``steps_taken``
    finest steps end here (the re-sort is due when they cross a multiple of its interval)."""
    state, work = parts.state, parts.work
    if parts.refiner is not None:
        splits, merges = parts.refiner.apply(state, parts.refinement_site)
        state.counters["splits"] += splits
        state.counters["merges"] += merges
    every = parts.domain.numerics.reorder_interval
    if every and state.steps // every != (state.steps - steps_taken) // every:
        reorder(state, work)
    work.lap("refinement")


def advance_clock(state: State, dt: float, updated: int | None = None) -> None:
    """t += dt, one more finest step, and the counters of particles and updates."""
    p = state.particles
    state.t += dt
    state.steps += 1
    state.counters["particles_max"] = max(state.counters["particles_max"], p.n)
    state.counters["particle_updates"] += p.n if updated is None else updated


def interactions(domain: Domain, state: State, work: Workspace, boundaries: Sequence[Boundary],
                 settle: bool = False, rows: np.ndarray | None = None) -> None:
    """Neighbours, density and forces of the water, with the boundaries' ghosts present.

    The ghosts (inflow buffers, mirror images beyond open edges) are appended behind the
    water, given the boundary state after the density solve, and dropped after the forces.
    ``settle`` is for the set-up (:func:`solve_density`). ``rows``: update only these
    water particles (and the ghosts), with lists built for them alone (local stepping).
    """
    p = state.particles
    water = p.mark()
    for boundary in boundaries:
        boundary.add_ghosts(p)
    work.lap("boundaries")
    if rows is None:
        update_lists(domain, state, work)
    else:
        ghosts = np.arange(water[0], p.n, dtype=np.int64)
        update_lists(domain, state, work, force=True, rows=np.concatenate([rows, ghosts]))
    solve_density(domain, state, work, settle)
    work.lap("density")
    for boundary in boundaries:
        boundary.impose(p, work.nl)
    work.lap("boundaries")
    evaluate_forces(domain, state, work)
    work.lap("forces")
    p.truncate(water)


def remove_outside(domain: Domain, state: State, nodata: bool) -> None:
    """Remove (and count as outflow) particles off the grid, and in nodata cells if
    ``nodata``, i.e. when nodata is not walled off (the walled nodata border runs through
    nodata cells, whose slivers are then wet area)."""
    p = state.particles
    inside = domain.terrain.covers(p.x, p.y, valid_only=nodata)
    if not inside.all():
        volume = float(p.m[~inside].sum() / RHO_WATER)
        state.volume_out += volume
        state.volume_out_other += volume
        p.keep(inside)


def reorder(state: State, work: Workspace) -> None:
    """Sort particles by cell so that neighbours are close in memory."""
    p = state.particles
    if p.n:
        p.permute(CellGrid(p.x, p.y, 2.0 * float(np.mean(p.h))).order)
        work.nl = None


def solve_density(domain: Domain, state: State, work: Workspace, settle: bool = False) -> None:
    """The depth-density solve.

    In a time step no h grows beyond what the neighbour lists hold, nor shrinks below
    ``density.H_SHRINK_MIN`` times its guess (``solve_density(cap=True)``; the counters
    ``density_capped`` and ``density_held``). A particle held back by lists built at this step
    catches up over the next steps; if the lists are older, they are rebuilt and the solve
    repeated once. When the model is set up (``settle``), h may move far from the seeding
    guess, so the lists are rebuilt and the solve repeated until they hold (at most
    ``SETTLE_ROUNDS``); lists of some rows alone (the set-up's settling of wall seeds)
    hold while they cover those rows, as the other particles do not change then.
    Under the balanced momentum, still water held by its banks keeps its continuity
    depth, and water just released from it has its offset matched
    (``floodsph.sph.level_offsets``).
    """
    num = domain.numerics
    p = state.particles
    h_predicted = p.h.copy()
    releasing = domain.balanced and bool((p.bank_held == level_offsets.RELEASED).any())
    rho_predicted = p.rho.copy() if releasing else None
    held = ((p.bank_held == level_offsets.HELD) | (p.bank_held == level_offsets.BANKED)
            if domain.balanced else None)
    for _ in range(SETTLE_ROUNDS if settle else 2):
        block_pairs(domain, state, work)
        nl = work.nl
        assert nl is not None  # update_lists runs first
        outcome = density.solve_density(
            p, nl, state.blocked, wall_lists(domain, state, work),
            tol=num.density_tol, max_iter=num.density_max_iter, h_ratio=num.h_ratio,
            cap=not settle, integral=domain.integral_walls, unmoved=work.lists_here,
            skip=held)
        if settle and nl.covers(p.x, p.y, p.h):
            break
        if not settle and (outcome.capped == 0 or work.lists_fresh):
            break
        work.lap("density")
        update_lists(domain, state, work, force=True, rows=None if nl.complete else nl.rows)
    nl = work.nl
    assert nl is not None
    rows = nl.rows
    if nl.complete:
        p.hgrow[:] = p.h / h_predicted
    else:
        p.hgrow[rows] = p.h[rows] / h_predicted[rows]
    if rho_predicted is not None:
        level_offsets.release(p.bank_held, rho_predicted, p.rho, p.eta_offset)
    if domain.balanced:
        level_offsets.floor_offsets(p.rho, p.bank_held, p.eta_offset)
    state.counters["density_unconverged"] += outcome.unconverged
    state.counters["density_capped"] += outcome.capped
    state.counters["density_held"] += outcome.held


def stable_dt(domain: Domain, state: State, boundaries: Sequence[Boundary]) -> float:
    """dt = cfl min h / (|v| + c) over the water and the open boundaries' buffers [s]."""
    p = state.particles
    cfl = domain.numerics.cfl
    dt = float(time_step.stable_dt(p.u, p.v, p.rho, p.h, cfl)) if p.n else np.inf
    return boundaries_dt(domain, boundaries, dt)


def boundaries_dt(domain: Domain, boundaries: Sequence[Boundary], dt: float) -> float:
    """The water's CFL step dt [s], shortened to what the open boundaries allow."""
    for boundary in boundaries:
        dt = min(dt, boundary.max_dt(domain.numerics.cfl))
    return dt
