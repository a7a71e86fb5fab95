"""The state of a FloodModel as a tree of named values, and its restoration into a fresh one.

A checkpoint (``floodsph.simulation.checkpoint``) stores what :func:`model_state` returns;
a resumed run builds its model from the scenario as a fresh run does
(``floodsph.model.from_scenario.build_model``: terrain, walls, boundaries, refiner, flux
lines) and :func:`restore_model` then sets, field by field, what changed while the
interrupted run went. Each part declares its own state (``STATE``,
``floodsph.simulation.state_arrays``); the tree, by the names a checkpoint gives them:

* ``model.*``: ``State.STATE`` of the model's ``state`` (``floodsph.model.state``: the
  clock, volumes, counters, per-particle arrays of the last step);
* ``model.particles.*``: ``ParticleSet.STATE`` (``capacity``, ``n``, ``next_pid``, every
  field of the active particles);
* ``model.lists.*``: the workspace's neighbour lists (``NeighbourList.STATE``; JSON null
  when the next step rebuilds them), and ``model.walls_near.*``: the near-wall lists built
  with them; ``model.blocked_current``: whether the blocked pairs belong to these lists
  (``floodsph.model.workspace``);
* ``model.boundaries.<i>.*``: each open boundary's ``STATE``, in the model's order, and
  ``model.boundary_kinds``, their class names;
* ``model.refiner.*`` and ``model.flux_lines.*``, when the model has them.

The neighbour lists are stored, not built again, because a new build may list the pairs in
another order, and the sums over them would then differ in the last digits: with them the
resumed run repeats the interrupted run's arithmetic exactly.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from floodsph.errors import InputError
from floodsph.simulation.state_arrays import capture, conform, expect_fields, restore
from floodsph.sph.neighbours import NeighbourList
from floodsph.walls.index import NearWalls

PARTS = ("particles", "lists", "walls_near", "blocked_current", "boundaries",
         "boundary_kinds", "refiner", "flux_lines")
"""The parts of the model's state beside ``State.STATE``."""


def model_state(model) -> dict[str, Any]:
    """The state of ``model`` (module docstring)."""
    work = model.work
    state = capture(model.state)
    state.update(
        particles=capture(model.state.particles),
        lists=None if work.nl is None else capture(work.nl),
        walls_near=work.walls_near._asdict(),
        blocked_current=work.nl is not None and work.blocked_for is work.nl,
        boundaries={str(i): capture(b) for i, b in enumerate(model.boundaries)},
        boundary_kinds=[type(b).__name__ for b in model.boundaries],
        refiner=None if model.refiner is None else capture(model.refiner),
        flux_lines=None if model.flux_lines is None else capture(model.flux_lines),
    )
    return state


def restore_model(model, state: dict[str, Any], source: str) -> None:
    """Set the state of ``model``, built afresh from the scenario, from ``state`` (read from
    the file ``source``, for messages).

    Raises
    ------
    InputError
        A field missing, extra or ill-formed, or a model of another make (other boundaries,
        a refiner or flux lines where the scenario has none, or none where it has them).
    """
    where = "model"
    own = {name: value for name, value in state.items() if name not in PARTS}
    parts = {name: value for name, value in state.items() if name in PARTS}
    expect_fields(parts, PARTS, where, source)
    work = model.work
    restore(model.state, own, where, source)
    restore(model.state.particles, parts["particles"], f"{where}.particles", source)
    work.nl = _lists(work.nl, parts["lists"], source)
    template = work.walls_near._asdict()
    work.walls_near = NearWalls(**conform(template, parts["walls_near"], f"{where}.walls_near",
                                          source))
    work.blocked_for = work.nl if parts["blocked_current"] is True else None
    kinds = [type(b).__name__ for b in model.boundaries]
    if parts["boundary_kinds"] != kinds:
        raise InputError(f"{source}: the checkpointed model has the boundaries "
                         f"{parts['boundary_kinds']}, the scenario makes {kinds}")
    boundaries = parts["boundaries"]
    expect_fields(boundaries, [str(i) for i in range(len(kinds))], f"{where}.boundaries",
                  source)
    for i, boundary in enumerate(model.boundaries):
        restore(boundary, boundaries[str(i)], f"{where}.boundaries.{i}", source)
    for name in ("refiner", "flux_lines"):
        part = getattr(model, name)
        if (part is None) != (parts[name] is None):
            raise InputError(f"{source}: the field {where}.{name} does not fit the scenario's "
                             "model (one has it, the other not)")
        if part is not None:
            restore(part, parts[name], f"{where}.{name}", source)


def _lists(fresh: NeighbourList | None, state, source: str) -> NeighbourList | None:
    """The neighbour lists of ``state`` (None: none, the next step builds them), read into
    the fresh model's lists ``fresh`` where it has them."""
    if state is None:
        return None
    empty = np.zeros(0)
    lists = fresh if fresh is not None else NeighbourList(empty, empty, empty)
    restore(lists, state, "model.lists", source)
    return lists
