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
   (``FloodModel.interactions(settle=True)``);
6. seeds of still water by walls are settled and their masses matched to the seeded depth
   (``floodsph.model.wall_seeds``); ``model.volume_seed_adjustment`` [m3] is the change; under
   the balanced momentum instead, every particle seeded at rest is given the level offset
   that makes its level its seeded level (``floodsph.sph.level_offsets``);
7. the first time step dt = cfl min h / (|v| + c).
"""

from __future__ import annotations

from collections.abc import Iterable

from floodsph.boundaries.open_edges import SIDES as OPEN_SIDES
from floodsph.boundaries.open_edges import OpenEdges
from floodsph.constants import RHO_WATER
from floodsph.model.flood_model import FloodModel
from floodsph.model.particles import ParticleSet
from floodsph.model.terrain import Terrain
from floodsph.model.wall_layout import model_segments
from floodsph.model.wall_seeds import settle_at_walls
from floodsph.scenario.numerics import Numerics
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
        The DEM cells that held water at seeding (``FloodModel``).
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
    model = FloodModel(terrain, particles, numerics, seg, closed, boundaries, refiner,
                       held)
    for boundary in model.boundaries:
        boundary.apply(model, 0.0)
    _seeds_off_walls(model, walled)
    model.remove_outside(nodata=not walled)
    rho_seed = model.particles.rho.copy()
    model.interactions(settle=True)
    if model.balanced:
        model.match_levels()
    else:
        model.volume_seed_adjustment = settle_at_walls(model, rho_seed)
    model.dt = model.stable_dt()
    return model


def _seeds_off_walls(model: FloodModel, walled: bool) -> None:
    """Move seeds off nodata and off wall lines (``settle_seeds``); those that cannot be moved
    are removed and counted as outflow."""
    p, t = model.particles, model.terrain
    spacing = model.numerics.particle_spacing_m
    assert spacing is not None  # set_up_model refuses a model without it
    x, y, lost = settle_seeds(p.x, p.y, t.valid, t.dx, t.dy, spacing,
                              model.seg if walled else None)
    p.x[:], p.y[:] = x, y
    if lost.any():
        model.volume_out += float(p.m[lost].sum() / RHO_WATER)
        p.keep(~lost)
