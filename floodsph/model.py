"""FloodModel: particles on a terrain, advanced one time step at a time.

The model knows how to take a step and nothing about files, schedules or output (those are
``floodsph.simulation``'s). One step (kick-drift-kick leap-frog with a variable CFL step,
method notes 2.6-2.7):

1. kick   v^{n+1/2} = v^n + a^n dt / 2
2. drift  x^{n+1} = x^n + v^{n+1/2} dt; moves across walls are reflected; particles that
          leave an open border or enter nodata are removed and counted as outflow
3. density guess from continuity, neighbour lists, Newton-Raphson solve of rho and h
4. forces a^{n+1} at (x^{n+1}, v^{n+1/2}): pressure + shock capturing + bed
5. kick   v^{n+1} = v^{n+1/2} + a^{n+1} dt / 2, then semi-implicit Manning friction over dt
6. next dt = cfl min h / (|v| + c)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from floodsph.constants import RHO_WATER
from floodsph.particles import ParticleSet
from floodsph.sph import bed as bedmod
from floodsph.sph import density, forces
from floodsph.sph import walls as wallmod
from floodsph.sph.neighbours import CellGrid, NeighbourList
from floodsph.terrain import Terrain


@dataclass(frozen=True)
class Numerics:
    """Numerical settings of the solver (defaults are the recommended production values).

    cfl : Courant number of dt = cfl min h / (|v| + c).
    kappa : h0 / particle spacing.
    spacing : initial particle spacing [m].
    density_tol : Newton-Raphson tolerance on |R| / rho.
    density_max_iter : iteration cap of the density solve.
    h_ratio : h is kept within [h0 / h_ratio, h0 h_ratio].
    stabilisation : "lax-friedrichs" (parameter-free, default) or "riemann".
    friction_depth_floor : depth floor [m] of the Manning term.
    max_slope : bed slopes steeper than this are limited in the bed term.
    neighbour_skin : relative margin of the neighbour lists.
    reorder_interval : steps between spatial re-sorts of the particle arrays.
    refinement : "none" (splitting and coalescing arrive with the refinement module).
    """

    cfl: float = 0.3
    kappa: float = 1.3
    spacing: float = 10.0
    density_tol: float = 1e-3
    density_max_iter: int = 20
    h_ratio: float = 10.0
    stabilisation: str = "lax-friedrichs"
    friction_depth_floor: float = 0.01
    max_slope: float = 1.0
    neighbour_skin: float = 0.1
    reorder_interval: int = 25
    refinement: str = "none"


class FloodModel:
    """Shallow-water SPH particles on a terrain.

    Parameters
    ----------
    terrain : Terrain
    particles : ParticleSet
        Seeded particles (local coordinates) with m, rho = rho_w d and h = kappa dx set; their
        density and smoothing length are solved on construction.
    numerics : Numerics
    walls : sequence of (k, 2) arrays
        Polylines in local coordinates that water cannot cross.
    closed_edges : bool
        True: the DEM border and nodata areas are walls. False: water reaching them leaves the
        model and is counted in ``volume_out``.
    """

    def __init__(self, terrain: Terrain, particles: ParticleSet, numerics: Numerics = Numerics(),
                 walls=(), closed_edges: bool = True):
        self.terrain = terrain
        self.particles = particles
        self.numerics = numerics
        self.closed_edges = closed_edges
        self.scheme = {"lax-friedrichs": forces.LAX_FRIEDRICHS,
                       "riemann": forces.RIEMANN}[numerics.stabilisation]
        segs = [wallmod.segments_from_polylines(walls)]
        if closed_edges:
            box = wallmod.box_polyline(0.0, 0.0, terrain.width, terrain.height)
            segs.append(wallmod.segments_from_polylines([box]))
            segs.append(wallmod.mask_boundary_segments(terrain.valid, terrain.dx, terrain.dy))
        self.seg = np.concatenate(segs)
        h0 = numerics.kappa * numerics.spacing
        self.wall_index = wallmod.WallIndex(
            self.seg, (0.0, 0.0, terrain.width, terrain.height), bucket=8.0 * h0,
            margin=8.0 * h0)
        self.t = 0.0
        self.steps = 0
        self.volume_in = 0.0
        self.volume_out = 0.0
        self.counters = {"splits": 0, "merges": 0, "particles_max": particles.n,
                         "wall_reflections": 0, "density_unconverged": 0}
        self.bed = np.empty((0, 7))
        self._remove_outside()
        self._neighbours()
        self._solve_density()
        self._forces()
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
        p = self.particles
        if p.n == 0:
            return np.inf
        return float(forces.stable_dt(p.u, p.v, p.rho, p.h, self.numerics.cfl))

    # -- one step ------------------------------------------------------------------------------
    def step(self, dt_max: float | None = None) -> float:
        """Advance one time step (at most ``dt_max``); return the step taken [s]."""
        p = self.particles
        dt = self.dt if dt_max is None else min(self.dt, dt_max)
        half = 0.5 * dt
        p.u[:] += half * p.ax
        p.v[:] += half * p.ay
        x_old = p.x.copy()
        y_old = p.y.copy()
        p.x[:] += dt * p.u
        p.y[:] += dt * p.v
        if self.seg.shape[0]:
            self.counters["wall_reflections"] += int(wallmod.guard_crossings(
                x_old, y_old, p.x, p.y, p.u, p.v, self.wstart, self.wseg, self.seg))
        self._remove_outside()
        density.predict(p.rho, p.h, p.divv, dt)
        if self.numerics.reorder_interval and self.steps % self.numerics.reorder_interval == 0:
            self._reorder()
        self._neighbours()
        self._solve_density()
        self._forces()
        p.u[:] += half * p.ax
        p.v[:] += half * p.ay
        forces.apply_friction(p.u, p.v, p.rho, self.bed[:, 6], dt,
                              self.numerics.friction_depth_floor)
        self.t += dt
        self.steps += 1
        self.counters["particles_max"] = max(self.counters["particles_max"], p.n)
        self.dt = self.stable_dt()
        return dt

    # -- stages --------------------------------------------------------------------------------
    def _remove_outside(self) -> None:
        """Remove (and count as outflow) particles off the grid or in nodata cells."""
        p = self.particles
        t = self.terrain
        ny, nx = t.shape
        col = np.floor(p.x / t.dx).astype(np.int64)
        row = np.floor(p.y / t.dy).astype(np.int64)
        inside = (col >= 0) & (col < nx) & (row >= 0) & (row < ny)
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

    def _neighbours(self) -> None:
        p = self.particles
        self.nl = NeighbourList(p.x, p.y, p.h, skin=self.numerics.neighbour_skin)
        self.wstart, self.wseg = self.wall_index.near_lists(
            p.x, p.y, p.h, self.nl.start, self.nl.nbr, self.nl.reach)

    def _solve_density(self) -> None:
        num = self.numerics
        p = self.particles
        for _ in range(3):
            _, bad = density.solve_density(p, self.nl, self.wstart, self.wseg, self.seg,
                                           tol=num.density_tol, max_iter=num.density_max_iter,
                                           h_ratio=num.h_ratio)
            if self.nl.still_valid(p.h):
                break
            self._neighbours()
        self.counters["density_unconverged"] += bad

    def _forces(self) -> None:
        p = self.particles
        t = self.terrain
        if self.bed.shape[0] != p.n:
            self.bed = np.empty((p.n, 7))
        bedmod.sample_bed(p.x, p.y, t.dx, t.dy, *t.bed_grids(), self.bed)
        forces.internal_acceleration(p.x, p.y, p.u, p.v, p.m, p.rho, p.alpha, p.h, self.nl.start,
                                     self.nl.nbr, self.wstart, self.wseg, self.seg, self.scheme,
                                     p.ax, p.ay, p.divv)
        forces.add_bed_acceleration(p.u, p.v, self.bed, self.numerics.max_slope, p.ax, p.ay)
