"""The balanced momentum's blend with the variational force and the release of still water
(``floodsph.sph.momentum_blend``)."""

import numpy as np

from floodsph.sph.level_momentum import BLEND_SPEED, EDGE_SPEED, HOLD_LEVEL
from floodsph.sph.level_offsets import BANKED, FREE, HELD, RELEASED
from floodsph.sph.momentum_blend import blend, release, variational_weights


def test_the_weight_rises_smoothly_from_rest_to_the_blend_speed():
    speed = np.array([0.0, 0.25, 0.5, 0.75, 1.0, 3.0]) * BLEND_SPEED
    u, v = speed * 0.6, speed * 0.8
    weight = np.empty(speed.size)
    variational_weights(np.arange(speed.size), u, v, weight)
    # smoothstep s^2 (3 - 2 s): 0 at rest, 1/2 at half the blend speed, 1 from it on
    np.testing.assert_allclose(weight, [0.0, 0.15625, 0.5, 0.84375, 1.0, 1.0], atol=1e-12)
    assert weight[0] == 0.0 and weight[-1] == 1.0


def test_still_water_is_banked_when_its_level_moves_and_released_when_it_moves():
    state = np.array([HELD, HELD, HELD, BANKED, BANKED, FREE, RELEASED, HELD], dtype=np.int64)
    fast = 2.0 * EDGE_SPEED
    u = np.array([0.0, 0.0, fast, 0.0, fast, fast, fast, fast])
    departed = np.array([0.0, 2.0, 0.0, 2.0, 0.0, 2.0, 0.0, 2.0]) * HOLD_LEVEL
    eta_seed = np.full(state.size, 50.0)
    eta = eta_seed + departed
    rows = np.arange(state.size, dtype=np.int64)
    release(rows, u, np.zeros(state.size), eta, eta_seed, state)
    assert state.tolist() == [HELD, BANKED, RELEASED, BANKED, RELEASED, FREE, RELEASED,
                              RELEASED]
    # a particle not among the rows keeps its state
    kept = np.array([HELD], dtype=np.int64)
    release(np.zeros(0, dtype=np.int64), np.array([fast]), np.zeros(1), eta[:1] + 1.0,
            eta_seed[:1], kept)
    assert kept[0] == HELD


def test_the_blend_is_the_variational_force_at_full_weight_and_linear_between():
    ax = np.array([1.0, 1.0, 5.0])  # the balanced accelerations
    ay = np.array([-2.0, -2.0, 0.0])
    divv = np.array([0.5, 0.5, 0.0])
    moving = np.array([0, 1], dtype=np.int64)
    blend(moving, np.array([1.0, 0.25]), np.array([3.0, 3.0]), np.array([2.0, 2.0]),
          np.array([-0.5, -0.5]), ax, ay, divv)
    assert (ax[0], ay[0], divv[0]) == (3.0, 2.0, -0.5)
    np.testing.assert_allclose((ax[1], ay[1], divv[1]), (1.5, -1.0, 0.25))
    assert (ax[2], ay[2], divv[2]) == (5.0, 0.0, 0.0)  # not moving: untouched
