"""State: what a run changes as it goes, and all that a checkpoint must keep of it.

The particles, the clock, the volumes and counters, and the per-particle arrays that a step
leaves and the next one may read before it writes them. The stages
(``floodsph.model.stages``) change it; the lists and other caches that a step can build again
are the :class:`~floodsph.model.workspace.Workspace`'s; what never changes is the
:class:`~floodsph.model.domain.Domain`'s.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from floodsph.model.particles import ParticleSet
from floodsph.sph import bed as bedmod
from floodsph.sph.sums import SUMS


def _counters() -> dict[str, int]:
    return {"splits": 0, "merges": 0, "particles_max": 0, "wall_reflections": 0,
            "density_unconverged": 0, "density_capped": 0, "density_held": 0,
            "particle_updates": 0, "seeds_settled": 0, "settle_steps": 0,
            "neighbour_builds": 0}


@dataclass(eq=False)
class State:
    """The changing part of a model (module docstring).

    Attributes
    ----------
    particles : ParticleSet
        The water particles (local coordinates); between steps, water only.
    t : float
        Simulated time [s].
    steps : int
        Finest time steps taken.
    dt : float
        The next (finest) time step [s].
    volume_in, volume_out : float
        Water that entered, and left, the domain [m3].
    volume_out_other : float
        Outflow [m3] off the grid or into nodata cells that no open side or sink took
        (``floodsph.model.stages.remove_outside``).
    volume_seed_adjustment : float
        Volume change [m3] of matching the masses of still-water seeds by walls at the set-up
        (``floodsph.model.wall_seeds``).
    counters : dict of str to int
        Splits, merges, the most particles, wall reflections, the density solve's
        unconverged, capped and held particles, particle updates, settled seeds and set-up
        steps, neighbour-list builds.
    bed : (n, BED_COLUMNS) array
        The bed sampled at the particles (``floodsph.sph.bed``).
    pair_sums : (n, SUMS) array
        The named pair sums of the last forces (``floodsph.sph.sums``).
    blocked : bool array
        The listed pairs that a wall separates (``floodsph.walls.sight.blocked_pairs``).
    wdist : array
        The distances [m] from each listed particle to its near wall segments.
    eta, ghost : arrays
        Under the balanced momentum, the particles' levels [m] and their dry ghosts'
        depths [m] (0: no free edge).
    walled : bool array
        The particles the integral walls balanced (``floodsph.sph.shadow``).
    """

    STATE: ClassVar[tuple[str, ...]] = (
        "t", "steps", "dt", "volume_in", "volume_out", "volume_out_other",
        "volume_seed_adjustment", "counters", "bed", "pair_sums", "blocked", "wdist", "eta",
        "ghost", "walled")
    """What a checkpoint holds of the state itself (``floodsph.simulation.state_arrays``),
    under ``model.<name>``; the particles declare their own (``ParticleSet.STATE``)."""

    particles: ParticleSet
    t: float = 0.0
    steps: int = 0
    dt: float = np.inf
    volume_in: float = 0.0
    volume_out: float = 0.0
    volume_out_other: float = 0.0
    volume_seed_adjustment: float = 0.0
    counters: dict[str, int] = field(default_factory=_counters)
    bed: np.ndarray = field(default_factory=lambda: np.empty((0, bedmod.BED_COLUMNS)))
    pair_sums: np.ndarray = field(default_factory=lambda: np.empty((0, SUMS)))
    blocked: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.bool_))
    wdist: np.ndarray = field(default_factory=lambda: np.empty(0))
    eta: np.ndarray = field(default_factory=lambda: np.empty(0))
    ghost: np.ndarray = field(default_factory=lambda: np.empty(0))
    walled: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.bool_))

    def __post_init__(self) -> None:
        self.counters["particles_max"] = max(self.counters["particles_max"], self.particles.n)
