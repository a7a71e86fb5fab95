"""A run-time range printed by ``floodsph check``, and the warnings of a run that is huge.

The cost of a run is its particle-steps: particles x time steps. The steps follow from the
end time and the CFL condition of the fastest water,

    dt = cfl h / (|u| + c),    c = sqrt(g d),    |u| + c ~ 2 sqrt(g d_max)

(a dam break's front runs at about 2 sqrt(g d0), Ritter's solution), with h = kappa dx and
d_max the deepest initial water or the critical depth (q^2 / g)^(1/3) of an inflow's peak
unit discharge q = Q_peak / L. The particles lie between the initial count and the memory
estimate's peak (``floodsph.inputs.memory``). With local time steps (the default) a particle
is updated at its own step, a multiple of the finest: the updates are
:data:`LOCAL_UPDATE_FRACTION` of the global-step count (measured 0.31 and 0.34 on Malpasset,
0.45 on EA test 4, 0.72 on Ritter's dam break). The throughput is stated as a range,
:data:`THROUGHPUT_PER_THREAD` particle-steps per second per thread (measured on the project
machine: 0.6 million on the sample with the default settings, 1.7-2.5 million on two
threads for a block of 100,000 particles, 0.14 million with ``refinement = "split"`` on
Malpasset; ``docs/measurements.md``), with a parallel efficiency of
:data:`PARALLEL_EFFICIENCY` per added thread.

On the sample (``data_samples/valley``, one thread) the range is 3-63 s (3,605 steps) for a
run measured at 24.5 s (2,326 steps); on the conftest valley 50 steps for 34; on Malpasset
(sea as particles) 2-43 min on one thread (25,809 steps) for a run of 396 s (20,958 steps).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from floodsph.constants import GRAVITY
from floodsph.errors import warn
from floodsph.sph.kernels import seeded_smoothing_length

#: Particle-steps per second of one thread: (slow, fast).
THROUGHPUT_PER_THREAD = (0.25e6, 1.0e6)
#: Each thread beyond the first adds this fraction of one.
PARALLEL_EFFICIENCY = 0.7
#: Particle updates with local time steps, as a fraction of particles x finest steps.
LOCAL_UPDATE_FRACTION = (0.3, 0.75)
#: Above this many particles at peak, ``check`` and ``run`` warn.
HUGE_PARTICLES = 5_000_000
#: A spacing below this fraction of the DEM cell is warned of: it resolves no more terrain.
SUB_CELL_FRACTION = 0.25


@dataclass(frozen=True)
class RunTimeEstimate:
    """The expected time steps and the wall-time range [s] of a run."""

    steps: int
    particle_steps: tuple[float, float]
    wall_s: tuple[float, float]
    threads: int

    def text(self) -> str:
        low, high = self.wall_s
        return (f"~{format_duration(low)} to {format_duration(high)} on {self.threads} "
                f"thread{'s' if self.threads != 1 else ''} (about {self.steps:,} steps, "
                f"{self.particle_steps[0]:.2g}-{self.particle_steps[1]:.2g} particle-steps "
                f"at {THROUGHPUT_PER_THREAD[0] / 1e6:g}-{THROUGHPUT_PER_THREAD[1] / 1e6:g} "
                "million per second per thread)")


def estimate_run_time(scenario, inputs, threads: int) -> RunTimeEstimate:
    """The run-time range of ``scenario`` from its prepared ``inputs`` (formula above)."""
    spacing = inputs.spacing_m
    depth = float(np.max(inputs.depth)) if inputs.depth.size else 0.0
    for inflow, hydrograph in zip(scenario.inflows, inputs.hydrographs, strict=True):
        length = math.dist(*inflow.line)
        q = float(np.max(hydrograph.Q)) / max(length, spacing)
        depth = max(depth, (q * q / GRAVITY) ** (1.0 / 3.0))
    speed = 2.0 * math.sqrt(GRAVITY * max(depth, 0.1))
    dt = scenario.numerics.cfl * seeded_smoothing_length(scenario.numerics.kappa, spacing) / speed
    steps = max(1, math.ceil(scenario.end_time_s / dt))
    particles = (max(inputs.particles.n, 1), max(inputs.memory.particles_peak,
                                                 inputs.particles.n, 1))
    local = scenario.numerics.time_stepping.value == "local"
    fraction = LOCAL_UPDATE_FRACTION if local else (1.0, 1.0)
    work = (steps * particles[0] * fraction[0], steps * particles[1] * fraction[1])
    threads = max(1, int(threads))
    effective = 1.0 + PARALLEL_EFFICIENCY * (threads - 1)
    slow, fast = THROUGHPUT_PER_THREAD
    return RunTimeEstimate(steps, work, (work[0] / (fast * effective),
                                         work[1] / (slow * effective)), threads)


def run_threads(scenario) -> int:
    """The numba threads a run of ``scenario`` gets: ``numerics.threads``, or for 0 the
    ``NUMBA_NUM_THREADS`` set (``floodsph --threads N`` sets it) or the cores."""
    import os

    if scenario.numerics.threads > 0:
        told = scenario.numerics.threads
    else:
        told = int(os.environ.get("NUMBA_NUM_THREADS", "0") or 0)
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (
        os.cpu_count() or 1)
    env = os.environ.get("NUMBA_NUM_THREADS", "")
    limit = int(env) if env.isdigit() and int(env) > 0 else cores
    return max(1, min(told, limit) if told > 0 else limit)


def warn_if_huge(scenario, spacing: float, cell: float, particles_peak: int, source: str,
                 warnings: list[str] | None) -> None:
    """Warn of a run with more than :data:`HUGE_PARTICLES` particles at peak, and of a
    spacing finer than :data:`SUB_CELL_FRACTION` of the DEM cell."""
    if particles_peak > HUGE_PARTICLES:
        warn(f"{source}: numerics.particle_spacing_m = {spacing:g} m gives about "
             f"{particles_peak:,} particles at peak: expect hours to days of run time "
             "(floodsph check prints an estimate); a coarser spacing first is advised",
             warnings)
    if spacing < SUB_CELL_FRACTION * cell:
        warn(f"{source}: numerics.particle_spacing_m = {spacing:g} m is finer than a quarter "
             f"of the DEM cell ({cell:g} m): the particles resolve no terrain the DEM does not "
             "have, at (cell / spacing)^2 = "
             f"{(cell / spacing) ** 2:.3g} times the particles of one per cell", warnings)


def format_duration(seconds: float) -> str:
    """``under 1 s``, ``42 s``, ``12 min``, ``3.5 h``, ``2.1 days``."""
    if seconds < 1:
        return "under 1 s"
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    if seconds < 172800:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 86400:.1f} days"
