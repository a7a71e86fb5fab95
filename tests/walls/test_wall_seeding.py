"""Seeds next to oblique walls under the variational momentum: settled and matched to the
seeded depth at set-up (``floodsph.walls.seeding``), so that still water along such walls
stays nearly still. The balanced momentum, the default, needs no settling: still water along
any wall is exact there (``tests/sph/test_balanced_momentum.py``)."""

import math

import numpy as np
import pytest
from matplotlib.path import Path
from sph_cases import lattice, model_on, run_until

from floodsph.constants import RHO_WATER
from floodsph.model import wall_seeds
from floodsph.scenario.numerics import Momentum, Numerics, TimeStepping
from floodsph.walls import seeding as wall_seeding
from floodsph.walls.geometry import segments_from_polylines
from floodsph.walls.index import WallIndex

VARIATIONAL = Momentum.VARIATIONAL


def turned_rectangle_lake():
    """2 m of still water inside a 300 m x 180 m rectangle of walls turned by 30 degrees about
    (200, 200) m, on a flat frictionless 400 m square bed at 5 m spacing, local time steps
    (the case ``turned-rectangle`` of ``benchmarks/still_water_at_walls.py``)."""
    turn = math.radians(30.0)
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]]) * np.array([150.0, 90.0])
    rotation = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
    wall = corners @ rotation.T + 200.0
    inside = Path(wall)

    def depth(x, y):
        return np.where(inside.contains_points(np.column_stack([x, y])), 2.0, 0.0)

    return model_on(lambda x, y: np.zeros_like(x), (0.0, 400.0), (0.0, 400.0), 5.0, depth,
                    5.0, walls=[wall], time_stepping=TimeStepping.LOCAL, momentum=VARIATIONAL)


@pytest.fixture(scope="module")
def turned_lake():
    """2 m of water inside a 300 m x 180 m rectangle of walls turned by 30 degrees (5 m
    spacing), and its seeded volume."""
    model = turned_rectangle_lake()
    seeded = float(np.count_nonzero(model.particles.m)) * 2.0 * 25.0
    return model, seeded


def test_along_an_oblique_wall_the_seeds_read_the_seeded_depth(turned_lake):
    """Without settling and matching, seeds next to the 30-degree walls read up to 0.84 m off
    the 2 m of water (the images crowd or leave gaps); after, within 2 % (measured 1.2 %)."""
    model, _ = turned_lake
    assert np.abs(model.depth() - 2.0).max() < 0.04


def test_the_adjustment_is_reported_and_small(turned_lake):
    """The seeds' volume changes by the reported ``volume_seed_adjustment`` only (measured
    +40 m3 of 107,900 m3), and masses move by at most the bounds."""
    model, seeded = turned_lake
    assert model.volume() == pytest.approx(seeded + model.state.volume_seed_adjustment, rel=1e-12)
    assert 0.0 < abs(model.state.volume_seed_adjustment) < 0.005 * seeded
    m = model.particles.m / (RHO_WATER * 2.0 * 25.0)
    assert m.min() >= wall_seeding.MASS_MIN - 1e-12 and m.max() <= wall_seeding.MASS_MAX + 1e-12


def test_still_water_along_an_oblique_wall_stays_nearly_still():
    """After 100 s the 95th-percentile speed is below 1.5 cm/s (measured 0.9 cm/s; 3.6 cm/s
    without the set-up, and 7.3 cm/s at 20 s) and the fastest particle below 5 cm/s
    (measured 3.6; 4.5 without); mass is exact. The issue's 1 cm/s for every particle is not
    met."""
    model = turned_rectangle_lake()
    volume = model.volume()
    run_until(model, 100.0)
    speed = np.hypot(model.particles.u, model.particles.v)
    assert np.percentile(speed, 95) < 0.015
    assert speed.max() < 0.05
    assert model.volume() == pytest.approx(volume, rel=1e-12)


def test_walls_along_the_lattice_change_nothing():
    """In a box whose walls run half a spacing from the lattice rows, and around a building
    aligned with it, the seeds are already exact: no seed moves and no mass changes."""
    def depth(x, y):
        inside = (x > 300) & (x < 500) & (y > 200) & (y < 400)
        return np.where(inside, 0.0, 3.0)

    building = np.array([[300.0, 200.0], [500.0, 200.0], [500.0, 400.0], [300.0, 400.0],
                         [300.0, 200.0]])
    model = model_on(lambda x, y: 0 * x, (0, 800), (0, 600), 10.0, depth, 10.0,
                     walls=[building], momentum=VARIATIONAL)
    x, y = lattice(0.0, 800.0, 0.0, 600.0, 10.0)
    keep = depth(x, y) > 0
    p = model.particles
    assert model.state.volume_seed_adjustment == 0.0
    np.testing.assert_array_equal(np.sort(p.x + 1e3 * p.y), np.sort(x[keep] + 1e3 * y[keep]))
    np.testing.assert_array_equal(p.m, RHO_WATER * 3.0 * 100.0)


