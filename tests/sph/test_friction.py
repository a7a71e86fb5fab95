"""Manning friction: the implicit step keeps the terminal (normal-flow) speed at any time step."""

import numpy as np
import pytest
from sph_cases import model_on

from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.scenario.numerics import Momentum, TimeStepping
from floodsph.sph import time_step

N, D = 0.05, 0.2  # Manning n [s m-1/3], depth [m]


@pytest.mark.parametrize("beta_e", [0.01, 0.1, 0.5, 2.0])
def test_a_steady_kick_and_friction_settle_at_the_manning_speed_for_any_step(beta_e):
    """v <- f (v + dt a), with a the gravity pull that Manning friction balances at u_e,
    has the fixed point u_e whatever beta_e = dt g n^2 u_e / d^(4/3): the point-implicit
    factor 1 / (1 + beta) settles 5 % low at beta_e = 0.1 and 38 % low at 1."""
    u_e = 0.7
    k = GRAVITY * N * N / D ** (4.0 / 3.0)
    a = k * u_e * u_e
    dt = beta_e / (k * u_e)
    u = 0.0
    for _ in range(2000):
        u += dt * a
        u *= time_step.friction_factor(u, 0.0, RHO_WATER * D, N, dt, 0.01)
    assert u == pytest.approx(u_e, rel=1e-9)


@pytest.mark.parametrize("stepping", list(TimeStepping))
def test_sheet_flow_down_a_plane_reaches_the_manning_normal_speed(stepping):
    """A 0.2 m sheet on a 1 % slope, n = 0.05, between channel walls: in its middle the flow
    is uniform and, after 40 s (six relaxation times u_e / (g S)), runs at Manning's normal speed
    u = d^(2/3) sqrt(S') / n with S' = S / (1 + S^2) (the bed term of floodsph.sph.forces).
    A 25 m deep still pool behind a wall sets the step to 0.11 s. With local steps the sheet
    takes strides of 8 (0.88 s, beta_e = 0.13), where the point-implicit factor ran 6.1 %
    slow (measured). The variational momentum: under the balanced one the pool's finest step
    differs and the sheet takes strides of 4."""
    slope = 0.01
    pool = [np.array([[1600.0, 0.0], [1600.0, 200.0]])]

    def bed(x, y):
        return np.where(x < 1600, -slope * x, 0.0)

    def depth(x, y):
        return np.where((x > 100) & (x < 600), D, np.where(x > 1600, 25.0, 0.0))

    model = model_on(bed, (0, 1800), (0, 200), 5.0, depth, 5.0, manning=N, walls=pool,
                     time_stepping=stepping, momentum=Momentum.VARIATIONAL)
    while model.t < 40.0:  # full (big) steps, so that the strides are those of a full one
        model.step()
    p = model.particles
    middle = (p.x > 330) & (p.x < 430) & (p.y > 50) & (p.y < 150)  # moved by about 27 m
    d_mid = p.rho[middle] / RHO_WATER
    u_normal = d_mid ** (2.0 / 3.0) * np.sqrt(slope / (1 + slope**2)) / N
    assert np.abs(d_mid - D).max() < 0.01 * D  # the middle is still uniform
    assert np.abs(p.u[middle] / u_normal - 1.0).max() < 0.02
    assert np.abs(p.v[middle]).max() < 0.01
    if stepping is TimeStepping.LOCAL:
        assert np.all(p.stride[middle] == 8)
