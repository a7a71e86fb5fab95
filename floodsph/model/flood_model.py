"""FloodModel: particles on a terrain, advanced one time step at a time.

The model knows how to take a step and nothing about files, schedules or output (those are
``floodsph.simulation.loop``'s). One step (kick-drift-kick leap-frog with a variable CFL step,
method notes 2.6-2.7):

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

import math

import numpy as np

from floodsph.boundaries.open_edges import SIDES as OPEN_SIDES
from floodsph.boundaries.open_edges import OpenEdges
from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.model.particles import ParticleSet
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Numerics, Stabilisation, TimeStepping, WallModel
from floodsph.sph import bed as bedmod
from floodsph.sph import consistency, density, forces, local_steps, shore
from floodsph.sph.neighbours import CellGrid, NeighbourList
from floodsph.walls import seeding as wall_seeding
from floodsph.walls import shadow, sight
from floodsph.walls.index import WallIndex
from floodsph.walls.layout import model_segments
from floodsph.walls.nodata import settle_seeds

MAX_SEARCH_GROWTH = 2.0
"""Cap on the factor ``hgrow`` by which a particle's neighbour search is widened."""
SETTLE_ROUNDS = 30
"""Rounds of list building and density solve when the model is set up (h may grow 10-fold)."""


class FloodModel:
    """Shallow-water SPH particles on a terrain.

    Parameters
    ----------
    terrain : Terrain
    particles : ParticleSet
        Seeded particles (local coordinates) with m, rho = rho_w d and h = kappa dx set; their
        density and smoothing length are solved on construction. Seeds of still water next to
        walls are also settled there, and their masses matched to the seeded depth
        (``floodsph.walls.seeding``): the set is changed in place, and
        ``volume_seed_adjustment`` [m3] is the volume change.
    numerics : Numerics
        The solver's settings (``floodsph.scenario.numerics``), with ``particle_spacing_m`` given.
    walls : sequence of (k, 2) arrays
        Polylines in local coordinates that water cannot cross.
    closed_edges : bool or collection of str
        True: the DEM border and nodata areas are walls. False: water reaching them leaves the
        model and is counted in ``volume_out``; the open sides get transmissive ghosts
        (``floodsph.boundaries.OpenEdges``). A collection of sides (``"west"``, ``"east"``,
        ``"south"``, ``"north"``) closes those sides and opens the others; nodata borders
        are then walls.
    boundaries : sequence of floodsph.boundaries.protocol.Boundary
        Open boundaries (inflows, sinks), each keeping that contract: ``apply`` after each
        drift (adding to ``volume_in`` / ``volume_out`` what they inject or remove),
        ``add_ghosts`` and ``impose`` around the density solve, ``protected``, ``max_dt`` and
        ``opening``.
    refiner : object or None
        Particle splitting and coalescing: ``apply(model) -> (splits, merges)``, called after
        the boundaries once the particles have moved (``floodsph.model.refinement``).

    Attributes
    ----------
    stage_timer : StageTimer or None
        Set it to a ``floodsph.model.stage_timer.StageTimer`` to have every step add the wall time
        of each of its stages there (None, the default: no timing).
    """

    stage_timer = None  # a class default, so that models pickled before it existed load

    def __init__(self, terrain: Terrain, particles: ParticleSet, numerics: Numerics,
                 walls=(), closed_edges: bool = True, boundaries=(), refiner=None):
        if numerics.particle_spacing_m is None:
            raise ValueError("FloodModel: numerics.particle_spacing_m must be given (the "
                             "scenario's default, the DEM cell size, is filled in by "
                             "floodsph.run.pipeline.build_model)")
        self.terrain = terrain
        self.boundaries = list(boundaries)
        self.refiner = refiner
        self.particles = particles
        self.numerics = numerics
        self.scheme = {Stabilisation.LAX_FRIEDRICHS: forces.LAX_FRIEDRICHS,
                       Stabilisation.RIEMANN: forces.RIEMANN}[numerics.stabilisation]
        closed = set(OPEN_SIDES) if closed_edges is True else set(closed_edges or ())
        unknown = closed - set(OPEN_SIDES)
        if unknown:
            raise ValueError(f"closed_edges: unknown sides {sorted(unknown)}; use {OPEN_SIDES}")
        self.closed_edges = closed_edges
        open_sides = [side for side in OPEN_SIDES if side not in closed]
        if open_sides:
            self.boundaries.insert(0, OpenEdges(terrain.width, terrain.height, open_sides))
        h0 = numerics.kappa * numerics.particle_spacing_m
        openings = [b.opening for b in self.boundaries if b.opening is not None]
        self.seg = model_segments(terrain, walls, closed, closed_edges is not False, openings,
                                  h0, numerics.particle_spacing_m)
        self.wall_index = WallIndex(
            self.seg, (0.0, 0.0, terrain.width, terrain.height), bucket=2.0 * h0)
        self.t = 0.0
        self.steps = 0
        self.volume_in = 0.0
        self.volume_out = 0.0
        self.counters = {"splits": 0, "merges": 0, "particles_max": particles.n,
                         "wall_reflections": 0, "density_unconverged": 0,
                         "density_capped": 0, "density_held": 0, "particle_updates": 0,
                         "seeds_settled": 0, "settle_steps": 0, "neighbour_builds": 0}
        self.bed = np.empty((0, 7))
        self.pair_sums = np.empty((0, forces.SUMS))
        self.shores = bool(np.ptp(terrain.elevation) > 0.0)  # a flat bed has no shore to balance
        self.blocked = np.empty(0, dtype=np.bool_)
        self.wdist = np.empty(0)
        self.integral_walls = numerics.wall_model is WallModel.INTEGRAL
        self._no_images = (None,)  # the integral walls' image-free lists, per list build
        self.walled = np.zeros(0, dtype=np.bool_)
        self._blocked_nl = None
        self._nl_fresh = False  # lists built in this step
        self._nl_here = False  # lists built at the current positions
        for boundary in self.boundaries:
            boundary.apply(self, 0.0)
        self._settle_seeds()
        self._remove_outside(nodata=closed_edges is False)
        rho_seed = self.particles.rho.copy()
        self._interactions(settle=True)
        self.volume_seed_adjustment = self._settle_at_walls(rho_seed)
        self.dt = self.stable_dt()

    def __repr__(self) -> str:
        return (f"FloodModel(t={self.t:.3f} s, steps={self.steps}, particles={self.particles.n}, "
                f"walls={self.seg.shape[0]} segments, closed_edges={self.closed_edges})")

    # -- state -----------------------------------------------------------------------------
    def depth(self) -> np.ndarray:
        """Depth d = rho / rho_w [m] of the active particles."""
        return self.particles.rho / RHO_WATER

    def volume(self) -> float:
        """Water volume in the domain, sum m / rho_w [m3]."""
        return self.particles.volume()

    def stable_dt(self) -> float:
        """dt = cfl min h / (|v| + c) over the water and the open boundaries' buffers [s]."""
        p = self.particles
        dt = float(forces.stable_dt(p.u, p.v, p.rho, p.h, self.numerics.cfl)) if p.n else np.inf
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
        (:meth:`_step_local`), at the end of which every particle is synchronised.
        """
        timer = self.stage_timer
        if timer is not None:
            timer.begin()
        self._nl_fresh = False
        self._nl_here = False
        if getattr(self, "nl", None) is None:  # particles were added or removed between steps
            self._neighbours()
        if self.numerics.time_stepping is TimeStepping.LOCAL:
            dt = self._step_local(dt_max)
            if timer is not None:
                timer.end()
            return dt
        p = self.particles
        dt = self.dt if dt_max is None else min(self.dt, dt_max)
        half = 0.5 * dt
        forces.kick(p.u, p.v, p.ax, p.ay, half)
        self._move(dt)
        self._synchronise()
        self._interactions()
        num = self.numerics
        dt_water = forces.close_step(p.u, p.v, p.ax, p.ay, half, p.rho, p.h, self.bed[: p.n, 6],
                                     dt, num.friction_depth_floor_m, num.cfl)
        self._advance_clock(dt)
        self.dt = self._boundaries_dt(float(dt_water))
        if timer is not None:
            timer.end()
        return dt

    def _step_local(self, dt_max: float | None) -> float:
        """One big step of 2^k finest steps dt_f = ``self.dt``, k <= ``step_levels`` (fewer
        when ``dt_max`` is shorter), each particle at its own stride (module docstring of
        ``floodsph.sph.local_steps``); a single step of ``dt_max`` if that is below dt_f."""
        p = self.particles
        dt_f = self.dt if dt_max is None else min(self.dt, dt_max)
        levels = self.numerics.step_levels
        if dt_max is not None:
            levels = min(levels, int(math.floor(math.log2(dt_max / dt_f) + 1e-12)))
        n_sub = 2 ** levels
        stride = np.empty(p.n, dtype=np.int64)
        local_steps.strides(p.u, p.v, p.rho, p.h, self.numerics.cfl, dt_f, n_sub, stride)
        local_steps.limit_strides(stride, self.nl.start, self.nl.nbr, p.n, p.stride)
        zone = np.zeros(p.n, dtype=bool)
        for boundary in self.boundaries:
            zone |= boundary.protected(p.x, p.y)
        p.stride[zone] = 1
        half = 0.5 * dt_f
        end = np.arange(p.n, dtype=np.int64)  # every particle's step begins at finest step 0
        for sub in range(n_sub):
            self._nl_fresh = False
            # the steps that end at finest step sub begin anew: no particle has been added or
            # removed since (the boundaries do that in the drift, and refinement at the end)
            begin = end
            local_steps.kick(begin, p.stride, half, p.u, p.v, p.ax, p.ay)
            self._move(dt_f)
            p.stride[p.stride == 0] = 1  # water that entered in this substep: finest stride
            last = sub == n_sub - 1
            if last:
                self._synchronise(n_sub)  # new particles inherit their parents' strides
            end = None if last else local_steps.step_ends(p.stride, sub + 1)
            self._interactions(rows=end)
            end = np.arange(p.n, dtype=np.int64) if end is None else end
            local_steps.close_steps(end, p.stride, dt_f, p.u, p.v, p.ax, p.ay, p.rho,
                                    self.bed[:, 6], self.numerics.friction_depth_floor_m)
            self._advance_clock(dt_f, end.size)
        self.dt = self.stable_dt()
        return n_sub * dt_f

    def _move(self, dt: float) -> None:
        """Drift every particle by dt (walls reflect), let the open boundaries act, drop what
        left the domain, and advance density and h by the continuity guess."""
        p = self.particles
        self.counters["wall_reflections"] += int(sight.drift(
            p.x, p.y, p.u, p.v, dt, *self.walls_near[:2], self.seg))
        self._nl_here = False
        self._lap("kick_drift")
        for boundary in self.boundaries:
            boundary.apply(self, dt)
        self._remove_outside(nodata=self.closed_edges is False)
        self._lap("boundaries")
        density.predict(p.rho, p.h, p.divv, dt)
        self._lap("density")

    def _synchronise(self, steps_taken: int = 1) -> None:
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

    def _advance_clock(self, dt: float, updated: int | None = None) -> None:
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

    def protected(self, x, y, h) -> np.ndarray:
        """True for points (x, y) [m] with a wall segment within the kernel reach of h [m]
        (with the neighbour lists' skin), or in an open boundary's zone: no merging there."""
        n = x.shape[0]
        reach = 2.0 * (1.0 + self.numerics.neighbour_skin)
        wstart = self.wall_index.near_lists(x, y, h, np.zeros(n + 1, dtype=np.int64),
                                            np.zeros(0, dtype=np.int64), reach)[0]
        mask = np.diff(wstart) > 0
        for boundary in self.boundaries:
            mask |= boundary.protected(x, y)
        return mask

    # -- stages --------------------------------------------------------------------------------
    def _interactions(self, settle: bool = False, rows: np.ndarray | None = None) -> None:
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
            self._neighbours()
        else:
            ghosts = np.arange(water[0], p.n, dtype=np.int64)
            self._neighbours(force=True, rows=np.concatenate([rows, ghosts]))
        self._solve_density(settle)
        self._lap("density")
        for boundary in self.boundaries:
            boundary.impose(self)
        self._lap("boundaries")
        self._forces()
        self._lap("forces")
        p.truncate(water)

    def _settle_seeds(self) -> None:
        """Move seeds off nodata and off wall lines (``settle_seeds``); those that cannot be
        moved are removed and counted as outflow."""
        p, t = self.particles, self.terrain
        walled = self.closed_edges is not False
        x, y, lost = settle_seeds(p.x, p.y, t.valid, t.dx, t.dy,
                                  self.numerics.particle_spacing_m, self.seg if walled else None)
        p.x[:], p.y[:] = x, y
        if lost.any():
            self.volume_out += float(p.m[lost].sum() / RHO_WATER)
            p.keep(~lost)

    def _settle_at_walls(self, rho_seed: np.ndarray) -> float:
        """Settle the seeds of still water next to walls, then match their depth to the seeded
        rho_seed / rho_w (``floodsph.walls.seeding``); return the volume change [m3]."""
        idx = self._wall_seeds(rho_seed)
        self.counters["seeds_settled"] = int(idx.size)
        if idx.size == 0:
            return 0.0
        rows = wall_seeding.neighbourhood(idx, self.nl.start, self.nl.nbr, self.particles.n,
                                          wall_seeding.RINGS)
        rounds = self._settle(idx, rows)
        v0 = self.particles.volume()
        rounds += self._match_masses(idx, rho_seed[idx], rows)
        if rounds:  # lists and sums of every particle again, for the first step
            self._interactions(settle=True)
        return self.particles.volume() - v0

    def _wall_seeds(self, rho_seed: np.ndarray) -> np.ndarray:
        """Indices of the lattice seeds (m = rho_seed spacing^2) near a wall, out of open
        boundaries' zones, in still water (``wall_seeding.still_water``) and enclosed within
        ``wall_seeding.ENCLOSURE`` h (``wall_seeding.enclosed_seeds``)."""
        p = self.particles
        dx = self.numerics.particle_spacing_m
        n = p.n
        candidate = np.abs(p.m - rho_seed * dx * dx) <= 1e-9 * p.m
        candidate &= np.diff(self.walls_near[0][:n + 1]) > 0
        for boundary in self.boundaries:
            candidate &= ~boundary.protected(p.x, p.y)
        everyone = np.arange(n, dtype=np.int64)
        still = np.empty(n, dtype=np.bool_)
        wall_seeding.still_water(everyone, self.nl.start, self.nl.nbr, n, p.u, p.v,
                                 self.bed[:n, 0], rho_seed / RHO_WATER,
                                 wall_seeding.LEVEL_TOLERANCE, still)
        rows = np.flatnonzero(candidate)
        calm = np.empty(rows.size, dtype=np.bool_)
        wall_seeding.with_neighbours(rows, self.nl.start, self.nl.nbr, n, still, calm)
        rows = rows[calm]
        wstart, wseg = self.wall_index.near_lists(p.x, p.y, p.h, np.zeros(n + 1, dtype=np.int64),
                                                  np.zeros(0, dtype=np.int64),
                                                  wall_seeding.ENCLOSURE)[:2]
        return wall_seeding.enclosed_seeds(p.x, p.y, wall_seeding.ENCLOSURE * p.h, rows,
                                           dx, wstart, wseg, self.seg)

    def _settle(self, idx: np.ndarray, rows: np.ndarray) -> int:
        """Move the particles ``idx`` by a dt^2 / 2 per round, along their acceleration (walls
        reflecting), with dt the model's CFL step, each at most ``wall_seeding.MAX_SHIFT``
        spacings in all from its seed, the others held, until |a| < ``wall_seeding.SETTLED`` g
        or for ``wall_seeding.SETTLE_STEPS`` rounds. Each round solves density and forces
        for ``rows`` alone: ``idx`` and every particle whose density they may change. Returns
        the number of rounds."""
        p = self.particles
        x0, y0 = p.x[idx].copy(), p.y[idx].copy()
        mx, my = np.zeros(p.n), np.zeros(p.n)
        limit = wall_seeding.MAX_SHIFT * self.numerics.particle_spacing_m
        taken = 0
        while (taken < wall_seeding.SETTLE_STEPS
               and np.hypot(p.ax[idx], p.ay[idx]).max() >= wall_seeding.SETTLED * GRAVITY):
            mx[idx], my[idx] = wall_seeding.limited_move(p.ax[idx], p.ay[idx], self.stable_dt(),
                                                         p.x[idx] - x0, p.y[idx] - y0, limit)
            sight.drift(p.x, p.y, mx, my, 1.0, *self.walls_near[:2], self.seg)
            self._interactions(settle=True, rows=rows)
            taken += 1
        self.counters["settle_steps"] = taken
        return taken

    def _match_masses(self, idx: np.ndarray, rho_target: np.ndarray, rows: np.ndarray) -> int:
        """Jacobi iteration m_i <- m_i rho_target_i / rho_i on the particles ``idx``, each
        mass kept within [``MASS_MIN``, ``MASS_MAX``] times its start (``wall_seeding``);
        density and forces solved for ``rows`` alone (:meth:`_settle`). Returns the number of
        solves."""
        p = self.particles
        m0 = p.m[idx].copy()
        solves = 0
        while solves < wall_seeding.ROUNDS:
            ratio = rho_target / p.rho[idx]
            if np.abs(ratio - 1.0).max() < wall_seeding.TOLERANCE:
                break
            p.m[idx] = np.clip(p.m[idx] * ratio, wall_seeding.MASS_MIN * m0,
                               wall_seeding.MASS_MAX * m0)
            self._interactions(settle=True, rows=rows)
            solves += 1
        return solves

    def _remove_outside(self, nodata: bool) -> None:
        """Remove (and count as outflow) particles off the grid, and in nodata cells if
        ``nodata``, i.e. when nodata is not walled off (the walled nodata border runs through
        nodata cells, whose slivers are then wet area)."""
        p = self.particles
        t = self.terrain
        ny, nx = t.shape
        col = np.floor(p.x / t.dx).astype(np.int64)
        row = np.floor(p.y / t.dy).astype(np.int64)
        inside = (col >= 0) & (col < nx) & (row >= 0) & (row < ny)
        if nodata:
            inside[inside] = t.valid[row[inside], col[inside]]
        if not inside.all():
            self.volume_out += float(p.m[~inside].sum() / RHO_WATER)
            p.keep(inside)

    def _reorder(self) -> None:
        """Sort particles by cell so that neighbours are close in memory."""
        p = self.particles
        if p.n:
            grid = CellGrid(p.x, p.y, 2.0 * float(np.mean(p.h)))
            p.permute(grid.order)
            self.nl = None

    def _neighbours(self, force: bool = False, rows: np.ndarray | None = None) -> None:
        """Neighbour and near-wall lists, rebuilt when the Verlet skin is used up (or ``force``).

        The lists are built for h_i times the growth of h_i in the last density solve
        (``hgrow``, at most ``MAX_SEARCH_GROWTH``), so that a particle whose h keeps growing
        in the solves (a thinning edge) is not held back by its lists step after step
        (:meth:`_solve_density`). ``rows``: list only these particles' neighbours (the
        near-wall lists still cover every particle, for the drift).
        """
        p = self.particles
        nl = getattr(self, "nl", None)
        if not force and nl is not None and nl.still_valid(p.x, p.y, p.h):
            self._lap("neighbours")
            return
        self._nl_fresh = True
        self.counters["neighbour_builds"] += 1
        self._nl_here = True  # built at the current positions (until the next drift)
        h_search = p.h * np.clip(p.hgrow, 1.0, MAX_SEARCH_GROWTH)
        self.nl = NeighbourList(p.x, p.y, h_search, skin=self.numerics.neighbour_skin,
                                rows=rows)
        self.walls_near = self.wall_index.near_lists(p.x, p.y, h_search, self.nl.start,
                                                     self.nl.nbr, self.nl.reach)
        self._lap("neighbours")

    def _blocked_pairs(self) -> None:
        """Flag the listed pairs that a wall separates, and measure the distances to the near
        segments, at the current positions."""
        p = self.particles
        self._blocked_nl = self.nl
        if self.blocked.shape[0] != self.nl.nbr.shape[0]:
            self.blocked = np.empty(self.nl.nbr.shape[0], dtype=np.bool_)
        if self.wdist.shape[0] != self.walls_near[1].shape[0]:
            self.wdist = np.empty(self.walls_near[1].shape[0])
        sight.blocked_pairs(self.nl.rows, p.x, p.y, self.nl.start, self.nl.nbr,
                              *self.walls_near[:2], self.seg, self.blocked, self.wdist)

    def _image_lists(self):
        """The wall arguments (wdist, wstart, wseg, cstart, cpair) of the density and force
        kernels: with ``wall_model = "integral"`` no segment makes images (its distance
        infinite, no corners), and the walls act through ``floodsph.walls.shadow``."""
        wstart, wseg, cstart, cpair = self.walls_near
        if not self.integral_walls:
            return self.wdist, wstart, wseg, cstart, cpair
        if self._no_images[0] is not self.walls_near:  # once per build of the lists
            self._no_images = (self.walls_near, np.full(wseg.shape[0], np.inf),
                               np.zeros_like(cstart), cpair[:0])
        _, far, no_corners, no_pairs = self._no_images
        return far, wstart, wseg, no_corners, no_pairs

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
        """
        num = self.numerics
        p = self.particles
        h_predicted = p.h.copy()
        for _ in range(SETTLE_ROUNDS if settle else 2):
            self._blocked_pairs()
            wdist, *walls = self._image_lists()
            outcome = density.solve_density(
                p, self.nl, self.blocked, wdist, walls, self.seg,
                tol=num.density_tol, max_iter=num.density_max_iter, h_ratio=num.h_ratio,
                cap=not settle, integral=self.integral_walls, unmoved=self._nl_here)
            if settle and self.nl.covers(p.x, p.y, p.h):
                break
            if not settle and (outcome.capped == 0 or self._nl_fresh):
                break
            self._lap("density")
            self._neighbours(force=True, rows=None if self.nl.complete else self.nl.rows)
        rows = self.nl.rows
        if self.nl.complete:
            p.hgrow[:] = p.h / h_predicted
        else:
            p.hgrow[rows] = p.h[rows] / h_predicted[rows]
        self.counters["density_unconverged"] += outcome.unconverged
        self.counters["density_capped"] += outcome.capped
        self.counters["density_held"] += outcome.held

    def _forces(self) -> None:
        p = self.particles
        t = self.terrain
        if self.bed.shape[0] != p.n:
            self.bed = np.empty((p.n, 7))
            self.pair_sums = np.empty((p.n, forces.SUMS))
        rows = self.nl.rows
        bedmod.sample_bed(rows, p.x, p.y, t.dx, t.dy, *t.bed_grids(), self.bed)
        if self._blocked_nl is not self.nl:  # the density loop rebuilt the lists last
            self._blocked_pairs()
        forces.internal_acceleration(rows, p.x, p.y, p.u, p.v, p.m, p.rho, p.alpha, p.h, p.kxx,
                                     p.kxy, p.kyy, self.nl.start, self.nl.nbr, self.blocked,
                                     *self._image_lists(), self.seg, self.scheme,
                                     self.pair_sums, p.ax, p.ay, p.divv)
        consistency.update_renormalisation(rows, p.h, self.pair_sums, self.shores, p.kxx, p.kxy,
                                           p.kyy)
        if self.walled.shape[0] != p.n:
            self.walled = np.zeros(p.n, dtype=np.bool_)
        if self.integral_walls:
            shadow.balance_walls(rows, p.x, p.y, p.rho, p.h, *self.walls_near[:2], self.seg,
                                      self.pair_sums, p.ax, p.ay, self.walled)
        if self.shores:
            shore.balance_shores(rows, p.x, p.y, p.u, p.v, p.rho, p.h, self.bed, t.dx, t.dy,
                                 t.elevation, self.pair_sums, self.walled, p.ax, p.ay)
        forces.add_bed_acceleration(rows, p.u, p.v, self.bed, self.numerics.max_slope, p.ax,
                                    p.ay)
