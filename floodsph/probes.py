"""Run-time callbacks: the mass-balance table, the progress bar and the progress log.

Each is a callable taking the :class:`~floodsph.simulation.Simulation`; the run pairs it with
a schedule (``floodsph.run``).
"""

from __future__ import annotations

import csv
import logging
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

    (flood-practice.md 1.5; LISFLOOD-FP's ``.mass`` file). Each row is flushed as written, so
    the table of an interrupted run is readable up to its last row.
    """

    def __init__(self, path: Path, volume_initial: float):
        self.path = Path(path)
        self.volume_initial = float(volume_initial)
        self.error_rel = 0.0
        self._file = open(self.path, "w", newline="", encoding="utf-8")
        self._writer = csv.writer(self._file)
        self._writer.writerow(MASS_BALANCE_COLUMNS)

    def budget(self, model) -> tuple[float, float, float, float, float]:
        """(V_domain, V_in, V_out, error, error_rel) of ``model`` now [m3, -]."""
        v_domain = float(model.volume())
        v_in = float(model.volume_in)
        v_out = float(model.volume_out)
        error = v_domain - (self.volume_initial + v_in - v_out)
        rel = abs(error) / max(self.volume_initial + v_in, TINY_VOLUME_M3)
        return v_domain, v_in, v_out, error, rel

    def __call__(self, sim) -> None:
        v_domain, v_in, v_out, error, rel = self.budget(sim.model)
        self.error_rel = rel
        self._writer.writerow(
            [repr(float(sim.model.t)), repr(v_domain), repr(v_in), repr(v_out), repr(error),
             repr(rel)]
        )
        self._file.flush()

    def close(self) -> None:
        self._file.close()


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


def log_progress(sim) -> None:
    """One INFO line: simulated time, dt, particles, wall time and the sim/wall ratio."""
    wall = sim.wall_time
    ratio = sim.model.t / wall if wall > 0 else float("nan")
    log.info(
        "t = %.6g s of %g s, step %d, dt = %.3g s, %d particles, wall %.1f s (%.2fx real time)",
        sim.model.t,
        sim.end_time,
        sim.model.steps,
        sim.last_dt,
        sim.n,
        wall,
        ratio,
    )
