"""The exact shallow-water solutions in floodsph.verification.exact satisfy the equations they
claim to.

Each solution is checked against the physics independently of its own formulas: finite
differences of the returned fields must satisfy the shallow-water equations, integrals must
conserve mass (and follow the momentum balance), and jumps must obey Rankine-Hugoniot.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from floodsph.verification.exact import (
    lake_at_rest,
    ritter,
    ritter_front,
    stoker,
    stoker_bore_position,
    stoker_middle_state,
    thacker_period,
    thacker_planar,
    thacker_shoreline,
)
from floodsph.verification.metrics import front_position, l1_relative, observed_order

G = 9.81


def _trapz(f, x):
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)))


def _swe_1d_residuals(solution, x, t, dx=1e-5, dt=1e-6):
    """Central-difference residuals of d_t + (du)_x and u_t + u u_x + g d_x (flat bed)."""
    d, u = solution(x, t)
    d_t = (solution(x, t + dt)[0] - solution(x, t - dt)[0]) / (2 * dt)
    u_t = (solution(x, t + dt)[1] - solution(x, t - dt)[1]) / (2 * dt)
    dp, up = solution(x + dx, t)
    dm, um = solution(x - dx, t)
    mass = d_t + (dp * up - dm * um) / (2 * dx)
    momentum = u_t + u * (up - um) / (2 * dx) + G * (dp - dm) / (2 * dx)
    return mass, momentum


# ----------------------------------------------------------------------------------------------
# Ritter
# ----------------------------------------------------------------------------------------------


def test_ritter_initial_step_and_front():
    d, u = ritter([-1.0, 0.0, 0.5], 0.0, 2.0, x_dam=0.0)
    assert d.tolist() == [2.0, 2.0, 0.0] and u.tolist() == [0.0, 0.0, 0.0]
    assert ritter_front(0.5, 1.0, x_dam=3.0) == pytest.approx(3.0 + 2 * math.sqrt(G) * 0.5)


def test_ritter_continuous_at_both_rarefaction_edges():
    d0, x_dam, t = 1.0, 2.0, 0.4
    c0 = math.sqrt(G * d0)
    eps = 1e-9
    for x_edge, d_edge in [(x_dam - c0 * t, d0), (x_dam + 2 * c0 * t, 0.0)]:
        d, u = ritter([x_edge - eps, x_edge + eps], t, d0, x_dam)
        assert d == pytest.approx([d_edge, d_edge], abs=1e-8)
    # u is continuous at the head; at the front the water reaches 2 c0 and dry bed carries 0
    u_head = ritter(x_dam - c0 * t + np.array([-eps, eps]), t, d0, x_dam)[1]
    assert u_head == pytest.approx([0.0, 0.0], abs=1e-8)
    assert ritter(x_dam + 2 * c0 * t - eps, t, d0, x_dam)[1] == pytest.approx(2 * c0, abs=1e-7)
    # the depth at the dam is the critical depth 4 d0 / 9 for all t > 0
    assert ritter(x_dam, t, d0, x_dam)[0] == pytest.approx(4 * d0 / 9, rel=1e-14)


def test_ritter_conserves_mass_and_follows_momentum_balance():
    d0, x_dam, x_back = 1.0, 2.0, -3.0
    x = np.linspace(x_back, 15.0, 400_001)
    for t in (0.1, 0.4, 0.6):
        d, u = ritter(x, t, d0, x_dam)
        assert _trapz(d, x) == pytest.approx(d0 * (x_dam - x_back), rel=1e-8)
        # d/dt of the momentum equals the hydrostatic force g d0^2 / 2 at the still end
        assert _trapz(d * u, x) == pytest.approx(G * d0**2 / 2 * t, rel=1e-6)


def test_ritter_satisfies_swe_by_finite_differences():
    d0, t = 1.0, 0.5
    c0 = math.sqrt(G * d0)
    xi = np.concatenate([np.linspace(-0.98 * c0, 1.98 * c0, 50), [-2 * c0, 3 * c0]])
    mass, momentum = _swe_1d_residuals(lambda x, s: ritter(x, s, d0), xi * t, t)
    assert np.max(np.abs(mass)) < 1e-4  # terms are O(c0 d0 / t) ~ 6 m/s
    assert np.max(np.abs(momentum)) < 1e-4


# ----------------------------------------------------------------------------------------------
# Stoker
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("d_r", [0.5, 0.1, 0.005])
def test_stoker_bore_satisfies_jump_conditions(d_r):
    d_l, x_dam, t = 1.0, 1.0, 2.0
    d_m, u_m, s = stoker_middle_state(d_l, d_r)
    x_b = float(stoker_bore_position(t, d_l, d_r, x_dam))
    assert x_b == pytest.approx(x_dam + s * t)
    (dm_, dr_), (um_, ur_) = stoker([x_b - 1e-9, x_b + 1e-9], t, d_l, d_r, x_dam)
    assert (dm_, um_, dr_, ur_) == (d_m, u_m, d_r, 0.0)
    # mass and momentum fluxes relative to the moving bore are continuous
    mass_jump = dm_ * (um_ - s) - dr_ * (ur_ - s)
    mom_jump = (dm_ * (um_ - s) ** 2 + G * dm_**2 / 2) - (dr_ * (ur_ - s) ** 2 + G * dr_**2 / 2)
    assert abs(mass_jump) < 1e-10 * d_l * s
    assert abs(mom_jump) < 1e-10 * G * d_l**2
    assert d_r < d_m < d_l and u_m > 0 and s > u_m


@pytest.mark.parametrize("d_r", [0.5, 0.1, 0.005])
def test_stoker_riemann_invariant_constant_through_rarefaction(d_r):
    d_l, t = 1.0, 2.0
    c_l = math.sqrt(G * d_l)
    d_m, u_m, s = stoker_middle_state(d_l, d_r)
    tail = u_m - math.sqrt(G * d_m)
    # left state, fan and middle state all carry u + 2c = 2 c_l
    x = np.linspace(-1.5 * c_l * t, 0.999 * s * t, 2001)
    d, u = stoker(x, t, d_l, d_r)
    assert np.max(np.abs(u + 2 * np.sqrt(G * d) - 2 * c_l)) < 1e-12 * c_l
    # and the fan joins the middle state continuously at its tail
    d_tail, u_tail = stoker(np.array([tail - 1e-9, tail + 1e-9]) * t, t, d_l, d_r)
    assert d_tail == pytest.approx([d_m, d_m], abs=1e-8)
    assert u_tail == pytest.approx([u_m, u_m], abs=1e-8)


def test_stoker_satisfies_swe_by_finite_differences_away_from_bore():
    d_l, d_r, t = 1.0, 0.1, 0.5
    d_m, u_m, s = stoker_middle_state(d_l, d_r)
    c_l, tail = math.sqrt(G * d_l), u_m - math.sqrt(G * d_m)
    xi = np.concatenate([np.linspace(-0.98 * c_l, tail - 0.02, 40), [tail + 0.1, 1.1 * s]])
    mass, momentum = _swe_1d_residuals(lambda x, s_: stoker(x, s_, d_l, d_r), xi * t, t)
    assert np.max(np.abs(mass)) < 1e-4
    assert np.max(np.abs(momentum)) < 1e-4


def test_stoker_conserves_mass_and_follows_momentum_balance():
    d_l, d_r, x_dam = 1.0, 0.2, 0.0
    x0, x1 = -20.0, 30.0
    x = np.linspace(x0, x1, 500_001)
    for t in (0.5, 2.0):
        d, u = stoker(x, t, d_l, d_r, x_dam)
        exact_mass = d_l * (x_dam - x0) + d_r * (x1 - x_dam)
        assert _trapz(d, x) == pytest.approx(exact_mass, rel=1e-6)  # bore jump inside a cell
        assert _trapz(d * u, x) == pytest.approx(G * (d_l**2 - d_r**2) / 2 * t, rel=1e-5)


def test_stoker_tends_to_ritter_as_downstream_depth_vanishes():
    x = np.linspace(-10.0, 20.0, 300_001)
    d_rit = ritter(x, 1.0, 1.0)[0]
    errs = [l1_relative(stoker(x, 1.0, 1.0, d_r)[0], d_rit) for d_r in (1e-2, 1e-4, 1e-6)]
    # measured: 2.6e-2, 8.2e-4, 2.7e-5 of the total volume
    assert errs[0] > errs[1] > errs[2] and errs[2] < 1e-4
    # the bore speed approaches the dry front speed 2 c0 only slowly: 95 % at d_r = 1e-6 d0
    ratio = stoker_bore_position(1.0, 1.0, 1e-6) / ritter_front(1.0, 1.0)
    assert 0.9 < ratio < 1.0
    assert stoker(x, 1.0, 1.0, 0.0)[0] == pytest.approx(d_rit, abs=0)


def test_stoker_rejects_inverted_depths():
    with pytest.raises(ValueError, match="d_right < d_left"):
        stoker_middle_state(1.0, 2.0)


# ----------------------------------------------------------------------------------------------
# Thacker
# ----------------------------------------------------------------------------------------------


def test_thacker_period_and_shoreline():
    T = thacker_period(10.0, 3000.0)
    assert T == pytest.approx(2 * math.pi * 3000.0 / math.sqrt(2 * G * 10.0))
    assert 1340 < T < 1350  # Thacker's period 2 pi a / sqrt(2 g h0) ~ 1345 s
    for t in (0.0, 0.3 * T, 0.8 * T):
        xc, yc, r = thacker_shoreline(t)
        assert thacker_planar(xc, yc, t)[0] == pytest.approx(10.0, rel=1e-12)
        theta = np.linspace(0, 2 * np.pi, 37)
        d_in = thacker_planar(xc + 0.999 * r * np.cos(theta), yc + 0.999 * r * np.sin(theta), t)
        d_out = thacker_planar(xc + 1.001 * r * np.cos(theta), yc + 1.001 * r * np.sin(theta), t)
        assert np.all(d_in[0] > 0) and np.all(d_out[0] == 0)
        assert np.all(d_out[1] == 0) and np.all(d_out[2] == 0)


def test_thacker_satisfies_swe_by_finite_differences():
    T = thacker_period()
    rng = np.random.default_rng(3)
    hx, ht = 1.0, 0.05
    for t in (0.1 * T, 0.45 * T, 0.7 * T):
        xc, yc, r = thacker_shoreline(t)
        rad, ang = 0.95 * r * np.sqrt(rng.random(200)), 2 * np.pi * rng.random(200)
        x, y = xc + rad * np.cos(ang), yc + rad * np.sin(ang)

        def f(dx=0.0, dy=0.0, dt=0.0, x=x, y=y, t=t):
            return thacker_planar(x + dx, y + dy, t + dt)

        d, u, v, b = f()
        assert np.all(d > 0)
        (dxp, uxp, vxp, bxp), (dxm, uxm, vxm, bxm) = f(dx=hx), f(dx=-hx)
        (dyp, uyp, vyp, byp), (dym, uym, vym, bym) = f(dy=hx), f(dy=-hx)
        (dtp, utp, vtp, _), (dtm, utm, vtm, _) = f(dt=ht), f(dt=-ht)
        mass = (
            (dtp - dtm) / (2 * ht)
            + (dxp * uxp - dxm * uxm) / (2 * hx)
            + (dyp * vyp - dym * vym) / (2 * hx)
        )
        Hx = (dxp + bxp - dxm - bxm) / (2 * hx)
        Hy = (dyp + byp - dym - bym) / (2 * hx)
        mom_x = (utp - utm) / (2 * ht) + u * (uxp - uxm) / (2 * hx) + v * (uyp - uym) / (2 * hx)
        mom_y = (vtp - vtm) / (2 * ht) + u * (vxp - vxm) / (2 * hx) + v * (vyp - vym) / (2 * hx)
        mom_x += G * Hx
        mom_y += G * Hy
        # individual terms are ~ 5e-2 m/s (mass) and ~ 3e-2 m/s2 (momentum)
        assert np.max(np.abs(mass)) < 1e-8
        assert np.max(np.abs(mom_x)) < 1e-8 and np.max(np.abs(mom_y)) < 1e-8
        assert np.max(np.abs(G * Hx)) > 1e-2  # the check is not vacuous


def test_thacker_wet_volume_is_constant():
    n, L = 800, 5000.0
    xs = np.linspace(-L, L, n + 1)
    xs = 0.5 * (xs[1:] + xs[:-1])
    X, Y = np.meshgrid(xs, xs)
    cell = (2 * L / n) ** 2
    exact = math.pi * 3000.0**2 * 10.0 / 2
    T = thacker_period()
    for t in (0.0, 0.2 * T, 0.55 * T, 0.9 * T):
        vol = thacker_planar(X, Y, t)[0].sum() * cell
        assert vol == pytest.approx(exact, rel=1e-4)


def test_thacker_returns_to_initial_state_after_one_period():
    # random points: a grid node lying exactly on the shoreline would flip wet/dry on round-off
    x, y = np.random.default_rng(5).uniform(-5000, 5000, (2, 2000))
    T = thacker_period()
    start, end = thacker_planar(x, y, 0.0), thacker_planar(x, y, T)
    half = thacker_planar(x, y, T / 2)
    for a0, a1 in zip(start, end, strict=True):
        assert a1 == pytest.approx(a0, abs=1e-9)
    assert np.max(np.abs(half[0] - start[0])) > 1.0  # the state did move in between
    assert start[1][start[0] > 0] == pytest.approx(0.0, abs=1e-12)
    assert start[2][start[0] > 0] == pytest.approx(-1500.0 * 2 * math.pi / T)


def test_thacker_without_oscillation_is_lake_at_rest():
    x, y = np.meshgrid(np.linspace(-4000, 4000, 21), np.linspace(-4000, 4000, 21))
    d, u, v, bed = thacker_planar(x, y, 123.0, eta=0.0)
    d_lake, u_lake, v_lake = lake_at_rest(bed, 10.0)
    assert d == pytest.approx(d_lake, abs=1e-12)
    assert np.all(u == 0) and np.all(v == 0) and np.all(u_lake == 0) and np.all(v_lake == 0)


# ----------------------------------------------------------------------------------------------
# Lake at rest and error measures
# ----------------------------------------------------------------------------------------------


def test_lake_at_rest_clips_dry_bed():
    d, u, v = lake_at_rest(np.array([0.0, 1.0, 2.5]), 2.0)
    assert d.tolist() == [2.0, 1.0, 0.0]
    assert u.tolist() == [0.0] * 3 and v.tolist() == [0.0] * 3


def test_l1_relative_on_hand_made_arrays():
    exact = np.array([1.0, 2.0, 3.0, 0.0])
    num = np.array([1.5, 2.0, 2.0, 0.5])
    assert l1_relative(num, exact) == pytest.approx(2.0 / 6.0)
    w = np.array([2.0, 1.0, 1.0, 4.0])
    assert l1_relative(num, exact, w) == pytest.approx((1.0 + 1.0 + 2.0) / 7.0)
    with pytest.raises(ValueError, match="zero"):
        l1_relative(num, np.zeros(4))


def test_front_position_on_hand_made_arrays():
    x = np.array([3.0, 0.0, 1.0, 2.0, 4.0])
    d = np.array([0.05, 1.0, 0.5, 0.2, 0.0])
    assert front_position(x, d, 0.1) == 2.0
    assert front_position(x, d, 0.01) == 3.0
    assert math.isnan(front_position(x, d, 5.0))
    # against Ritter on a fine grid: within one grid spacing of the exact front
    xg = np.linspace(-1, 10, 11001)
    xf = front_position(xg, ritter(xg, 0.5, 1.0)[0], 0.0)
    assert abs(xf - ritter_front(0.5, 1.0)) <= xg[1] - xg[0]


def test_observed_order_on_hand_made_arrays():
    h = np.array([20.0, 10.0, 5.0, 2.5])
    assert observed_order(3.0 * h**2, h) == pytest.approx(2.0, rel=1e-12)
    assert observed_order(0.1 * h**1.5, h) == pytest.approx(1.5, rel=1e-12)
    # least squares through noisy data: log e = [0, -1, -2.2, -2.9] vs log h
    e = np.exp(np.array([0.0, -1.0, -2.2, -2.9]))
    lh, le = np.log(h), np.log(e)
    slope = np.sum((lh - lh.mean()) * (le - le.mean())) / np.sum((lh - lh.mean()) ** 2)
    assert observed_order(e, h) == pytest.approx(slope, rel=1e-12)
    with pytest.raises(ValueError):
        observed_order([1.0], [1.0])
