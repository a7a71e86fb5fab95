"""Workspace: the caches a step builds and may build again (lists, their wall images).

Nothing here is a result of the run: the neighbour and near-wall lists are rebuilt when the
particles have moved past their skin or have been added or removed, and the flags say what
the current step has built. A checkpoint keeps the lists nevertheless
(``floodsph.simulation.model_state``): a fresh build may list the pairs in another order,
and the sums over them would then differ in the last digits.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from floodsph.sph.neighbours import NeighbourList
from floodsph.walls.index import NearWalls

if TYPE_CHECKING:
    from floodsph.model.stage_timer import StageTimer


@dataclass(eq=False)
class Workspace:
    """The caches of a model (module docstring).

    Attributes
    ----------
    nl : NeighbourList or None
        The neighbour lists (``floodsph.sph.neighbours``); None: the next step builds them.
    walls_near : NearWalls or None
        The near-wall lists built with them (``floodsph.walls.index``).
    blocked_for : NeighbourList or None
        The lists that ``State.blocked`` and ``State.wdist`` were measured for.
    no_images : tuple
        The integral walls' image-free wall lists and the near-wall lists they were made
        from (``floodsph.model.list_stages.wall_lists``), once per build of the lists.
    lists_fresh : bool
        Lists built in this step (or local substep).
    lists_here : bool
        Lists built at the current positions (until the next drift).
    timer : StageTimer or None
        The stage timer of the step under way (``floodsph.model.stage_timer``), or None.
    """

    nl: NeighbourList | None = None
    walls_near: NearWalls | None = None
    blocked_for: NeighbourList | None = None
    no_images: tuple = (None,)
    lists_fresh: bool = False
    lists_here: bool = False
    timer: StageTimer | None = None

    def particles_changed(self) -> None:
        """Particles were added or removed outside the step (a refinement, a boundary): the
        neighbour and near-wall lists are stale, and the next step rebuilds them."""
        self.nl = None

    def lap(self, stage: str) -> None:
        """Mark the end of a stage of the step for the stage timer, if one is set."""
        if self.timer is not None:
            self.timer.lap(stage)
