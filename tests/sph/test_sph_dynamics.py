"""Conservation, walls and the lake at rest on analytic beds (fast cases)."""

import numpy as np
import pytest
from sph_cases import model_on, particles_with_depth, run_until

from floodsph.model import list_stages, stages
from floodsph.model.builder import set_up_model
from floodsph.model.terrain import Terrain
from floodsph.output.rasterise import interpolate
from floodsph.scenario.numerics import Momentum, Numerics, TimeStepping
from floodsph.sph.sums import SUMS


def test_closed_box_conserves_mass_and_keeps_every_particle_inside():
    """A column collapsing in a closed box: mass to round-off, no particle leaves or crosses."""
    model = model_on(lambda x, y: 0 * x, (0, 300), (0, 200), 10.0,
                     lambda x, y: np.where(x < 100, 5.0, 0.0), 5.0)
    p = model.particles
    n0, m0 = p.n, p.m.sum()
    run_until(model, 40.0)
    assert p.n == n0
    assert abs(p.m.sum() - m0) <= 1e-12 * m0
    assert model.state.volume_out == 0.0
    assert p.x.min() >= 0 and p.x.max() <= 300 and p.y.min() >= 0 and p.y.max() <= 200


def test_momentum_changes_only_through_external_forces():
    """Free flat frictionless bed, no walls reached: sum m v stays at its initial value (with
    one global step; local steps conserve it to the order of the step). The variational
    momentum's pair forces are antisymmetric; the balanced momentum's renormalised level
    differences are not, and conserve momentum only as far as they act (slow water)."""
    terrain = Terrain.from_function(lambda x, y: 0 * x, (0, 2000), (0, 2000), 20.0)
    rng = np.random.default_rng(0)
    x, y = np.meshgrid(np.arange(800, 1200, 8.0), np.arange(850, 1150, 8.0))
    x, y = x.ravel(), y.ravel()
    d = 2.0 + 0.5 * rng.random(x.size)
    p = particles_with_depth(x, y, d, 8.0, 1.3, u=rng.normal(0, 1, x.size) + 2.0,
                             v=rng.normal(0, 1, x.size) - 1.0)
    model = set_up_model(terrain, p, Numerics(particle_spacing_m=8.0, kappa=1.3,
                                              time_stepping=TimeStepping.GLOBAL,
                                              momentum=Momentum.VARIATIONAL),
                         closed_sides=())
    mom0 = np.array([(p.m * p.u).sum(), (p.m * p.v).sum()])
    scale = (p.m * np.hypot(p.u, p.v)).sum()
    run_until(model, 20.0)
    assert model.state.volume_out == 0.0
    mom = np.array([(p.m * p.u).sum(), (p.m * p.v).sum()])
    assert np.abs(mom - mom0).max() < 1e-12 * scale


def test_friction_only_removes_momentum():
    """With Manning friction on a flat bed, momentum decays and never reverses."""
    model = model_on(lambda x, y: 0 * x, (0, 1000), (0, 200), 20.0, 2.0, 10.0, manning=0.05)
    p = model.particles
    p.u[:] = 1.0
    mx = [(p.m * p.u).sum()]
    for _ in range(20):
        model.step()
        mx.append((p.m * p.u).sum())
    mx = np.array(mx)
    assert np.all(np.diff(mx) < 0) and mx[-1] > 0


def assert_stays_still(model, depth, t_end):
    """Run to ``t_end`` [s]: no particle faster than 1 mm/s, the depth within 1 cm of
    ``depth`` [m]."""
    run_until(model, t_end)
    p = model.particles
    assert np.hypot(p.u, p.v).max() < 1e-3
    assert np.abs(model.depth() - depth).max() < 0.01


def test_still_water_along_walls_and_in_corners_of_a_closed_box_stays_still():
    model = model_on(lambda x, y: 0 * x, (0, 800), (0, 600), 10.0, 3.0, 10.0)
    assert_stays_still(model, 3.0, 100.0)


