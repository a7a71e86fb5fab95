"""Run-time callbacks: the mass-balance table, the progress bar and the progress log.

Each is a callable taking the :class:`~floodsph.simulation.loop.Simulation`; the run pairs it with
a schedule (``floodsph.run.pipeline``).
"""

from __future__ import annotations

import csv
import logging
import sys
from dataclasses import dataclass
from pathlib import Path

log = logging.getLogger(__name__)

MASS_BALANCE_COLUMNS = (
    "time_s",
    "volume_domain_m3",
    "volume_in_m3",
    "volume_out_m3",
    "error_m3",
    "error_rel",
)

#: Denominator floor of the relative mass error [m3] (a run without water).
TINY_VOLUME_M3 = 1e-12


class MassBalance:
    """Rows of ``mass_balance.csv``: the water budget of the domain over time.

    With V0 the initial volume, V_in the cumulative inflow and V_out the cumulative outflow
    (open edges, sinks), the budget error at time t is::

        error = V_domain(t) - (V0 + V_in(t) - V_out(t))      [m3]
        error_rel = |error| / max(V0 + V_in(t), TINY_VOLUME_M3)

    (as LISFLOOD-FP's ``.mass`` file; ``docs/outputs.md``). The rows are kept (they go into
    checkpoints) and written by :meth:`write` when the run ends.
    """

    def __init__(self, volume_initial: float, rows: list[tuple[float, ...]] | None = None):
        self.volume_initial = float(volume_initial)
        self.rows: list[tuple[float, ...]] = list(rows or [])

    def budget(self, model) -> MassBudget:
        """The water budget of ``model`` now."""
        v_domain = float(model.volume())
        v_in = float(model.state.volume_in)
        v_out = float(model.state.volume_out)
        error = v_domain - (self.volume_initial + v_in - v_out)
        rel = abs(error) / max(self.volume_initial + v_in, TINY_VOLUME_M3)
        return MassBudget(v_domain, v_in, v_out, error, rel)

    def __call__(self, sim) -> None:
        b = self.budget(sim.model)
        self.rows.append((float(sim.model.t), b.volume_domain_m3, b.volume_in_m3,
                          b.volume_out_m3, b.error_m3, b.error_rel))

    def write(self, path: Path) -> Path:
        """Write the rows as ``mass_balance.csv`` at ``path`` (full precision, ``repr``)."""
        with open(path, "w", newline="", encoding="utf-8") as f:
            writer = csv.writer(f)
            writer.writerow(MASS_BALANCE_COLUMNS)
            writer.writerows([repr(value) for value in row] for row in self.rows)
        return Path(path)


@dataclass(frozen=True)
class MassBudget:
    """The water budget at one time [m3]; ``error_rel`` [-] (:class:`MassBalance`)."""

    volume_domain_m3: float
    volume_in_m3: float
    volume_out_m3: float
    error_m3: float
    error_rel: float


class Progress:
    """A tqdm bar over simulated time with dt, particle count and ETA.

    ``disable=None`` turns the bar off when stderr is not a terminal (logs, CI); ``enabled =
    False`` turns it off altogether (``--quiet``).
    """

    def __init__(self, end_time: float, enabled: bool = True):
        from tqdm import tqdm

        self.bar = tqdm(
            total=float(end_time),
            unit="s",
            unit_scale=False,
            disable=None if enabled else True,
            bar_format="{l_bar}{bar}| t={n:.4g}/{total:.4g} s [{elapsed}<{remaining}{postfix}]",
            dynamic_ncols=True,
        )

    def __call__(self, sim) -> None:
        self.bar.n = min(float(sim.model.t), self.bar.total)
        self.bar.set_postfix_str(f"dt={sim.last_dt:.3g} s, N={sim.n}", refresh=False)
        self.bar.refresh()

    def close(self) -> None:
        self.bar.close()


class ProgressLines:
    """Progress as lines, for a log: every ``percent`` % of the simulated time and at least
    every ``wall_s`` seconds of wall time (call it after every step).

    Each line (:func:`progress_line`) is an INFO record of the ``floodsph`` logger, marked for
    the run's ``floodsph.log`` only, and, when ``to_stderr``, also written to stderr: what a
    batch log or a redirected stderr gets in place of the progress bar, which draws only on
    a terminal.
    """

    def __init__(self, end_time: float, *, to_stderr: bool, percent: float = 10.0,
                 wall_s: float = 60.0):
        self.end_time = float(end_time)
        self.to_stderr = to_stderr
        self.step = self.end_time * percent / 100.0
        self.wall_s = wall_s
        self.next_time = self.step
        self.last_wall = 0.0

    def __call__(self, sim) -> None:
        t, wall = float(sim.model.t), float(sim.wall_time)
        if t < self.next_time - 1e-9 * self.end_time and wall - self.last_wall < self.wall_s:
            return
        while self.next_time <= t + 1e-9 * self.end_time:
            self.next_time += self.step
        self.last_wall = wall
        line = progress_line(sim)
        log.info("%s", line, extra={"file_only": True})
        if self.to_stderr:
            print(line, file=sys.stderr, flush=True)


def progress_line(sim) -> str:
    """``progress: t = 120 s of 1200 s (10 %), step 5400, dt = 0.02 s, 31000 particles,
    wall 95 s (1.26x real time), about 855 s to go``."""
    t, wall = float(sim.model.t), float(sim.wall_time)
    ratio = t / wall if wall > 0 else float("nan")
    left = (sim.end_time - t) / ratio if ratio > 0 else float("nan")
    return (f"progress: t = {t:.6g} s of {sim.end_time:g} s ({100.0 * t / sim.end_time:.0f} %), "
            f"step {sim.model.steps}, dt = {sim.last_dt:.3g} s, {sim.n} particles, wall "
            f"{wall:.0f} s ({ratio:.2f}x real time), about {left:.0f} s to go")
