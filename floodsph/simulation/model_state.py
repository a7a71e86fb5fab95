"""The state of a FloodModel as a tree of named values, and its restoration into a fresh one.

A checkpoint (``floodsph.simulation.checkpoint``) stores what :func:`model_state` returns;
a resumed run builds its model from the scenario as a fresh run does
(``floodsph.model.from_scenario.build_model``: terrain, walls, boundaries, refiner, flux
lines) and :func:`restore_model` then sets, field by field, what changed while the
interrupted run went. Each part declares its own state (``STATE``,
``floodsph.simulation.state_arrays``); the tree, by the names a checkpoint gives them:

* ``model.*``: ``FloodModel.STATE`` (the clock, volumes, counters, per-particle arrays of
  the last step);
* ``model.particles.*``: ``ParticleSet.STATE`` (``capacity``, ``n``, ``next_pid``, every
  field of the active particles);
* ``model.lists.*``: the neighbour lists (``NeighbourList.STATE``; JSON null when the next
  step rebuilds them), and ``model.walls_near.*``: the near-wall lists built with them;
  ``model.blocked_current``: whether the blocked pairs belong to these lists;
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
"""The parts of the model's state beside ``FloodModel.STATE``."""


def model_state(model) -> dict[str, Any]:
    """The state of ``model`` (module docstring)."""
    state = capture(model)
    state.update(
        particles=capture(model.particles),
        lists=None if model.nl is None else capture(model.nl),
        walls_near=model.walls_near._asdict(),
        blocked_current=model.nl is not None and model._blocked_nl is model.nl,
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
    restore(model, own, where, source)
    restore(model.particles, parts["particles"], f"{where}.particles", source)
    model.nl = _lists(model, parts["lists"], source)
    template = model.walls_near._asdict()
    model.walls_near = NearWalls(**conform(template, parts["walls_near"], f"{where}.walls_near",
                                           source))
    model._blocked_nl = model.nl if parts["blocked_current"] is True else None
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


def _lists(model, state, source: str) -> NeighbourList | None:
    """The neighbour lists of ``state`` (None: none, the next step builds them)."""
    if state is None:
        return None
    empty = np.zeros(0)
    lists = model.nl if model.nl is not None else NeighbourList(empty, empty, empty)
    restore(lists, state, "model.lists", source)
    return lists