@pytest.mark.parametrize("vertex_x", [103.0, 100.0])
def test_a_wall_split_in_two_collinear_segments_completes_the_kernel_as_one(vertex_x):
    """Still water north of a wall along y = 50 m: the depth is the same, exact to round-off,
    whether the wall is one segment or two meeting at x = ``vertex_x`` (images are taken
    through whichever segment hides them; requiring the image's foot on the segment lost some
    near the vertex: 3 m water read 2.80 m there). At x = 100 m, midway between two lattice
    columns, the sight line from each particle beside the vertex to the other's image passes
    exactly through it; imaged through both segments, they read 3.15 m."""
    depth = lambda x, y: np.where(y > 50.0, 3.0, 0.0)  # noqa: E731
    one = model_on(lambda x, y: 0 * x, (0, 200), (0, 100), 10.0, depth, 10.0,
                   walls=[np.array([[-10.0, 50.0], [210.0, 50.0]])])
    two = model_on(lambda x, y: 0 * x, (0, 200), (0, 100), 10.0, depth, 10.0,
                   walls=[np.array([[-10.0, 50.0], [vertex_x, 50.0], [210.0, 50.0]])])
    away = np.abs(one.particles.x - 100.0) < 70.0  # off the corners with the box's sides
    np.testing.assert_allclose(one.depth()[away], 3.0, rtol=1e-9)
    np.testing.assert_allclose(two.depth(), one.depth(), rtol=1e-12)


def test_still_water_where_walls_cross_each_other_and_the_border_stays_still():
    """Two user walls cross (an X at (200, 150) m) and run past the DEM border (each crosses a
    side of the closed box); a third ends on one of them (a T at (100, 150) m). Each junction
    is made a shared vertex (``floodsph.walls.junctions``), so its right-angled corners
    get the point reflection and 2 m of still water in the six compartments stays still.
    Without the cuts the corner particles read 1.886 m and moved at 0.28 m/s within 5 s."""
    walls = [np.array([[-30.0, 150.0], [430.0, 150.0]]),
             np.array([[200.0, -30.0], [200.0, 330.0]]),
             np.array([[100.0, 150.0], [100.0, 300.0]])]
    model = model_on(lambda x, y: 0 * x, (0, 400), (0, 300), 5.0, 2.0, 5.0, walls=walls)
    assert np.abs(model.depth() - 2.0).max() < 1e-9
    assert_stays_still(model, 2.0, 50.0)


def test_walls_are_cut_where_they_cross_or_end_on_each_other():
    from floodsph.walls.junctions import split_at_junctions

    seg = np.array([[0.0, 0.0, 10.0, 0.0],     # cut by the T at x = 5 and the X at x = 2
                    [5.0, -5.0, 5.0, 0.0],     # ends on the first: a T, itself uncut
                    [2.0, -3.0, 2.0, 3.0],     # crosses the first: an X, cut at y = 0
                    [10.0, 0.0, 10.0, 5.0],    # shares the first's end; cut by the last
                    [0.0, 1.0, 10.0, 1.0 + 1e-9]])  # crosses the X, ends 1e-9 m off a wall
    out = split_at_junctions(seg, 1e-6)
    expected = {(0, 0, 2, 0), (2, 0, 5, 0), (5, 0, 10, 0), (5, -5, 5, 0), (2, -3, 2, 0),
                (2, 0, 2, 1), (2, 1, 2, 3), (10, 0, 10, 1), (10, 1, 10, 5), (0, 1, 2, 1),
                (2, 1, 10, 1)}
    assert {tuple(np.round(s, 6)) for s in out} == expected
    assert out.shape[0] == len(expected)
    lengths = lambda s: np.hypot(s[:, 2] - s[:, 0], s[:, 3] - s[:, 1]).sum()  # noqa: E731
    assert abs(lengths(out) - lengths(seg)) < 1e-9

    # 200 random segments: afterwards no two pieces cross inside and no end lies inside another
    rng = np.random.default_rng(3)
    start = rng.uniform(0, 100, (200, 2))
    seg = np.hstack([start, start + rng.normal(0, 15, (200, 2))])
    out = split_at_junctions(seg, 1e-6)
    assert out.shape[0] > 400 and abs(lengths(out) - lengths(seg)) < 1e-8
    p1, p2 = out[:, None, :2], out[:, None, 2:]
    q1, q2 = out[None, :, :2], out[None, :, 2:]
    cross = lambda a, b, c: ((b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1])  # noqa: E731
                             - (b[..., 1] - a[..., 1]) * (c[..., 0] - a[..., 0]))
    d1, d2, d3, d4 = cross(q1, q2, p1), cross(q1, q2, p2), cross(p1, p2, q1), cross(p1, p2, q2)
    scale = 1e-9 * 100.0**2
    proper = (d1 * d2 < -scale) & (d3 * d4 < -scale)
    assert not proper.any()
    e = q2 - q1
    length = np.hypot(e[..., 0], e[..., 1])
    for end in (p1, p2):
        along = ((end - q1) * e).sum(-1) / length
        across = np.abs(cross(q1, q2, end)) / length
        assert not ((across < 1e-7) & (along > 1e-6) & (along < length - 1e-6)).any()


