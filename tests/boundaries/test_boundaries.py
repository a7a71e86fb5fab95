"""Open boundaries: inflow sections, open edges (outflow) and sinks.

Physical facts asserted: the boundary state solves the Riemann and discharge conditions;
injected volume equals the hydrograph integral; normal flow in a sloping channel stays normal
between an inflow and an outflow; still water at an open edge stays; waves leave through open
edges as if the domain went on (supercritical Ritter and subcritical Stoker flows); sinks
absorb and count water.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from sph_cases import lattice, particles_with_depth, run_until

from floodsph.boundaries import Inflow, Sink
from floodsph.boundaries.inflow import lattice_alpha_ratio
from floodsph.boundaries.open_edges import SIDES
from floodsph.boundaries.riemann import critical_depth, inflow_state
from floodsph.constants import GRAVITY
from floodsph.errors import InputError
from floodsph.io.hydrograph import Hydrograph
from floodsph.model.builder import set_up_model
from floodsph.model.terrain import Terrain
from floodsph.scenario.numerics import Numerics
from floodsph.verification import exact, metrics
from floodsph.walls.openings import cut_openings

G = GRAVITY
KAPPA = Numerics.kappa


# -- the boundary state --------------------------------------------------------------------------
@pytest.mark.parametrize("q, d_i, w_i", [(2.0, 3.0, 0.5), (14.645, 5.0, 2.929), (0.5, 8.0, -0.2)])
def test_subcritical_state_solves_discharge_and_riemann_invariant(q, d_i, w_i):
    d, w, regime = inflow_state(q, d_i, w_i)
    assert regime == "subcritical"
    assert d * w == pytest.approx(q, rel=1e-12)
    invariant = w_i - 2 * math.sqrt(G * d_i)
    assert w - 2 * math.sqrt(G * d) == pytest.approx(invariant, rel=1e-10, abs=1e-12)
    assert w < math.sqrt(G * d)


def test_uniform_flow_state_is_the_interior_state():
    d, w, _ = inflow_state(14.645, 5.0, 14.645 / 5.0)
    assert d == pytest.approx(5.0, rel=1e-10)
    assert w == pytest.approx(2.929, rel=1e-10)


def test_dry_interior_and_supercritical_roots_give_critical_flow():
    d, w, regime = inflow_state(1.0, 0.0, 0.0)
    assert regime == "critical"
    assert d == pytest.approx((1.0 / G) ** (1 / 3), rel=1e-12)
    assert w == pytest.approx(math.sqrt(G * d), rel=1e-12)  # Froude number 1
    # a fast shallow interior: the subcritical root does not exist, flow is critical
    assert inflow_state(1.0, 0.05, 10.0)[2] == "critical"
    assert critical_depth(20.0 / 20.0) == pytest.approx(0.4672, abs=1e-4)


def test_closed_section_without_discharge_holds_water():
    d, w, regime = inflow_state(0.0, 2.0, 0.0)
    assert (regime, w) == ("closed", 0.0)
    assert d == pytest.approx(2.0)
    assert inflow_state(0.0, 0.0, 0.0)[0] == 0.0


def test_lattice_alpha_ratio_matches_the_solver_on_a_lattice():
    """alpha / rho of the buffer equals the value the density solve gives inside a lattice."""
    terrain = Terrain.from_function(lambda x, y: 0 * x, (0, 200), (0, 200), 5.0)
    x, y = lattice(0, 200, 0, 200, 10.0)
    model = set_up_model(terrain, particles_with_depth(x, y, np.full(x.shape, 2.0), 10.0, KAPPA),
                       Numerics(particle_spacing_m=10.0))
    p = model.particles
    centre = np.argmin(np.hypot(p.x - 100, p.y - 100))
    assert lattice_alpha_ratio(10.0, 10.0, p.h[centre]) == pytest.approx(
        p.alpha[centre] / p.rho[centre], rel=1e-3)  # the density solve's tolerance
    assert abs(lattice_alpha_ratio(10.0, 10.0, 13.0) - 2.0) > 0.02  # not the continuum 2


# -- geometry ------------------------------------------------------------------------------------
def test_cut_openings_removes_exactly_the_opening():
    box = np.array([[0, 100, 0, 0], [0, 0, 300, 0]], dtype=float)  # west side, south side
    out = cut_openings(box, [np.array([[0.0, 40.0], [0.0, 60.0]])], 1e-9)
    lengths = np.hypot(out[:, 2] - out[:, 0], out[:, 3] - out[:, 1])
    assert lengths.sum() == pytest.approx(380.0)
    assert len(out) == 3  # the west side in two pieces, the south side untouched
    west = out[np.isclose(out[:, 0], 0) & np.isclose(out[:, 2], 0)]
    assert sorted(np.round(np.sort(west[:, [1, 3]], axis=1).ravel())) == [0, 40, 60, 100]


def _flat(width, height, cell=5.0, manning=0.0):
    return Terrain.from_function(lambda x, y: 0 * x, (0, width), (0, height), cell,
                                 manning=manning)


def test_inflow_refuses_bad_lines():
    terrain = _flat(100, 100)
    hg = Hydrograph([0.0, 10.0], [1.0, 1.0])
    with pytest.raises(InputError, match=r"inflows\[2\].line: .*zero-length"):
        Inflow([[10, 10], [10, 10]], hg, 5.0, KAPPA, terrain, name="inflows[2]")
    with pytest.raises(InputError, match=r"inflows\[0\]: the ground is level.*direction"):
        Inflow([[50, 20], [50, 80]], hg, 5.0, KAPPA, terrain)
    with pytest.raises(InputError, match=r"inflows\[0\].direction: .*parallel"):
        Inflow([[50, 20], [50, 80]], hg, 5.0, KAPPA, terrain, direction=[0, 1])


def test_inflow_enters_towards_lower_ground_or_off_the_dem_edge():
    slope = Terrain.from_function(lambda x, y: 0.01 * x, (0, 200), (0, 100), 5.0)
    hg = Hydrograph([0.0, 10.0], [1.0, 1.0])
    inflow = Inflow([[100, 20], [100, 80]], hg, 5.0, KAPPA, slope)
    assert inflow.normal == pytest.approx([-1.0, 0.0])  # towards lower ground (west)
    edge = Inflow([[0, 40], [0, 60]], hg, 5.0, KAPPA, _flat(200, 100))
    assert edge.normal == pytest.approx([1.0, 0.0])  # into the DEM from its west edge


# -- inflow: exact volume ------------------------------------------------------------------------
def test_floodplain_inflow_injects_the_hydrograph_volume():
    """A 20 m opening in the west edge of a flat floodplain (n = 0.05), trapezoidal
    hydrograph 0 -> 20 m3/s -> 0: the injected volume follows the integral of Q within one
    buffer row at all times and equals it once the hydrograph ends; the domain holds exactly
    what was injected; the front advances monotonically."""
    dx = 2.5
    terrain = _flat(200, 200, cell=5.0, manning=0.05)
    hg = Hydrograph([0.0, 30.0, 150.0, 180.0], [0.0, 20.0, 20.0, 0.0])
    inflow = Inflow([[0, 90], [0, 110]], hg, dx, KAPPA, terrain)
    model = set_up_model(terrain, particles_with_depth(np.zeros(0), np.zeros(0), np.zeros(0), dx,
                                                     KAPPA), Numerics(particle_spacing_m=dx),
                       boundaries=[inflow])
    row = critical_depth(1.0) * 20.0 * dx  # volume of one buffer row at the peak [m3]
    fronts, lags = [], []
    for t in np.arange(10.0, 241.0, 10.0):
        run_until(model, t)
        lags.append(hg.volume(0.0, t) - model.state.volume_in)
        p = model.particles
        fronts.append(np.hypot(p.x, p.y - 100.0).max() if p.n else 0.0)
        assert model.volume() == pytest.approx(model.state.volume_in, rel=1e-12)
    assert np.abs(lags).max() < row
    assert model.state.volume_in == pytest.approx(hg.total_volume(), rel=1e-9)
    assert model.state.volume_out == 0.0
    assert np.all(np.diff(fronts) > 0.0)
    assert fronts[-1] < 200.0  # no particle left the inlet area the wrong way or escaped


@pytest.mark.parametrize("times, discharges", [
    ([0.0, 40.0], [0.01, 0.01]),                      # a trickle: 1 l/s per 2 m of section
    ([0.0, 2.0, 30.0, 32.0], [0.0, 50.0, 50.0, 0.0]),  # rises to the peak in 2 s
], ids=["trickle", "rise-in-seconds"])
def test_injected_volume_matches_the_hydrograph_from_trickle_to_steep_rise(times, discharges):
    dx = 2.5
    terrain = _flat(120, 100, cell=5.0, manning=0.03)
    hg = Hydrograph(times, discharges)
    inflow = Inflow([[0, 40], [0, 60]], hg, dx, KAPPA, terrain)
    empty = particles_with_depth(np.zeros(0), np.zeros(0), np.zeros(0), dx, KAPPA)
    model = set_up_model(terrain, empty, Numerics(particle_spacing_m=dx), boundaries=[inflow])
    for t in np.linspace(5.0, times[-1], 8):
        run_until(model, t)
        v = hg.volume(0.0, t)
        row = critical_depth(hg.discharge(t) / 20.0) * 20.0 * dx
        assert abs(model.state.volume_in - v) <= max(row, 0.005 * v), t
        assert model.volume() == pytest.approx(model.state.volume_in, rel=1e-12)
    run_until(model, times[-1] + 2.0)
    assert model.state.volume_in == pytest.approx(hg.volume(0.0, model.t), rel=0.005)


# -- outflow ------------------------------------------------------------------------------------
def test_still_water_at_an_open_edge_does_not_drain():
    terrain = _flat(300, 100)
    x, y = lattice(0, 300, 0, 100, 10.0)
    model = set_up_model(terrain, particles_with_depth(x, y, np.full(x.shape, 2.0), 10.0, KAPPA),
                       Numerics(particle_spacing_m=10.0), closed_sides=("south", "north", "west"))
    v0 = model.volume()
    run_until(model, 200.0)
    p = model.particles
    assert model.state.volume_out < 1e-6 * v0
    assert np.hypot(p.u, p.v).max() < 0.01
    assert np.abs(model.depth() - 2.0).max() < 0.02


def test_uniform_flow_in_a_sloping_channel_stays_normal():
    """S0 = 0.001, n = 0.0316, q = 14.645 m2/s: normal depth 5 m, velocity 2.929 m/s.
    Inflow upstream, open edge downstream: reach-averaged depth and velocity stay within 3 %
    of normal for 200 s, including the reaches at both boundaries."""
    dx, length, width = 10.0, 1000.0, 100.0
    s0, n, q, d0 = 0.001, 0.0316, 14.645, 5.0
    terrain = Terrain.from_function(lambda x, y: -s0 * x, (0, length), (0, width), 5.0,
                                    manning=n)
    x, y = lattice(0, length, 0, width, dx)
    particles = particles_with_depth(x, y, np.full(x.shape, d0), dx, KAPPA, u=q / d0)
    inflow = Inflow([[0, 0], [0, width]], Hydrograph([0.0, 1e6], [q * width] * 2), dx, KAPPA,
                    terrain)
    model = set_up_model(terrain, particles, Numerics(particle_spacing_m=dx),
                       closed_sides=("south", "north", "west"), boundaries=[inflow])
    for t in (50.0, 100.0, 150.0, 200.0):
        run_until(model, t)
        p, d = model.particles, model.depth()
        for lo in np.arange(0.0, length, 100.0):
            reach = (p.x >= lo) & (p.x < lo + 100.0)
            assert d[reach].mean() == pytest.approx(d0, rel=0.03), (t, lo)
            assert p.u[reach].mean() == pytest.approx(q / d0, rel=0.03), (t, lo)
    # volume balance: what is in the channel is what it started with, plus in, minus out
    v_expected = length * width * d0 + model.state.volume_in - model.state.volume_out
    assert model.volume() == pytest.approx(v_expected, rel=1e-12)


def _dam_break(length, d_left, d_right, closed, dx=10.0):
    terrain = _flat(length, 40.0, cell=10.0)
    x, y = lattice(0, length, 0, 40.0, dx)
    depth = np.where(x < 1000.0, d_left, d_right)
    wet = depth > 0
    return set_up_model(terrain, particles_with_depth(x[wet], y[wet], depth[wet], dx, KAPPA),
                      Numerics(particle_spacing_m=dx), closed_sides=closed)


def _profile(model, xq):
    from floodsph.output.rasterise import interpolate

    p = model.particles
    d = interpolate(xq, np.full(xq.shape, 20.0), p.x, p.y, p.u, p.v, p.m, p.rho, p.h)[0]
    return np.nan_to_num(d, nan=0.0)


@pytest.mark.parametrize("d_right, t_end", [(0.0, 50.0), (5.0, 80.0)],
                         ids=["supercritical-ritter", "subcritical-stoker"])
def test_waves_leave_an_open_edge_without_reflection(d_right, t_end):
    """A dam break at x = 1000 m in a channel cut at x = 1300 m (open east edge): after the
    front has left, the depth upstream of the cut matches a channel twice as long, and the
    exact solution, as closely as the long channel does."""
    short = _dam_break(1300.0, 10.0, d_right, ("south", "north", "west"))
    long_ = _dam_break(2600.0, 10.0, d_right, SIDES)
    v0 = short.volume()
    run_until(short, t_end)
    run_until(long_, t_end)
    xq = np.arange(500.0, 1250.0, 2.0)
    d_short, d_long = _profile(short, xq), _profile(long_, xq)
    if d_right == 0.0:
        d_exact, _ = exact.ritter(xq, t_end, 10.0, x_dam=1000.0)
    else:
        d_exact, _ = exact.stoker(xq, t_end, 10.0, d_right, x_dam=1000.0)
        d_mid = exact.stoker_middle_state(10.0, d_right)[0]
        assert d_mid / exact.stoker_middle_state(10.0, d_right)[1] ** 2 * GRAVITY > 1  # Fr < 1
    assert short.state.volume_out > 0.0
    assert np.abs(d_short - d_long).mean() < 0.01 * 10.0
    l1_short, l1_long = metrics.l1_relative(d_short, d_exact), metrics.l1_relative(d_long, d_exact)
    assert l1_short < 1.2 * l1_long + 0.005
    assert short.volume() + short.state.volume_out == pytest.approx(v0, rel=1e-12)


# -- sinks ----------------------------------------------------------------------------------------
def test_sink_absorbs_and_counts_the_water_that_reaches_it():
    dx = 10.0
    terrain = _flat(1000, 40, cell=10.0)
    x, y = lattice(0, 1000, 0, 40, dx)
    d = np.where(x < 300, 5.0, 0.0)
    sink = Sink([[700, -10], [1100, -10], [1100, 50], [700, 50]], terrain, reach=4 * KAPPA * dx)
    model = set_up_model(terrain, particles_with_depth(x[d > 0], y[d > 0], d[d > 0], dx, KAPPA),
                       Numerics(particle_spacing_m=dx), boundaries=[sink])
    v0 = model.volume()
    run_until(model, 120.0)
    p = model.particles
    assert model.state.volume_out > 0.05 * v0
    assert model.volume() + model.state.volume_out == pytest.approx(v0, rel=1e-12)
    assert not np.any(p.x >= 700.0)
    assert sink.protected(np.array([650.0, 300.0]), np.array([20.0, 20.0])).tolist() == [
        True, False]
