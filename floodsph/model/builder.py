"""Setting up a FloodModel: open edges, wall segments, seeds off nodata and walls, first solve.

The model (``floodsph.model.flood_model``) only steps; this is the set-up before its first
step. In order:

1. the closed sides are checked, and the open ones get transmissive ghosts
   (``floodsph.boundaries.OpenEdges``) ahead of the other boundaries;
2. the wall segments are laid out: the scenario's walls, the closed DEM border and the
   nodata banks, with the boundaries' openings cut out (``floodsph.model.wall_layout``);
3. the boundaries act once at t = 0 (an inflow fills its buffer);
4. seeds are moved off nodata and wall lines (``floodsph.walls.nodata.settle_seeds``), and
   those off the grid (or on open nodata) removed as outflow;
5. neighbour lists and the density solve settle h from the seeding guess
   (``floodsph.model.stages.interactions(settle=True)``);
6. seeds of still water by walls are settled and their masses matched to the seeded depth
   (``floodsph.model.wall_seeds``); ``state.volume_seed_adjustment`` [m3] is the change; under
   the balanced momentum instead, every particle seeded at rest is given the level offset
   that makes its level its seeded level (:func:`match_levels`,
   ``floodsph.sph.level_offsets``);
7. the first time step dt = cfl min h / (|v| + c).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from floodsph.boundaries.open_edges import SIDES as OPEN_SIDES
from floodsph.boundaries.open_edges import OpenEdges
from floodsph.constants import RHO_WATER
from floodsph.model.domain import Domain
from floodsph.model.flood_model import FloodModel
from floodsph.model.particles import ParticleSet
from floodsph.model.stages import Parts, interactions, remove_outside, stable_dt
from floodsph.model.terrain import Terrain
from floodsph.model.wall_layout import model_segments
from floodsph.model.wall_seeds import settle_at_walls
from floodsph.scenario.numerics import Numerics
from floodsph.sph import level_offsets
from floodsph.sph.kernels import seeded_smoothing_length
from floodsph.walls.nodata import settle_seeds


def set_up_model(terrain: Terrain, particles: ParticleSet, numerics: Numerics, walls=(),
                 closed_sides: Iterable[str] = OPEN_SIDES, boundaries=(),
                 refiner=None, held=None, level_sides: Iterable[str] = ()) -> FloodModel:
    """A FloodModel ready for its first step (module docstring).

    Parameters
    ----------
    terrain : Terrain
    particles : ParticleSet
        Seeded particles (local coordinates) with m, rho = rho_w d and h = kappa dx set; the
        set is changed in place (seeds moved, removed, masses matched by walls).
    numerics : Numerics
        The solver's settings, with ``particle_spacing_m`` given.
    walls : sequence of (k, 2) arrays
        Polylines in local coordinates [m] that water cannot cross.
    closed_sides : collection of str
        The sides of the DEM rectangle (``"west"``, ``"east"``, ``"south"``, ``"north"``) that
        are walls; by default all four. Water reaching an open side leaves the model and is
        counted in ``volume_out``; the open sides get transmissive ghosts. Where any side is
        closed the nodata borders are walls too; with none closed, water entering nodata
        leaves the model.
    boundaries : sequence of floodsph.boundaries.protocol.Boundary
        Open boundaries (inflows, sinks).
    refiner : floodsph.model.refinement.Refiner or None
    held : (ny, nx) bool array or None
        The DEM cells that held water at seeding (``Domain.held``).
    level_sides : collection of str
        The sides taken by level boundaries (``floodsph.boundaries.level``, among
        ``boundaries``): neither walls nor open edges; the closed sides that meet them run on
        beyond them, as beyond an open side.
    """
    if numerics.particle_spacing_m is None:
        raise ValueError("set_up_model: numerics.particle_spacing_m must be given (the "
                         "scenario's default, the DEM cell size, is filled in by "
                         "floodsph.model.from_scenario.build_model)")
    closed = frozenset(closed_sides)
    unknown = closed - set(OPEN_SIDES)
    if unknown or isinstance(closed_sides, str):
        raise ValueError(f"closed_sides: unknown sides {sorted(unknown)}; use {OPEN_SIDES}")
    levels = frozenset(level_sides)
    if levels & closed or levels - set(OPEN_SIDES):
        raise ValueError(f"level_sides: {sorted(levels)} must be sides of {OPEN_SIDES} that "
                         "are not closed")
    boundaries = list(boundaries)
    open_sides = [side for side in OPEN_SIDES if side not in closed | levels]
    if open_sides:
        boundaries.insert(0, OpenEdges(terrain.width, terrain.height, open_sides))
    openings = [b.opening for b in boundaries if b.opening is not None]
    walled = bool(closed)
    seg = model_segments(terrain, walls, closed, walled, openings,
                         seeded_smoothing_length(numerics.kappa, numerics.particle_spacing_m),
                         numerics.particle_spacing_m)
    model = FloodModel(Domain.build(terrain, numerics, seg, closed, held), particles,
                       boundaries, refiner)
    parts = model.parts()
    domain, state, work = parts.domain, parts.state, parts.work
    for boundary in model.boundaries:
        boundary.apply(state, parts.site, 0.0)
    _seeds_off_walls(domain, state, walled)
    remove_outside(domain, state, nodata=not walled)
    rho_seed = state.particles.rho.copy()
    interactions(domain, state, work, model.boundaries, settle=True)
    if domain.balanced:
        match_levels(parts)
    else:
        state.volume_seed_adjustment = settle_at_walls(parts, rho_seed)
    state.dt = stable_dt(domain, state, model.boundaries)
    return model


def _seeds_off_walls(domain: Domain, state, walled: bool) -> None:
    """Move seeds off nodata and off wall lines (``settle_seeds``); those that cannot be moved
    are removed and counted as outflow."""
    p, t = state.particles, domain.terrain
    spacing = domain.numerics.particle_spacing_m
    assert spacing is not None  # set_up_model refuses a model without it
    x, y, lost = settle_seeds(p.x, p.y, t.valid, t.dx, t.dy, spacing,
                              domain.seg if walled else None)
    p.x[:], p.y[:] = x, y
    if lost.any():
        state.volume_out += float(p.m[lost].sum() / RHO_WATER)
        p.keep(~lost)


def match_levels(parts: Parts) -> int:
    """Give every particle seeded at rest the level offset that makes its level its seeded
    level (``floodsph.sph.level_offsets.match_offsets``), evaluate the forces again, and
    mark as held by its banks each particle seeded at rest that has no free edge then
    (``ParticleSet.bank_held``, ``floodsph.sph.level_momentum``); returns the number
    matched. For the set-up, under the balanced momentum."""
    domain, state = parts.domain, parts.state
    p = state.particles
    t = domain.terrain
    bed = np.empty(p.n)
    level_offsets.levels(p.x, p.y, np.zeros(p.n), np.zeros(p.n), t.elevation, t.dx, t.dy,
                         bed)
    matched = level_offsets.match_offsets(p.eta_seed, p.rho, bed, p.eta_offset)
    p.bank_held[:] = level_offsets.FREE
    interactions(domain, state, parts.work, parts.boundaries)
    free_edge = np.zeros(p.n, dtype=bool)
    evaluated = min(p.n, state.ghost.shape[0])  # no ghost array when all water moves
    free_edge[:evaluated] = state.ghost[:evaluated] > 0.0
    at_rest = np.isfinite(p.eta_seed) & (p.u == 0.0) & (p.v == 0.0)
    p.bank_held[:] = np.where(at_rest & ~free_edge, level_offsets.HELD, level_offsets.FREE)
    p.x_seed[:] = p.x
    p.y_seed[:] = p.y
    return matched