def test_the_closer_a_particle_is_to_a_wall_the_harder_the_wall_pushes_it_back():
    """Still water 3 m deep at 10 m spacing; one particle of the row next to the south wall
    (5 m off it) is moved closer. Its acceleration away from the wall grows as the gap shrinks
    (with the plain cubic gradient on its image it peaked at 2 m, 0.33 m s-2, and fell to
    0.03 m s-2 at 0.1 m: particles reaching a wall stuck to it)."""
    model = model_on(lambda x, y: 0 * x, (0, 200), (0, 100), 10.0, 3.0, 10.0,
                     momentum=Momentum.VARIATIONAL)
    p = model.particles
    pid = p.pid[np.flatnonzero(np.isclose(p.x, 105.0) & np.isclose(p.y, 5.0))[0]]
    push = []
    for gap in (4.0, 3.0, 2.0, 1.0, 0.5, 0.1):
        k = np.flatnonzero(p.pid == pid)[0]
        p.y[k] = gap
        model.work.nl = None
        stages.interactions(model.domain, model.state, model.work, model.boundaries)
        k = np.flatnonzero(p.pid == pid)[0]
        push.append(p.ay[k])
    assert np.all(np.diff(push) > 0.0) and push[0] > 0.0
    assert push[-1] > 2.0 * push[1]  # 0.87 against 0.35 m s-2 at 3 m


def test_a_dam_break_between_side_walls_stays_uniform_across_the_channel():
    """Ritter's dam break in a 100 m channel at 10 m spacing, t = 50 s: the depth next to the
    side walls (2.5 m off them) is the centre line's to 3 %. Before the own-image push was
    floored, the rows along the walls emptied: dry there at x = 1200 m (2.9 m at the centre)."""
    model = model_on(lambda x, y: 0 * x, (0, 2000), (0, 100), 10.0,
                     lambda x, y: np.where(x < 1000, 10.0, 0.0), 10.0)
    run_until(model, 50.0)
    p = model.particles
    for x in (1200.0, 1400.0, 1600.0):
        d = interpolate(np.full(3, x), np.array([2.5, 50.0, 97.5]), p.x, p.y, p.u, p.v, p.m,
                        p.rho, p.h, level=model.surface_levels(), bed=np.zeros(3))[0]
        assert np.all(np.abs(d[[0, 2]] / d[1] - 1.0) < 0.03)


def test_still_water_around_a_building_stays_still():
    """A closed footprint with four convex corners, aligned with the lattice. Until sight lines
    through a vertex were settled one way (``floodsph.walls.sight.hides``), the particle on each
    corner's diagonal was imaged through both faces, 4.9 % too deep, and the water moved at
    up to 1-2 m/s within 100 s."""
    building = np.array([[300.0, 200.0], [500.0, 200.0], [500.0, 400.0], [300.0, 400.0],
                         [300.0, 200.0]])

    def depth(x, y):
        inside = (x > 300) & (x < 500) & (y > 200) & (y < 400)
        return np.where(inside, 0.0, 3.0)

    model = model_on(lambda x, y: 0 * x, (0, 800), (0, 600), 10.0, depth, 10.0,
                     walls=[building])
    assert np.abs(model.depth() - 3.0).max() < 1e-9
    assert_stays_still(model, 3.0, 100.0)