def test_seeds_that_need_no_settling_leave_the_set_up_as_it_was(monkeypatch):
    """In Ritter's channel at 10 m the seeds along the side walls qualify but are exact, so no
    round runs: the depths, smoothing lengths, accelerations and pressure renormalisation
    are then those of a set-up without the settling, bit for bit. An extra evaluation after
    no round once changed some of them, and took the same dam break in
    ``test_sph_dynamics.py``'s side-wall test past its 3 % bound (3.1 %)."""
    def build():
        return model_on(lambda x, y: 0 * x, (0, 2000), (0, 100), 10.0,
                        lambda x, y: np.where(x < 1000, 10.0, 0.0), 10.0, momentum=VARIATIONAL)

    model = build()
    assert model.state.counters["seeds_settled"] > 500 and model.state.counters["settle_steps"] == 0
    monkeypatch.setattr(wall_seeds, "wall_seeds", lambda model, rho: np.zeros(0, np.int64))
    unsettled = build()
    assert unsettled.state.counters["seeds_settled"] == 0
    for field in ("rho", "h", "hgrow", "ax", "ay", "kxx", "kxy", "kyy"):
        np.testing.assert_array_equal(getattr(model.particles, field),
                                      getattr(unsettled.particles, field), err_msg=field)


def test_seeds_whose_support_reaches_dry_ground_are_not_enclosed():
    """Water against a wall along x = 51 m (1.5 m from the first lattice column), from a free
    edge at y = 0 to a free shore at y = 100 m: the seeds next to the wall and within
    ``ENCLOSURE`` h of either see dry lattice nodes and are left as they are; the others are
    enclosed."""
    dx, h = 5.0, Numerics.kappa * 5.0
    x, y = lattice(0.0, 200.0, 0.0, 200.0, dx)
    wet = (x > 51.0) & (y < 100.0)
    x, y = x[wet], y[wet]
    seg = segments_from_polylines([np.array([[51.0, -10.0], [51.0, 210.0]])])
    index = WallIndex(seg, (0.0, 0.0, 200.0, 200.0), bucket=2.0 * h)
    n = x.size
    reach = wall_seeding.ENCLOSURE * h
    wstart, wseg, _, _ = index.near_lists(x, y, np.full(n, h), np.zeros(n + 1, dtype=np.int64),
                                          np.zeros(0, dtype=np.int64), wall_seeding.ENCLOSURE)
    near = np.flatnonzero(np.diff(wstart) > 0)
    enclosed = wall_seeding.enclosed_seeds(x, y, np.full(n, reach), near, dx, wstart, wseg, seg)
    inner = (y[near] + dx / 2 >= reach) & (100.0 + dx / 2 - y[near] >= reach)  # first dry nodes
    assert inner.any() and (~inner).any()
    np.testing.assert_array_equal(np.sort(enclosed), np.sort(near[inner]))


def test_a_settling_move_stops_at_the_limit_but_not_short_of_it():
    """Moves a dt^2 / 2 are shortened exactly to the limit from the seed, and only where they
    would go beyond it; a seed at the limit can still move back."""
    rng = np.random.default_rng(1)
    n, limit = 10_000, 2.5
    ax, ay = rng.normal(size=(2, n)) * 5.0
    angle, r = rng.uniform(0.0, 2.0 * np.pi, n), rng.uniform(0.0, limit, n)
    sx, sy = r * np.cos(angle), r * np.sin(angle)
    mx, my = wall_seeding.limited_move(ax, ay, np.ones(n), sx, sy, limit)
    end = np.hypot(sx + mx, sy + my)
    free = np.hypot(sx + 0.5 * ax, sy + 0.5 * ay) <= limit
    assert free.any() and (~free).any()
    np.testing.assert_allclose(mx[free], 0.5 * ax[free], rtol=1e-12)
    np.testing.assert_allclose(end[~free], limit, rtol=1e-12)
    back = wall_seeding.limited_move(np.array([-1.0]), np.array([0.0]), np.ones(1),
                                     np.array([limit]), np.array([0.0]), limit)
    assert back[0][0] == -0.5


def test_settling_the_seeds_neighbourhood_alone_moves_them_as_settling_everything(
        turned_lake, monkeypatch):
    """Each settling round solves density and forces for the seeds and two rings of their
    neighbours only (``wall_seeding.neighbourhood``): the particles farther off cannot change.
    The seeds then end where rounds over every particle put them, with the same masses."""
    model, _ = turned_lake
    monkeypatch.setattr(wall_seeding, "neighbourhood",
                        lambda rows, start, nbr, n, rings: np.arange(n, dtype=np.int64))
    everything = turned_rectangle_lake()
    assert model.state.counters["seeds_settled"] == everything.state.counters["seeds_settled"] > 400
    p, q = model.particles, everything.particles
    np.testing.assert_allclose(p.x, q.x, rtol=0.0, atol=1e-9)
    np.testing.assert_allclose(p.y, q.y, rtol=0.0, atol=1e-9)
    np.testing.assert_allclose(p.m, q.m, rtol=1e-12)


def test_a_neighbourhood_holds_the_rows_and_what_their_lists_hold_ring_by_ring():
    start = np.array([0, 2, 3, 5, 6, 6])
    nbr = np.array([1, 7, 0, 3, 4, 2])  # 7 >= n: a ghost, left out
    assert wall_seeding.neighbourhood(np.array([0]), start, nbr, 5, 1).tolist() == [0, 1]
    assert wall_seeding.neighbourhood(np.array([2]), start, nbr, 5, 1).tolist() == [2, 3, 4]
    assert wall_seeding.neighbourhood(np.array([2]), start, nbr, 5, 2).tolist() == [2, 3, 4]
    rows = np.array([3, 0])
    assert wall_seeding.neighbourhood(rows, start, nbr, 5, 1).tolist() == [0, 1, 2, 3]
    assert wall_seeding.neighbourhood(rows, start, nbr, 5, 2).tolist() == [0, 1, 2, 3, 4]
