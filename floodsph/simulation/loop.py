"""The time loop: step a model to an end time and run scheduled callbacks.

The model only knows how to take a step; the :class:`Simulation` decides when to stop and
what to record (the Model / Simulation split of Oceananigans.jl). Everything periodic (map
envelopes, gauges, mass balance, progress) is a ``(callback, schedule)`` pair; callbacks are
called with the simulation as their only argument.

Every callback runs once at the start (the initial state), whenever its schedule is due after
a step, and once at the end (the final state) unless it already ran on the last step. The
step is shortened so that the model lands exactly on the end time and on every
:class:`~floodsph.simulation.schedules.TimeInterval` and
:class:`~floodsph.simulation.schedules.TimeList` time. After every step a guard checks that
depth, velocity and position are finite and depth is not negative.

A stop request (``should_stop``, e.g. a SIGTERM caught by ``floodsph.simulation.stop_signals``)
ends the loop after the step and its callbacks, without the final calls: :meth:`Simulation.state` is
then exactly what a run that was never stopped had at that step, and a simulation given that
state by :meth:`Simulation.restore` continues as that run would (checkpoint and resume).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from floodsph.simulation.schedules import TimeInterval, TimeList, time_tolerance

log = logging.getLogger(__name__)


class SimulationError(RuntimeError):
    """The simulation cannot continue (non-finite or negative state, stalled time step)."""


class Simulation:
    """Advance ``model`` to ``end_time`` [s], running ``callbacks`` on their schedules.

    Parameters
    ----------
    model : FloodModel-like
        Needs ``step(dt_max) -> dt``, ``t``, ``steps``, ``particles`` and ``depth()``.
    end_time : float
        Simulated time to stop at [s].
    callbacks : sequence of (callable, schedule)
        ``callable(sim)`` runs when ``schedule.due(sim)``; see the module docstring.
    max_steps : int, optional
        Stop once this many time steps are taken, even before ``end_time`` (for trial runs).
        With local time stepping these are finest steps, and the loop stops at the end of
        the big step that holds the last of them (at most 2^step_levels - 1 more).
    should_stop : callable, optional
        ``should_stop() -> bool``, asked after every step; True ends the loop
        (:attr:`interrupted`).
    """

    def __init__(
        self,
        model,
        end_time: float,
        callbacks: Sequence[tuple[Callable, Any]] = (),
        max_steps: int | None = None,
        should_stop: Callable[[], bool] | None = None,
    ):
        if not end_time > 0:
            raise ValueError(f"end_time must be > 0, got {end_time}")
        self.model = model
        self.end_time = float(end_time)
        self.callbacks = list(callbacks)
        self.max_steps = max_steps
        self.should_stop = should_stop
        self.interrupted = False
        self.steps_taken = 0
        self.last_dt = 0.0
        self.wall_start = time.monotonic()
        self.last_call: list[int] | None = None
        self._restored: dict | None = None

    @property
    def wall_time(self) -> float:
        """Wall-clock seconds since :meth:`run` started."""
        return time.monotonic() - self.wall_start

    @property
    def finished(self) -> bool:
        """True once the end time (within round-off) or ``max_steps`` is reached."""
        if self.max_steps is not None and self.steps_taken >= self.max_steps:
            return True
        return self.model.t >= self.end_time - time_tolerance(self.end_time)

    def dt_max(self) -> float:
        """The longest step that does not jump over the end time or an aligned TimeInterval
        or TimeList time [s]."""
        t = self.model.t
        targets = [self.end_time]
        targets += [s.next_time for _, s in self.callbacks
                    if isinstance(s, TimeInterval | TimeList) and s.align]
        return min(target - t for target in targets if target > t + time_tolerance(target))

    def state(self) -> dict:
        """What the loop needs to continue: the step each callback last ran at, the next
        time of each TimeInterval, and the last step [s]."""
        return {"last_call": list(self.last_call or []), "last_dt": self.last_dt,
                "next_times": [getattr(s, "next_time", None) for _, s in self.callbacks]}

    def restore(self, state: dict) -> None:
        """Continue from :meth:`state` of a simulation with the same callbacks: :meth:`run`
        then skips the initial calls."""
        if len(state["last_call"]) != len(self.callbacks):
            raise ValueError("the saved simulation state has another set of callbacks")
        self._restored = state

    def run(self) -> None:
        """Step until finished or stopped; callbacks at start, when due, and at the end."""
        self.wall_start = time.monotonic()
        for _, schedule in self.callbacks:
            schedule.reset(self)
        if self._restored is None:
            self.last_call = [self.model.steps] * len(self.callbacks)
            for func, _ in self.callbacks:
                func(self)
        else:
            self.last_call = list(self._restored["last_call"])
            self.last_dt = self._restored["last_dt"]
            for (_, schedule), next_time in zip(self.callbacks, self._restored["next_times"],
                                                strict=True):
                if next_time is not None:
                    schedule.next_time = next_time
        log.info("simulation started: end time %g s, %d particles", self.end_time, self.n)
        while not self.finished:
            before = self.model.steps
            self.last_dt = self.model.step(dt_max=self.dt_max())
            self.steps_taken += self.model.steps - before
            self.check_state()
            for k, (func, schedule) in enumerate(self.callbacks):
                if schedule.due(self):
                    self.last_call[k] = self.model.steps
                    func(self)
            if self.should_stop is not None and self.should_stop():
                self.interrupted = True
                log.warning("stop requested: the loop ends at t = %g s, step %d", self.model.t,
                            self.model.steps)
                return
        for k, (func, _) in enumerate(self.callbacks):
            if self.last_call[k] != self.model.steps:
                self.last_call[k] = self.model.steps
                func(self)
        log.info(
            "simulation ended at t = %g s after %d steps (%.1f s wall)",
            self.model.t,
            self.steps_taken,
            self.wall_time,
        )

    @property
    def n(self) -> int:
        """Number of active particles."""
        return len(self.model.particles)

    def check_state(self) -> None:
        """Raise :class:`SimulationError` on a non-finite state, negative depth or dt <= 0."""
        model = self.model
        where = f"step {model.steps} (t = {model.t:.6g} s)"
        if not (np.isfinite(self.last_dt) and self.last_dt > 0):
            raise SimulationError(f"{where}: the time step is {self.last_dt!r}; the run stalled")
        p = model.particles
        d = model.depth()
        bad = ~(np.isfinite(d) & np.isfinite(p.u) & np.isfinite(p.v))
        bad |= ~(np.isfinite(p.x) & np.isfinite(p.y))
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise SimulationError(
                f"{where}: {int(bad.sum())} particles have a non-finite depth, velocity or "
                f"position (first: particle id {int(p.pid[i])}, depth {d[i]!r}, "
                f"u {p.u[i]!r}, v {p.v[i]!r}); try a smaller numerics.cfl"
            )
        negative = d < 0.0
        if negative.any():
            i = int(np.flatnonzero(negative)[0])
            raise SimulationError(
                f"{where}: {int(negative.sum())} particles have a negative depth (first: "
                f"particle id {int(p.pid[i])}, depth {d[i]:.3g} m)"
            )

    def __repr__(self) -> str:
        return (
            f"Simulation(t={self.model.t:g} s of {self.end_time:g} s, steps={self.model.steps}, "
            f"callbacks={len(self.callbacks)})"
        )
