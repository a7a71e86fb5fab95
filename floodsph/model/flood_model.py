"""FloodModel: particles on a terrain, advanced one time step at a time.

The model knows how to take a step and nothing about files, schedules or output (those are
``floodsph.simulation.loop``'s). One step (kick-drift-kick leap-frog with a variable CFL step,
``docs/method.md`` §5):

1. kick   v^{n+1/2} = v^n + a^n dt / 2
2. drift  x^{n+1} = x^n + v^{n+1/2} dt; moves across walls are reflected; particles that
          leave an open border or enter nodata are removed and counted as outflow
3. density guess from continuity, neighbour lists, Newton-Raphson solve of rho and h
4. forces a^{n+1} at (x^{n+1}, v^{n+1/2}): pressure (renormalised where the lattice is
          distorted, ``floodsph.sph.consistency``) + shock capturing, balanced at shores
          (``floodsph.sph.shore``), + bed
5. kick   v^{n+1} = v^{n+1/2} + a^{n+1} dt / 2, then implicit Manning friction over dt
6. next dt = cfl min h / (|v| + c)

With ``Numerics.time_stepping = TimeStepping.LOCAL`` a call to :meth:`FloodModel.step` takes
one big step of 2^K such steps, in which each particle does steps 1-5 at its own power-of-two
multiple of the finest step (``floodsph.sph.local_steps``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.model.local_stepping import big_step
from floodsph.model.particles import ParticleSet
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Momentum, Numerics, Stabilisation, TimeStepping, WallModel
from floodsph.sph import bed as bedmod
from floodsph.sph import (
    consistency,
    density,
    forces,
    kernels,
    level_momentum,
    level_offsets,
    shadow,
    shore,
    time_step,
)
from floodsph.sph.cells import CellGrid
from floodsph.sph.neighbours import NeighbourList
from floodsph.sph.sums import SUMS
from floodsph.sph.velocity_gradient import velocity_gradient
from floodsph.walls import sight
from floodsph.walls.index import MapWalls, WallIndex, WallLists
from floodsph.walls.sight import SIGHT_SLACK

if TYPE_CHECKING:
    from floodsph.model.stage_timer import StageTimer
    from floodsph.simulation.flux import FluxLines

MAX_SEARCH_GROWTH = 2.0
"""Cap on the factor ``hgrow`` by which a particle's neighbour search is widened."""
SETTLE_ROUNDS = 30
"""Rounds of list building and density solve when the model is set up (h may grow 10-fold)."""


