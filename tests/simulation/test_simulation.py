"""The time loop: schedules, time-step alignment, start/end calls and the state guard."""

from __future__ import annotations

import numpy as np
import pytest

from floodsph.model.particles import ParticleSet
from floodsph.simulation.loop import Simulation, SimulationError
from floodsph.simulation.schedules import IterationInterval, TimeInterval, WallTimeInterval


class StubModel:
    """A model with a fixed preferred step; depth can be poisoned at a given step."""

    def __init__(self, dt=0.7, n=4, poison_step=None, poison_value=np.nan):
        self.dt = dt
        self.t = 0.0
        self.steps = 0
        self.particles = ParticleSet(8)
        self.particles.append(x=np.arange(n, dtype=float), y=np.zeros(n), m=np.ones(n),
                              rho=np.full(n, 1000.0), h=np.ones(n))
        self.poison_step = poison_step
        self.poison_value = poison_value
        self.dt_max_seen = []

    def step(self, dt_max=None):
        self.dt_max_seen.append(dt_max)
        dt = self.dt if dt_max is None else min(self.dt, dt_max)
        self.t += dt
        self.steps += 1
        if self.steps == self.poison_step:
            self.particles.rho[1] = self.poison_value
        return dt

    def depth(self):
        return self.particles.rho / 1000.0


def recorder(log):
    return lambda sim: log.append((sim.model.steps, sim.model.t))


def test_time_interval_lands_exactly_on_output_times():
    model = StubModel(dt=0.7)
    log = []
    Simulation(model, 10.0, [(recorder(log), TimeInterval(2.0))]).run()
    # Called at the start, then at 2, 4, 6, 8, 10 s: every time hit to round-off.
    times = [t for _, t in log]
    assert times == pytest.approx([0.0, 2.0, 4.0, 6.0, 8.0, 10.0], abs=1e-12)
    assert model.t == pytest.approx(10.0, abs=1e-12)
    # Each 2 s interval takes 0.7 + 0.7 + 0.6 s: only the step before a target is shortened.
    assert model.steps == 15


def test_unaligned_time_interval_samples_without_shortening_steps():
    """A sampling callback (the map envelopes) runs at the first step at or after each
    mark; only the end time cuts a step: 0.96 s steps over 10 s take 11 steps, not 20."""
    model = StubModel(dt=0.96)
    log = []
    Simulation(model, 10.0, [(recorder(log), TimeInterval(1.0, align=False))]).run()
    assert model.steps == 11 and model.t == pytest.approx(10.0, abs=1e-12)
    times = [t for _, t in log]
    assert times == pytest.approx([0.0, *(0.96 * np.arange(2, 11)), 10.0], abs=1e-12)
    assert all(a >= k for k, a in zip(range(1, 10), times[1:], strict=False))


def test_end_time_not_a_multiple_of_the_interval():
    model = StubModel(dt=1.0)
    log = []
    Simulation(model, 5.5, [(recorder(log), TimeInterval(2.0))]).run()
    # 0, 2, 4 on schedule, then once more for the final state at 5.5.
    assert [t for _, t in log] == pytest.approx([0.0, 2.0, 4.0, 5.5])
    assert model.steps == 6  # 1,1,1,1,1,0.5


def test_iteration_interval_and_single_final_call():
    model = StubModel(dt=1.0)
    log = []
    Simulation(model, 7.0, [(recorder(log), IterationInterval(3))]).run()
    # start (step 0), steps 3 and 6 on schedule, final state at step 7.
    assert [s for s, _ in log] == [0, 3, 6, 7]


def test_final_call_not_repeated_when_due_on_last_step():
    model = StubModel(dt=1.0)
    log = []
    Simulation(model, 6.0, [(recorder(log), IterationInterval(3))]).run()
    assert [s for s, _ in log] == [0, 3, 6]


def test_max_steps_stops_early():
    model = StubModel(dt=1.0)
    sim = Simulation(model, 100.0, [], max_steps=4)
    sim.run()
    assert model.steps == 4 and model.t == 4.0


def test_wall_time_interval_not_due_immediately():
    schedule = WallTimeInterval(3600.0)
    assert not schedule.due(None)


@pytest.mark.parametrize(
    ("value", "text"), [(np.nan, "non-finite depth"), (-5.0, "negative depth")]
)
def test_guard_names_step_and_time(value, text):
    model = StubModel(dt=0.5, poison_step=3, poison_value=value)
    with pytest.raises(SimulationError) as err:
        Simulation(model, 10.0).run()
    message = str(err.value)
    assert message.startswith("step 3 (t = 1.5 s)")
    assert text in message
    assert "particle id 1" in message


def test_stalled_time_step_is_an_error():
    model = StubModel(dt=0.0)
    with pytest.raises(SimulationError, match="step 1 .*time step is 0.0"):
        Simulation(model, 1.0).run()
