"""The stages that build the neighbour and near-wall lists and measure the walls between pairs.

Each takes the :class:`~floodsph.model.domain.Domain`, the
:class:`~floodsph.model.state.State` and the :class:`~floodsph.model.workspace.Workspace`
(``docs/method.md`` §5, step 3; the kernels are ``floodsph.sph.neighbours`` and
``floodsph.walls``).
"""

from __future__ import annotations

import numpy as np

from floodsph.model.domain import Domain
from floodsph.model.state import State
from floodsph.model.workspace import Workspace
from floodsph.sph.neighbours import NeighbourList
from floodsph.walls import sight
from floodsph.walls.index import WallLists

MAX_SEARCH_GROWTH = 2.0
"""Cap on the factor ``hgrow`` by which a particle's neighbour search is widened."""


def update_lists(domain: Domain, state: State, work: Workspace, force: bool = False,
                 rows: np.ndarray | None = None) -> None:
    """Neighbour and near-wall lists, rebuilt when the Verlet skin is used up (or ``force``).

    The lists are built for h_i times the growth of h_i in the last density solve
    (``hgrow``, at most ``MAX_SEARCH_GROWTH``), so that a particle whose h keeps growing
    in the solves (a thinning edge) is not held back by its lists step after step
    (``floodsph.model.stages.solve_density``). ``rows``: list only these particles'
    neighbours and near walls (the drift finds its walls in the wall index).
    """
    p = state.particles
    nl = work.nl
    if not force and nl is not None and nl.still_valid(p.x, p.y, p.h):
        work.lap("neighbours")
        return
    work.lists_fresh = True
    state.counters["neighbour_builds"] += 1
    work.lists_here = True  # built at the current positions (until the next drift)
    h_search = p.h * np.clip(p.hgrow, 1.0, MAX_SEARCH_GROWTH)
    work.nl = NeighbourList(p.x, p.y, h_search, skin=domain.numerics.neighbour_skin,
                            rows=rows)
    work.walls_near = domain.wall_index.near_lists(p.x, p.y, h_search, work.nl.start,
                                                   work.nl.nbr, work.nl.reach, rows)
    work.lap("neighbours")


def block_pairs(domain: Domain, state: State, work: Workspace) -> None:
    """Flag the listed pairs that a wall separates, and measure the distances to the near
    segments, at the current positions."""
    p = state.particles
    nl, near = work.nl, work.walls_near
    assert nl is not None and near is not None  # update_lists runs first
    work.blocked_for = nl
    if state.blocked.shape[0] != nl.nbr.shape[0]:
        state.blocked = np.empty(nl.nbr.shape[0], dtype=np.bool_)
    if state.wdist.shape[0] != near.wseg.shape[0]:
        state.wdist = np.empty(near.wseg.shape[0])
    sight.blocked_pairs(nl.rows, p.x, p.y, nl.start, nl.nbr,
                        near.wstart, near.wseg, domain.seg, state.blocked, state.wdist)


def wall_lists(domain: Domain, state: State, work: Workspace) -> WallLists:
    """The walls as the density and force kernels take them: with ``wall_model =
    "integral"`` no segment makes images (its distance infinite, no corners), and the
    walls act through ``floodsph.sph.shadow``."""
    assert work.walls_near is not None  # update_lists runs first
    wstart, wseg, cstart, cpair = work.walls_near
    if not domain.integral_walls:
        return WallLists(domain.seg, state.wdist, wstart, wseg, cstart, cpair)
    if work.no_images[0] is not work.walls_near:  # once per build of the lists
        work.no_images = (work.walls_near, WallLists(
            domain.seg, np.full(wseg.shape[0], np.inf), wstart, wseg, np.zeros_like(cstart),
            cpair[:0]))
    return work.no_images[1]
