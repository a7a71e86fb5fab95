"""What the refiner (``floodsph.model.refinement``) is given besides the run's state.

The refiner does not see the model: it reads the domain and the open boundaries' zones, and
calls back to count the water it moves and to say that particles were added or removed.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import NamedTuple

import numpy as np

from floodsph.boundaries.protocol import Boundary
from floodsph.model.domain import Domain


class RefinementSite(NamedTuple):
    """What the refiner reads and calls besides the run's state: the domain, the open
    boundaries (their zones are left alone), ``count_moves(x0, y0, x1, y1, m)`` for water of
    mass m [kg] moved from (x0, y0) to (x1, y1) [m] (the flux lines'; None without them), and
    ``particles_changed()``, called when particles were added or removed (the lists are
    stale then)."""

    domain: Domain
    boundaries: Sequence[Boundary]
    count_moves: Callable[..., None] | None
    particles_changed: Callable[[], None]


def protected(site: RefinementSite, x, y, h) -> np.ndarray:
    """True for points (x, y) [m] with a wall segment within the kernel reach of h [m]
    (with the neighbour lists' skin), or in an open boundary's zone: no merging there."""
    n = x.shape[0]
    reach = 2.0 * (1.0 + site.domain.numerics.neighbour_skin)
    wstart = site.domain.wall_index.near_lists(x, y, h, np.zeros(n + 1, dtype=np.int64),
                                               np.zeros(0, dtype=np.int64), reach).wstart
    mask = np.diff(wstart) > 0
    for boundary in site.boundaries:
        mask |= boundary.protected(x, y)
    return mask


def count_refinement_moves(site: RefinementSite, p, parents, a, b, born, merged) -> None:
    """Tell the flux lines (``site.count_moves``) where refinement moved water: each parent's
    mass to its daughters (each with the daughter's mass), each pair's masses to the merged
    particle."""
    from floodsph.sph import refine

    count = site.count_moves
    assert count is not None  # called only with flux lines
    if born is not None:
        rep = np.repeat(parents, refine.DAUGHTERS)
        count(p.x[rep], p.y[rep], born["x"], born["y"], born["m"])
    if merged is not None:
        both = np.concatenate([a, b])
        count(p.x[both], p.y[both], np.tile(merged["x"], 2), np.tile(merged["y"], 2),
              p.m[both])

