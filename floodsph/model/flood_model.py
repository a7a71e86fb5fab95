"""FloodModel: particles on a terrain, advanced one time step at a time.

The model knows how to take a step and nothing about files, schedules or output (those are
``floodsph.simulation.loop``'s). It holds the parts a step works on and hands them to a
driver:

* ``domain``: the :class:`~floodsph.model.domain.Domain`, fixed at the set-up (terrain,
  settings, walls and their index, closed sides);
* ``state``: the :class:`~floodsph.model.state.State`, all that a run changes and a
  checkpoint keeps (particles, clock, volumes, counters, the arrays of the last step);
* ``work``: the :class:`~floodsph.model.workspace.Workspace` of lists, built again as needed;
* ``boundaries``, ``refiner``, ``flux_lines`` and ``stage_timer``.

A step (``docs/method.md`` §5) is the stages of ``floodsph.model.stages``, driven by
``floodsph.model.stepping.global_step``, or with ``Numerics.time_stepping =
TimeStepping.LOCAL`` by ``floodsph.model.local_stepping.big_step``: one big step of 2^K
finest steps in which each particle does the stages at its own power-of-two multiple of the
finest step (``floodsph.sph.local_steps``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from floodsph.boundaries.protocol import Site
from floodsph.constants import RHO_WATER
from floodsph.model.domain import Domain
from floodsph.model.local_stepping import big_step
from floodsph.model.particles import ParticleSet
from floodsph.model.refinement_site import RefinementSite
from floodsph.model.stages import Parts, begin_step, stable_dt
from floodsph.model.state import State
from floodsph.model.stepping import global_step
from floodsph.model.terrain import Terrain
from floodsph.model.workspace import Workspace
from floodsph.scenario.numerics import Numerics, TimeStepping
from floodsph.sph import level_offsets
from floodsph.walls.index import MapWalls

if TYPE_CHECKING:
    from floodsph.model.stage_timer import StageTimer
    from floodsph.simulation.flux import FluxLines


class FloodModel:
    """Shallow-water SPH particles on a terrain.

    The model steps; it is set up by ``floodsph.model.builder.set_up_model``, which makes the
    domain and the open edges, settles the seeds and solves the first density.

    Parameters
    ----------
    domain : Domain
    particles : ParticleSet
        The water particles (local coordinates), the start of the :class:`State`.
    boundaries : sequence of floodsph.boundaries.protocol.Boundary
        Open boundaries (the open edges, inflows, sinks), each keeping that contract.
    refiner : floodsph.model.refinement.Refiner or None
        Particle splitting and coalescing, called after the boundaries once the particles
        have moved.

    Attributes
    ----------
    domain, state, work, boundaries, refiner
        As above; ``work`` the :class:`Workspace`.
    stage_timer : StageTimer or None
        Set it to a ``floodsph.model.stage_timer.StageTimer`` to have every step add the wall
        time of each of its stages there (None, the default: no timing).
    flux_lines : FluxLines or None
        ``floodsph.simulation.flux.FluxLines`` counting the water that crosses the scenario's
        flux lines (every move of a particle), or None (the default).

    The read-only ``particles``, ``t``, ``steps``, ``terrain`` and ``numerics`` are those of
    ``state`` and ``domain``, which many readers of a model want.
    """

    def __init__(self, domain: Domain, particles: ParticleSet, boundaries, refiner=None):
        self.domain = domain
        self.state = State(particles)
        self.work = Workspace()
        self.boundaries = list(boundaries)
        self.refiner = refiner
        self.stage_timer: StageTimer | None = None
        self.flux_lines: FluxLines | None = None

    @property
    def particles(self) -> ParticleSet:
        """The particles (``state.particles``)."""
        return self.state.particles

    @property
    def t(self) -> float:
        """Simulated time [s] (``state.t``)."""
        return self.state.t

    @property
    def steps(self) -> int:
        """Finest time steps taken (``state.steps``)."""
        return self.state.steps

    @property
    def terrain(self) -> Terrain:
        """The terrain (``domain.terrain``)."""
        return self.domain.terrain

    @property
    def numerics(self) -> Numerics:
        """The solver's settings (``domain.numerics``)."""
        return self.domain.numerics

    def __repr__(self) -> str:
        return (f"FloodModel(t={self.t:.3f} s, steps={self.steps}, particles={self.particles.n}, "
                f"walls={self.domain.seg.shape[0]} segments, "
                f"closed_sides={sorted(self.domain.closed_sides)})")

    # -- queries -----------------------------------------------------------------------------
    def depth(self) -> np.ndarray:
        """Depth [m] of the active particles: d = rho / rho_w, and under the balanced momentum
        d + o, its level less the bed (``floodsph.sph.level_offsets``)."""
        p = self.particles
        if self.domain.balanced:
            return p.rho / RHO_WATER + p.eta_offset
        return p.rho / RHO_WATER

    def surface_levels(self) -> np.ndarray | None:
        """The free-surface levels eta = d + b + o [m] of the particles under the balanced
        momentum (``floodsph.sph.level_offsets``), which the maps and gauges report depth
        from; None under the variational momentum (they report the summed depth)."""
        if not self.domain.balanced:
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
        return stable_dt(self.domain, self.state, self.boundaries)

    def map_walls(self) -> MapWalls:
        """The walls as the maps see them (``Domain.map_walls`` at the particles)."""
        p = self.particles
        return self.domain.map_walls(p.x, p.y, p.h)

    # -- one step ------------------------------------------------------------------------------
    def parts(self) -> Parts:
        """The parts the stages work on (``floodsph.model.stages.Parts``), with the
        boundaries' and the refiner's narrow views of the model."""
        count = None if self.flux_lines is None else self.flux_lines.count
        site = Site(self.domain.terrain, self.domain.numerics.neighbour_skin,
                    self.domain.balanced, count)
        return Parts(self.domain, self.state, self.work, self.boundaries, site, self.refiner,
                     RefinementSite(self.domain, self.boundaries, count,
                                    self.work.particles_changed))

    def step(self, dt_max: float | None = None) -> float:
        """Advance one time step (at most ``dt_max``); return the step taken [s].

        With local time stepping the step is a big step of up to 2^K finest steps
        (``floodsph.model.local_stepping.big_step``), at the end of which every particle is
        synchronised.
        """
        timer = self.work.timer = self.stage_timer
        if timer is not None:
            timer.begin()
        parts = self.parts()
        begin_step(parts)
        if self.numerics.time_stepping is TimeStepping.LOCAL:
            dt = big_step(parts, dt_max)
        else:
            dt = global_step(parts, dt_max)
        if timer is not None:
            timer.end()
        return dt