class FloodModel:
    """Shallow-water SPH particles on a terrain.

    The model steps; it is set up by ``floodsph.model.builder.set_up_model``, which makes the
    wall segments and the open edges, settles the seeds and solves the first density. Its
    arguments here are that set-up's results.

    Parameters
    ----------
    terrain : Terrain
    particles : ParticleSet
        The water particles (local coordinates).
    numerics : Numerics
        The solver's settings (``floodsph.scenario.numerics``), with ``particle_spacing_m``
        given.
    seg : (k, 4) array
        Wall segments (x0, y0, x1, y1) [m] that water cannot cross
        (``floodsph.model.wall_layout.model_segments``).
    closed_sides : frozenset of str
        The closed sides of the DEM rectangle (``floodsph.model.builder.set_up_model``); with
        any closed, the nodata border is a wall too.
    boundaries : sequence of floodsph.boundaries.protocol.Boundary
        Open boundaries (the open edges, inflows, sinks), each keeping that contract:
        ``apply`` after each drift (adding to ``volume_in`` / ``volume_out`` what they inject
        or remove), ``add_ghosts`` and ``impose`` around the density solve, ``protected``,
        ``max_dt`` and ``opening``.
    refiner : object or None
        Particle splitting and coalescing: ``apply(model) -> (splits, merges)``, called after
        the boundaries once the particles have moved (``floodsph.model.refinement``).
    held : (ny, nx) bool array or None
        The DEM cells that held water at seeding; with the nodata cells, the balanced
        momentum's still water does not take them for dry land beyond a free edge
        (``floodsph.sph.level_momentum``). None: the nodata cells only.

    Attributes
    ----------
    stage_timer : StageTimer or None
        Set it to a ``floodsph.model.stage_timer.StageTimer`` to have every step add the wall time
        of each of its stages there (None, the default: no timing).
    flux_lines : FluxLines or None
        ``floodsph.simulation.flux.FluxLines`` counting the water that crosses the scenario's
        flux lines (every move of a particle: :meth:`count_moves`), or None (the default).
    volume_out_other : float
        Outflow [m3] off the grid or into nodata cells that no open side or sink took
        (:meth:`remove_outside`).
    """

    STATE = ("t", "steps", "dt", "volume_in", "volume_out", "volume_out_other",
             "volume_seed_adjustment", "counters", "bed", "pair_sums", "blocked", "wdist",
             "eta", "ghost", "walled")
    """What a checkpoint holds of the model itself (``floodsph.simulation.state_arrays``): the
    clock, the volumes, the counters and the per-particle arrays the last step left (the
    sampled bed, the pair sums, the blocked pairs and wall distances, the levels and ghost
    depths, the walled flags), which the next step may read before it writes them. Its
    particles, lists, boundaries, refiner and flux lines declare their own
    (``floodsph.simulation.model_state``); the rest is made again from the scenario."""

    def __init__(self, terrain: Terrain, particles: ParticleSet, numerics: Numerics,
                 seg: np.ndarray, closed_sides: frozenset[str], boundaries,
                 refiner=None, held: np.ndarray | None = None):
        self.terrain = terrain
        self.boundaries = list(boundaries)
        self.refiner = refiner
        self.particles = particles
        self.numerics = numerics
        self.scheme = {Stabilisation.LAX_FRIEDRICHS: forces.LAX_FRIEDRICHS,
                       Stabilisation.RIEMANN: forces.RIEMANN,
                       Stabilisation.MUSCL: forces.MUSCL}[numerics.stabilisation]
        self.closed_sides = closed_sides
        self.seg = seg
        h0 = kernels.seeded_smoothing_length(numerics.kappa, numerics.particle_spacing_m)
        self.wall_index = WallIndex(
            self.seg, (0.0, 0.0, terrain.width, terrain.height), bucket=2.0 * h0)
        self.t = 0.0
        self.steps = 0
        self.volume_in = 0.0
        self.volume_out = 0.0
        self.volume_seed_adjustment = 0.0
        self.volume_out_other = 0.0
        self.stage_timer: StageTimer | None = None
        self.flux_lines: FluxLines | None = None
        self.counters = {"splits": 0, "merges": 0, "particles_max": particles.n,
                         "wall_reflections": 0, "density_unconverged": 0,
                         "density_capped": 0, "density_held": 0, "particle_updates": 0,
                         "seeds_settled": 0, "settle_steps": 0, "neighbour_builds": 0}
        self.bed = np.empty((0, bedmod.BED_COLUMNS))
        self.pair_sums = np.empty((0, SUMS))
        self.shores = bool(np.ptp(terrain.elevation) > 0.0)  # a flat bed has no shore to balance
        self.blocked = np.empty(0, dtype=np.bool_)
        self.wdist = np.empty(0)
        self.integral_walls = numerics.wall_model is WallModel.INTEGRAL
        self.balanced = numerics.momentum is Momentum.BALANCED
        self.held = np.ascontiguousarray(~terrain.valid if held is None else held | ~terrain.valid,
                                         dtype=np.uint8)
        self.eta = np.empty(0)  # the particles' levels under the balanced momentum [m]
        self.ghost = np.empty(0)  # and their dry ghosts' depths [m] (0: no free edge)
        self._no_images = (None,)  # the integral walls' image-free lists, per list build
        self.walled = np.zeros(0, dtype=np.bool_)
        self._blocked_nl = None
        self.lists_fresh = False  # lists built in this step (or local substep)
        self._nl_here = False  # lists built at the current positions
        self.nl: NeighbourList | None = None
        self.dt = np.inf

    def __repr__(self) -> str:
        return (f"FloodModel(t={self.t:.3f} s, steps={self.steps}, particles={self.particles.n}, "
                f"walls={self.seg.shape[0]} segments, closed_sides={sorted(self.closed_sides)})")

    # -- state -----------------------------------------------------------------------------
    def depth(self) -> np.ndarray:
        """Depth [m] of the active particles: d = rho / rho_w, and under the balanced momentum
        d + o, its level less the bed (``floodsph.sph.level_offsets``)."""
        p = self.particles
        if self.balanced:
            return p.rho / RHO_WATER + p.eta_offset
        return p.rho / RHO_WATER

    def surface_levels(self) -> np.ndarray | None:
        """The free-surface levels eta = d + b + o [m] of the particles under the balanced
        momentum (``floodsph.sph.level_offsets``), which the maps and gauges report depth
        from; None under the variational momentum (they report the summed depth)."""
        if not self.balanced:
            return None
        p = self.particles
        t = self.terrain
        eta = np.empty(p.n)
        level_offsets.levels(p.x, p.y, p.rho, p.eta_offset, t.elevation, t.dx, t.dy, eta)
        return eta

    def volume(self) -> float:
        """Water volume in the domain, sum m / rho_w [m3]."""
        return self.particles.volume()

    def stable_dt(self) -> float:
        """dt = cfl min h / (|v| + c) over the water and the open boundaries' buffers [s]."""
        p = self.particles
        dt = float(time_step.stable_dt(p.u, p.v, p.rho, p.h, self.numerics.cfl)) if p.n else np.inf
        return self._boundaries_dt(dt)

    def _boundaries_dt(self, dt: float) -> float:
        """The water's CFL step dt [s], shortened to what the open boundaries allow."""
        for boundary in self.boundaries:
            dt = min(dt, boundary.max_dt(self.numerics.cfl))
        return dt

    # -- one step ------------------------------------------------------------------------------
    def step(self, dt_max: float | None = None) -> float:
        """Advance one time step (at most ``dt_max``); return the step taken [s].

        With local time stepping the step is a big step of up to 2^K finest steps
        (``floodsph.model.local_stepping.big_step``), at the end of which every particle is
        synchronised.
        """
        timer = self.stage_timer
        if timer is not None:
            timer.begin()
        self.lists_fresh = False
        self._nl_here = False
        if self.nl is None:  # particles were added or removed between steps
            self.update_lists()
        if self.numerics.time_stepping is TimeStepping.LOCAL:
            dt = big_step(self, dt_max)
            if timer is not None:
                timer.end()
            return dt
        p = self.particles
        dt = self.dt if dt_max is None else min(self.dt, dt_max)
        half = 0.5 * dt
        time_step.kick(p.u, p.v, p.ax, p.ay, half)
        self.move(dt)
        self.synchronise()
        self.interactions()
        num = self.numerics
        dt_water = time_step.close_step(p.u, p.v, p.ax, p.ay, half, p.rho, p.h,
                                     self.bed[: p.n, bedmod.MANNING], dt,
                                     num.friction_depth_floor_m, num.cfl)
        self.advance_clock(dt)
        self.dt = self._boundaries_dt(float(dt_water))
        if timer is not None:
            timer.end()
        return dt

    def move(self, dt: float) -> None:
        """Drift every particle by dt (walls reflect), let the open boundaries act, drop what
        left the domain, and advance density and h by the continuity guess. Under the balanced
        momentum the level offsets of moving water fade with the distance travelled, and still
        water held by its banks is damped and tethered (``floodsph.sph.level_offsets``)."""
        p = self.particles
        if self.balanced:
            level_offsets.decay_offsets(p.u, p.v, p.h, dt, p.bank_held, p.eta_offset)
            level_offsets.hold_still(p.u, p.v, p.x, p.y, p.x_seed, p.y_seed, p.bank_held, dt,
                                     level_momentum.HOLD_TIME, level_momentum.HOLD_STIFFNESS)
        moves = None if self.flux_lines is None else (p.x.copy(), p.y.copy())
        self.counters["wall_reflections"] += self.wall_index.drift(p.x, p.y, p.u, p.v, dt)
        if moves is not None:
            self.count_moves(*moves, p.x, p.y, p.m)
        self._nl_here = False
        self._lap("kick_drift")
        for boundary in self.boundaries:
            boundary.apply(self, dt)
        self.remove_outside(nodata=not self.closed_sides)
        self._lap("boundaries")
        density.predict(p.rho, p.h, p.divv, dt)
        self._lap("density")

    def count_moves(self, x0, y0, x1, y1, m) -> None:
        """Water of mass ``m`` [kg] moved from (x0, y0) to (x1, y1) [m]: the flux lines count
        what crossed them (``floodsph.simulation.flux``; nothing without flux lines)."""
        if self.flux_lines is not None:
            self.flux_lines.count(x0, y0, x1, y1, m)

    def synchronise(self, steps_taken: int = 1) -> None:
        """Refinement, and the periodic re-sort, on synchronised particles; ``steps_taken``
        finest steps end here (the re-sort is due when they cross a multiple of its interval)."""
        if self.refiner is not None:
            splits, merges = self.refiner.apply(self)
            self.counters["splits"] += splits
            self.counters["merges"] += merges
        every = self.numerics.reorder_interval
        if every and self.steps // every != (self.steps - steps_taken) // every:
            self._reorder()
        self._lap("refinement")

    def _lap(self, stage: str) -> None:
        """Mark the end of a stage of the step for the stage timer, if one is set."""
        if self.stage_timer is not None:
            self.stage_timer.lap(stage)

    def advance_clock(self, dt: float, updated: int | None = None) -> None:
        """t += dt, one more finest step, and the counters of particles and updates."""
        p = self.particles
        self.t += dt
        self.steps += 1
        self.counters["particles_max"] = max(self.counters["particles_max"], p.n)
        self.counters["particle_updates"] += p.n if updated is None else updated

    def particles_changed(self) -> None:
        """Say that particles were added or removed outside the step (a refinement, a
        boundary): the neighbour and near-wall lists are stale, and the next step rebuilds
        them."""
        self.nl = None

    def map_walls(self) -> MapWalls:
        """The walls as the maps see them (``floodsph.output.rasterise``): each particle's
        segments within its support 2 h_i (and the sight test's slack)."""
        p = self.particles
        near = self.wall_index.near_lists(p.x, p.y, p.h + SIGHT_SLACK,
                                          np.zeros(p.n + 1, dtype=np.int64),
                                          np.zeros(0, dtype=np.int64), 2.0)
        return MapWalls(self.seg, near.wstart, near.wseg)

    def protected(self, x, y, h) -> np.ndarray:
        """True for points (x, y) [m] with a wall segment within the kernel reach of h [m]
        (with the neighbour lists' skin), or in an open boundary's zone: no merging there."""
        n = x.shape[0]
        reach = 2.0 * (1.0 + self.numerics.neighbour_skin)
        wstart = self.wall_index.near_lists(x, y, h, np.zeros(n + 1, dtype=np.int64),
                                            np.zeros(0, dtype=np.int64), reach).wstart
        mask = np.diff(wstart) > 0
        for boundary in self.boundaries:
            mask |= boundary.protected(x, y)
        return mask

    # -- stages --------------------------------------------------------------------------------
    def interactions(self, settle: bool = False, rows: np.ndarray | None = None) -> None:
        """Neighbours, density and forces of the water, with the boundaries' ghosts present.

        The ghosts (inflow buffers, mirror images beyond open edges) are appended behind the
        water, given the boundary state after the density solve, and dropped after the forces.
        ``settle`` is for the set-up (:meth:`_solve_density`). ``rows``: update only these
        water particles (and the ghosts), with lists built for them alone (local stepping).
        """
        p = self.particles
        water = p.mark()
        for boundary in self.boundaries:
            boundary.add_ghosts(self)
        self._lap("boundaries")
        if rows is None:
            self.update_lists()
        else:
            ghosts = np.arange(water[0], p.n, dtype=np.int64)
            self.update_lists(force=True, rows=np.concatenate([rows, ghosts]))
        self._solve_density(settle)
        self._lap("density")
        for boundary in self.boundaries:
            boundary.impose(self)
        self._lap("boundaries")
        self.evaluate_forces()
        self._lap("forces")
        p.truncate(water)

    def remove_outside(self, nodata: bool) -> None:
        """Remove (and count as outflow) particles off the grid, and in nodata cells if
        ``nodata``, i.e. when nodata is not walled off (the walled nodata border runs through
        nodata cells, whose slivers are then wet area)."""
        p = self.particles
        inside = self.terrain.covers(p.x, p.y, valid_only=nodata)
        if not inside.all():
            volume = float(p.m[~inside].sum() / RHO_WATER)
            self.volume_out += volume
            self.volume_out_other += volume
            p.keep(inside)

    def _reorder(self) -> None:
        """Sort particles by cell so that neighbours are close in memory."""
        p = self.particles
        if p.n:
            p.permute(CellGrid(p.x, p.y, 2.0 * float(np.mean(p.h))).order)
            self.nl = None

    def update_lists(self, force: bool = False, rows: np.ndarray | None = None) -> None:
        """Neighbour and near-wall lists, rebuilt when the Verlet skin is used up (or ``force``).

        The lists are built for h_i times the growth of h_i in the last density solve
        (``hgrow``, at most ``MAX_SEARCH_GROWTH``), so that a particle whose h keeps growing
        in the solves (a thinning edge) is not held back by its lists step after step
        (:meth:`_solve_density`). ``rows``: list only these particles' neighbours and near
        walls (the drift finds its walls in the wall index).
        """
        p = self.particles
        nl = self.nl
        if not force and nl is not None and nl.still_valid(p.x, p.y, p.h):
            self._lap("neighbours")
            return
        self.lists_fresh = True
        self.counters["neighbour_builds"] += 1
        self._nl_here = True  # built at the current positions (until the next drift)
        h_search = p.h * np.clip(p.hgrow, 1.0, MAX_SEARCH_GROWTH)
        self.nl = NeighbourList(p.x, p.y, h_search, skin=self.numerics.neighbour_skin,
                                rows=rows)
        self.walls_near = self.wall_index.near_lists(p.x, p.y, h_search, self.nl.start,
                                                     self.nl.nbr, self.nl.reach, rows)
        self._lap("neighbours")

    def block_pairs(self) -> None:
        """Flag the listed pairs that a wall separates, and measure the distances to the near
        segments, at the current positions."""
        p = self.particles
        self._blocked_nl = self.nl
        if self.blocked.shape[0] != self.nl.nbr.shape[0]:
            self.blocked = np.empty(self.nl.nbr.shape[0], dtype=np.bool_)
        near = self.walls_near
        if self.wdist.shape[0] != near.wseg.shape[0]:
            self.wdist = np.empty(near.wseg.shape[0])
        sight.blocked_pairs(self.nl.rows, p.x, p.y, self.nl.start, self.nl.nbr,
                              near.wstart, near.wseg, self.seg, self.blocked, self.wdist)

    def wall_lists(self) -> WallLists:
        """The walls as the density and force kernels take them: with ``wall_model =
        "integral"`` no segment makes images (its distance infinite, no corners), and the
        walls act through ``floodsph.sph.shadow``."""
        wstart, wseg, cstart, cpair = self.walls_near
        if not self.integral_walls:
            return WallLists(self.seg, self.wdist, wstart, wseg, cstart, cpair)
        if self._no_images[0] is not self.walls_near:  # once per build of the lists
            self._no_images = (self.walls_near, WallLists(
                self.seg, np.full(wseg.shape[0], np.inf), wstart, wseg, np.zeros_like(cstart),
                cpair[:0]))
        return self._no_images[1]

    def _solve_density(self, settle: bool = False) -> None:
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
        num = self.numerics
        p = self.particles
        h_predicted = p.h.copy()
        releasing = self.balanced and bool((p.bank_held == level_offsets.RELEASED).any())
        rho_predicted = p.rho.copy() if releasing else None
        held = ((p.bank_held == level_offsets.HELD) | (p.bank_held == level_offsets.BANKED)
                if self.balanced else None)
        for _ in range(SETTLE_ROUNDS if settle else 2):
            self.block_pairs()
            outcome = density.solve_density(
                p, self.nl, self.blocked, self.wall_lists(),
                tol=num.density_tol, max_iter=num.density_max_iter, h_ratio=num.h_ratio,
                cap=not settle, integral=self.integral_walls, unmoved=self._nl_here,
                skip=held)
            if settle and self.nl.covers(p.x, p.y, p.h):
                break
            if not settle and (outcome.capped == 0 or self.lists_fresh):
                break
            self._lap("density")
            self.update_lists(force=True, rows=None if self.nl.complete else self.nl.rows)
        rows = self.nl.rows
        if self.nl.complete:
            p.hgrow[:] = p.h / h_predicted
        else:
            p.hgrow[rows] = p.h[rows] / h_predicted[rows]
        if rho_predicted is not None:
            level_offsets.release(p.bank_held, rho_predicted, p.rho, p.eta_offset)
        if self.balanced:
            level_offsets.floor_offsets(p.rho, p.bank_held, p.eta_offset)
        self.counters["density_unconverged"] += outcome.unconverged
        self.counters["density_capped"] += outcome.capped
        self.counters["density_held"] += outcome.held

    def evaluate_forces(self) -> None:
        p = self.particles
        t = self.terrain
        if self.bed.shape[0] != p.n:
            self.bed = np.empty((p.n, bedmod.BED_COLUMNS))
            self.pair_sums = np.empty((p.n, SUMS))
        rows = self.nl.rows
        bedmod.sample_bed(rows, p.x, p.y, t.dx, t.dy, *t.bed_grids(), self.bed)
        if self._blocked_nl is not self.nl:  # the density loop rebuilt the lists last
            self.block_pairs()
        if not self.balanced:
            self._variational_forces(rows)
            return
        if self.eta.shape[0] != p.n:
            self.eta = np.empty(p.n)
            self.ghost = np.zeros(p.n)
        level_offsets.levels(p.x, p.y, p.rho, p.eta_offset, t.elevation, t.dx, t.dy, self.eta)
        self._release(rows)
        weight = level_momentum.variational_weight(p.u[rows], p.v[rows])
        moving = rows[weight > 0.0]
        if moving.size:
            self._variational_forces(moving)
            a_var = np.stack([p.ax[moving], p.ay[moving], p.divv[moving]])
        slow = rows[weight < 1.0]
        if slow.size:
            self._balanced_forces(slow)
        if moving.size:
            w = weight[weight > 0.0]
            for field, value in zip((p.ax, p.ay, p.divv), a_var, strict=True):
                field[moving] = w * value + (1.0 - w) * field[moving]

    def _variational_forces(self, rows: np.ndarray) -> None:
        """The variational momentum's accelerations of the particles ``rows``
        (``floodsph.sph.forces``, renormalised by ``floodsph.sph.consistency``, balanced at
        shores by ``floodsph.sph.shore``, and the bed)."""
        p = self.particles
        t = self.terrain
        if self.scheme == forces.MUSCL:
            velocity_gradient(rows, p.x, p.y, p.u, p.v, p.m, p.rho, p.h, self.nl.start,
                              self.nl.nbr, self.blocked, p.dudx, p.dudy, p.dvdx, p.dvdy)
        forces.internal_acceleration(rows, p.x, p.y, p.u, p.v, p.m, p.rho, p.alpha, p.h, p.kxx,
                                     p.kxy, p.kyy, p.dudx, p.dudy, p.dvdx, p.dvdy, self.nl.start,
                                     self.nl.nbr, self.blocked, self.wall_lists(), self.scheme,
                                     self.pair_sums, p.ax, p.ay, p.divv)
        consistency.update_renormalisation(rows, p.h, self.pair_sums, self.shores, p.kxx, p.kxy,
                                           p.kyy)
        if self.walled.shape[0] != p.n:
            self.walled = np.zeros(p.n, dtype=np.bool_)
        if self.integral_walls:
            shadow.balance_walls(rows, p.x, p.y, p.rho, p.h, self.walls_near.wstart,
                                 self.walls_near.wseg, self.seg, self.pair_sums, p.ax, p.ay,
                                 self.walled)
        if self.shores:
            shore.balance_shores(rows, p.x, p.y, p.u, p.v, p.rho, p.h, self.bed, t.dx, t.dy,
                                 t.elevation, self.pair_sums, self.walled, p.ax, p.ay)
        forces.add_bed_acceleration(rows, p.u, p.v, self.bed, self.numerics.max_slope, p.ax,
                                    p.ay, GRAVITY, 0.0)

    def _balanced_forces(self, rows: np.ndarray) -> None:
        """The balanced momentum's accelerations of the particles ``rows``
        (``floodsph.sph.level_momentum``), on the levels of all particles (``self.eta``)."""
        p = self.particles
        t = self.terrain
        level_momentum.balanced_acceleration(rows, p.x, p.y, p.u, p.v, p.m, p.rho, p.alpha, p.h,
                                             self.eta, self.bed, self.nl.start, self.nl.nbr,
                                             self.blocked, self.wall_lists(), t.elevation,
                                             self.held, p.bank_held, t.dx, t.dy, p.ax, p.ay,
                                             p.divv, self.ghost)
        forces.add_bed_acceleration(rows, p.u, p.v, self.bed, self.numerics.max_slope, p.ax,
                                    p.ay, 0.0, -GRAVITY)

    def _release(self, rows: np.ndarray) -> None:
        """Among ``rows``, bank the still water held by its banks whose level ``self.eta``
        departs from its seeded level by ``HOLD_LEVEL``, and release the held or banked water
        that moves at ``EDGE_SPEED`` (``floodsph.sph.level_momentum``,
        ``floodsph.sph.level_offsets``)."""
        p = self.particles
        state = p.bank_held[rows]
        fast = p.u[rows] ** 2 + p.v[rows] ** 2 >= level_momentum.EDGE_SPEED ** 2
        departed = np.abs(self.eta[rows] - p.eta_seed[rows]) >= level_momentum.HOLD_LEVEL
        p.bank_held[rows[(state == level_offsets.HELD) & departed]] = level_offsets.BANKED
        kept = (state == level_offsets.HELD) | (state == level_offsets.BANKED)
        p.bank_held[rows[kept & fast]] = level_offsets.RELEASED

    def match_levels(self) -> int:
        """Give every particle seeded at rest the level offset that makes its level its seeded
        level (``floodsph.sph.level_offsets.match_offsets``), evaluate the forces again, and
        mark as held by its banks each particle seeded at rest that has no free edge then
        (``ParticleSet.bank_held``, ``floodsph.sph.level_momentum``); returns the number
        matched. For the set-up, under the balanced momentum."""
        p = self.particles
        t = self.terrain
        bed = np.empty(p.n)
        level_offsets.levels(p.x, p.y, np.zeros(p.n), np.zeros(p.n), t.elevation, t.dx, t.dy,
                             bed)
        matched = level_offsets.match_offsets(p.eta_seed, p.rho, bed, p.eta_offset)
        p.bank_held[:] = level_offsets.FREE
        self.interactions()
        free_edge = np.zeros(p.n, dtype=bool)
        evaluated = min(p.n, self.ghost.shape[0])  # no ghost array when all water moves
        free_edge[:evaluated] = self.ghost[:evaluated] > 0.0
        at_rest = np.isfinite(p.eta_seed) & (p.u == 0.0) & (p.v == 0.0)
        p.bank_held[:] = np.where(at_rest & ~free_edge, level_offsets.HELD, level_offsets.FREE)
        p.x_seed[:] = p.x
        p.y_seed[:] = p.y
        return matched
