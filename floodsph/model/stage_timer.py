"""Wall time per stage of a time step: the optional timer of ``FloodModel.stage_timer``.

Set ``model.stage_timer = StageTimer()`` and every :meth:`FloodModel.step` then adds the wall
time [s] of each of its stages to ``seconds[stage]``, and one to ``steps``. The model marks
the end of each stage (:meth:`StageTimer.lap`), so the stages are exclusive and add up to the
whole step; a stage met several times in a step (the lists rebuilt inside the density solve,
the substeps of local time stepping) accumulates. With no timer set (the default) a mark
costs one attribute test.

Stages (:data:`STAGES`):

* ``kick_drift``: the opening half kick and the drift with its wall reflections;
* ``boundaries``: the open boundaries (inflows, sinks, open edges), their ghosts, and the
  removal of the water that left the domain;
* ``refinement``: splitting and coalescing, and the periodic re-sort;
* ``neighbours``: the neighbour and near-wall lists (their validity test included);
* ``density``: the continuity guess, the wall-blocked pairs and the density solve;
* ``forces``: bed sample, pair forces, renormalisation, shore and bed terms;
* ``close``: the closing half kick, friction, the clock and the next time step.
"""

from __future__ import annotations

import time

STAGES = ("kick_drift", "boundaries", "refinement", "neighbours", "density", "forces", "close")


class StageTimer:
    """Accumulated wall time [s] per stage of ``FloodModel.step`` (module docstring)."""

    def __init__(self):
        self.seconds = dict.fromkeys(STAGES, 0.0)
        self.steps = 0
        self._last = None

    def begin(self) -> None:
        """Start the clock of a step."""
        self._last = time.perf_counter()

    def lap(self, stage: str) -> None:
        """Add the time since the previous mark to ``stage``; ignored outside a step."""
        if self._last is None:
            return
        now = time.perf_counter()
        self.seconds[stage] += now - self._last
        self._last = now

    def end(self) -> None:
        """Close the step: its remaining time is ``close``'s."""
        self.lap("close")
        self._last = None
        self.steps += 1

    def reset(self) -> None:
        """Forget the time and steps accumulated so far."""
        self.seconds = dict.fromkeys(STAGES, 0.0)
        self.steps = 0
