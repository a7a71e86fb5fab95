"""When a callback runs: every N steps, every T simulated seconds, at listed simulated times,
every W wall-clock seconds.

Schedules are small objects with ``due(sim) -> bool`` (called after every step) and
``reset(sim)`` (called once when the simulation starts). An aligned :class:`TimeInterval`
also tells the simulation its next actuation time, so the time step can be shortened to land
on it exactly (the idea of Oceananigans.jl's ``aligned_time_step``). Landing costs up to one
extra step per interval (a 0.96 s step before a 1 s mark is followed by a 0.04 s one), so
callbacks that only sample, like the max-depth envelopes, use ``align=False``: they run at
the first step at or after each mark.
"""

from __future__ import annotations

import bisect
import math
import time


def time_tolerance(t: float) -> float:
    """Times closer than this [s] count as equal (round-off of summed time steps)."""
    return 1e-9 * max(1.0, abs(t))


class IterationInterval:
    """Due every ``n`` steps (``model.steps % n == 0``)."""

    def __init__(self, n: int):
        if int(n) < 1:
            raise ValueError(f"IterationInterval needs n >= 1, got {n}")
        self.n = int(n)

    def reset(self, sim) -> None:
        pass

    def due(self, sim) -> bool:
        return sim.model.steps % self.n == 0

    def __repr__(self) -> str:
        return f"IterationInterval({self.n})"


class _SimulatedTimes:
    """A schedule due at the first step at or after its ``next_time`` [s], which ``reset``
    moves on."""

    next_time: float

    def reset(self, sim) -> None:
        raise NotImplementedError

    def due(self, sim) -> bool:
        t = sim.model.t
        if t < self.next_time - time_tolerance(self.next_time):
            return False
        self.reset(sim)
        return True


class TimeInterval(_SimulatedTimes):
    """Due at simulated times ``k * interval`` (k = 1, 2, ...) [s]; with ``align`` the time
    step lands on them, otherwise it is due at the first step at or after each."""

    def __init__(self, interval: float, align: bool = True):
        if not interval > 0:
            raise ValueError(f"TimeInterval needs interval > 0, got {interval}")
        self.interval = float(interval)
        self.align = bool(align)
        self.next_time = self.interval

    def reset(self, sim) -> None:
        t = sim.model.t
        self.next_time = (math.floor(t / self.interval + time_tolerance(t)) + 1) * self.interval

    def __repr__(self) -> str:
        return f"TimeInterval({self.interval:g} s{'' if self.align else ', not aligned'})"


class TimeList(_SimulatedTimes):
    """Due at the listed simulated times [s] (increasing); the time step lands on each
    (aligned, as :class:`TimeInterval`). Due at the first step at or after a time, once."""

    align = True

    def __init__(self, times):
        self.times = tuple(float(t) for t in times)
        if any(b <= a for a, b in zip(self.times[:-1], self.times[1:], strict=True)):
            raise ValueError(f"TimeList needs increasing times, got {self.times}")
        self.next_time = self.times[0] if self.times else math.inf

    def reset(self, sim) -> None:
        """The first listed time after ``sim.model.t`` (infinity after the last)."""
        t = sim.model.t
        k = bisect.bisect_right(self.times, t + time_tolerance(t))
        self.next_time = self.times[k] if k < len(self.times) else math.inf

    def __repr__(self) -> str:
        return f"TimeList({len(self.times)} times)"


class WallTimeInterval:
    """Due when ``seconds`` of wall-clock time have passed since it was last due."""

    def __init__(self, seconds: float):
        self.seconds = float(seconds)
        self.last = time.monotonic()

    def reset(self, sim) -> None:
        self.last = time.monotonic()

    def due(self, sim) -> bool:
        now = time.monotonic()
        if now - self.last < self.seconds:
            return False
        self.last = now
        return True

    def __repr__(self) -> str:
        return f"WallTimeInterval({self.seconds:g} s)"