def test_lake_at_rest_over_a_bump_stays_at_rest():
    """Field scale: 10 m deep lake over a 4 m Gaussian bump, 200 s, frictionless."""
    bump = lambda x, y: 4.0 * np.exp(-((x - 500) ** 2 + (y - 500) ** 2) / 150.0**2)  # noqa: E731
    model = model_on(bump, (0, 1000), (0, 1000), 10.0, 10.0, 20.0)
    run_until(model, 200.0)
    p = model.particles
    level = model.depth() + model.state.bed[:, 0]
    assert np.hypot(p.u, p.v).max() < 0.01
    assert np.abs(level - 10.0).max() < 0.01 * 10.0


def test_lake_at_rest_in_a_parabolic_bowl_stays_at_rest():
    """Under the balanced momentum. (The variational force with its shore balance held the
    level to 1 % and the shore in place, but not the shore rows where the lattice meets the
    round shore in steps: after 200 s 2.2 cm/s (95th percentile), 7.7 cm/s at the shore.)"""
    bowl = lambda x, y: 10.0 * ((x - 500) ** 2 + (y - 500) ** 2) / 500.0**2  # noqa: E731
    model = model_on(bowl, (0, 1000), (0, 1000), 10.0, 5.0, 10.0)
    run_until(model, 200.0)
    p = model.particles
    level = model.depth() + model.state.bed[:, 0]
    assert np.hypot(p.u, p.v).max() < 0.01
    assert np.abs(level - 5.0).max() < 0.01 * 5.0


def test_segments_beyond_reach_are_skipped_without_changing_density_or_forces():
    """The density summation and the forces skip the images of the near segments beyond their
    support (``wdist``, of ``floodsph.walls.sight.blocked_pairs``). With every distance set to
    zero nothing is skipped, and both give the same numbers bit for bit: on a dam break
    around a building rotated by 30 degrees, after 4 m particles have spread thin (h up to
    three times h0) and many listed segments lie beyond the support."""
    from floodsph.sph import density, forces

    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    corners = np.array([[-15.0, -15.0], [15.0, -15.0], [15.0, 15.0], [-15.0, 15.0],
                        [-15.0, -15.0]])
    building = corners @ np.array([[c, s], [-s, c]]) + (110.0, 60.0)
    model = model_on(lambda x, y: 0 * x, (0, 200), (0, 120), 10.0,
                     lambda x, y: np.where(x < 60, 2.0, 0.0), 4.0, walls=[building])
    run_until(model, 20.0)
    p = model.particles
    list_stages.update_lists(model.domain, model.state, model.work, force=True)
    list_stages.block_pairs(model.domain, model.state, model.work)
    wstart, wseg, cstart, cpair = model.work.walls_near
    beyond = model.state.wdist >= 2.0 * np.repeat(p.h, np.diff(wstart))
    assert p.h.max() > 2.0 * 1.3 * 4.0 and beyond.mean() > 0.3

    def results(wdist):
        walls = list_stages.wall_lists(model.domain, model.state, model.work)._replace(wdist=wdist)
        rho = [density.summation(i, p.h[i], p.x, p.y, p.m, model.work.nl.start, model.work.nl.nbr,
                                 model.state.blocked, walls)
               for i in range(p.n)]
        acc = np.empty((3, p.n))
        forces.internal_acceleration(model.work.nl.rows, p.x, p.y, p.u, p.v, p.m, p.rho,
                                     p.alpha, p.h, p.kxx, p.kxy, p.kyy, p.dudx, p.dudy, p.dvdx,
                                     p.dvdy, model.work.nl.start, model.work.nl.nbr,
                                     model.state.blocked, walls, model.domain.scheme,
                                     np.empty((p.n, SUMS)), *acc)
        return np.array(rho), acc

    rho, acc = results(model.state.wdist)
    rho_all, acc_all = results(np.zeros_like(model.state.wdist))
    np.testing.assert_array_equal(rho, rho_all)
    np.testing.assert_array_equal(acc, acc_all)
