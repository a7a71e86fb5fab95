"""The cubic-spline kernel and the neighbour search (exact against a k-d tree, mixed h)."""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.spatial import cKDTree
from sph_cases import model_on

from floodsph.sph.kernels import (
    SIGMA_2D,
    beyond_support,
    dwdr_over_r_cubic,
    dwdr_over_r_floored,
    w_cubic,
    w_dwdr_cubic,
)
from floodsph.sph.neighbours import NeighbourList


@pytest.mark.parametrize("h", [0.3, 1.0, 13.0])
def test_kernel_is_normalised_and_compact(h):
    area = quad(lambda r: 2 * np.pi * r * w_cubic(r, h), 0, 2 * h, points=[h])[0]
    assert area == pytest.approx(1.0, abs=1e-10)
    assert w_cubic(2.0 * h, h) == 0.0 and w_cubic(2.0001 * h, h) == 0.0
    assert w_cubic(0.0, h) == pytest.approx(SIGMA_2D / h**2)



def test_every_kernel_term_is_exactly_zero_where_beyond_support_skips_the_pair():
    """Images that ``beyond_support`` skips must contribute exactly nothing: at the first
    separations it accepts, every kernel form evaluates to zero, with r and 1 / h rounded as
    the pair loops round them."""
    rng = np.random.default_rng(5)
    skipped = 0
    for h in np.exp(rng.uniform(np.log(0.01), np.log(500.0), 2000)):
        angle = rng.uniform(0.0, 2.0 * np.pi)
        for r in np.nextafter(2.0 * h * np.sqrt(1.0 + 1e-9), 0.0) * np.array([1.0, 1.0 + 1e-15]):
            rx, ry = r * np.cos(angle), r * np.sin(angle)
            if not beyond_support(rx, ry, h):
                continue
            skipped += 1
            rr = np.sqrt(rx * rx + ry * ry)
            w, dwdr = w_dwdr_cubic(rr, h)
            assert w == 0.0 and dwdr == 0.0 and w_cubic(rr, h) == 0.0
            assert dwdr_over_r_cubic(rr, 1.0 / rr, 1.0 / h) == 0.0
            assert dwdr_over_r_floored(rr, 1.0 / rr, 1.0 / h) == 0.0
    assert skipped > 1000
    assert not beyond_support(2.0 * 0.999999 * 3.0, 0.0, 3.0)


def test_kernel_derivative_matches_finite_difference():
    h = 1.7
    for r in np.linspace(0.05, 3.3, 40):
        e = 1e-6
        fd = (w_cubic(r + e, h) - w_cubic(r - e, h)) / (2 * e)
        w, dwdr = w_dwdr_cubic(r, h)
        assert w == w_cubic(r, h)
        assert dwdr == pytest.approx(fd, rel=1e-6, abs=1e-9)
        assert dwdr_over_r_cubic(r, 1.0 / r, 1.0 / h) == pytest.approx(dwdr / r, rel=1e-13,
                                                                       abs=1e-15)


def _reference_pairs(x, y, h):
    tree = cKDTree(np.c_[x, y])
    pairs = tree.query_pairs(2 * h.max(), output_type="ndarray")
    r = np.hypot(*(np.c_[x, y][pairs[:, 0]] - np.c_[x, y][pairs[:, 1]]).T)
    keep = pairs[r < 2 * np.maximum(h[pairs[:, 0]], h[pairs[:, 1]])]
    return set(map(tuple, keep)) | set(map(tuple, keep[:, ::-1]))


def _listed_pairs(nl, n):
    return {(i, int(j)) for i in range(n) for j in nl.nbr[nl.start[i]:nl.start[i + 1]]}


@pytest.mark.parametrize("cloud", ["uniform", "clustered"])
def test_neighbour_lists_equal_kdtree_with_mixed_h(cloud):
    rng = np.random.default_rng(7)
    n = 6000
    if cloud == "uniform":
        x, y = rng.uniform(0, 100, n), rng.uniform(0, 60, n)
    else:
        centres = rng.uniform(0, 100, (12, 2))
        pick = rng.integers(0, 12, n)
        x = centres[pick, 0] + rng.normal(0, 3, n)
        y = centres[pick, 1] + rng.normal(0, 3, n)
    h = rng.uniform(0.4, 1.2, n)
    big = rng.random(n) < 0.01  # a few front particles with a much larger support
    h[big] = rng.uniform(5, 15, big.sum())
    nl = NeighbourList(x, y, h, skin=0.0)
    assert _listed_pairs(nl, n) == _reference_pairs(x, y, h)


def test_neighbour_lists_equal_kdtree_with_h_spread_over_many_levels():
    """A front-like cloud: h grows smoothly by a factor 20 along x (five search levels)."""
    rng = np.random.default_rng(11)
    n = 5000
    x, y = rng.uniform(0, 400, n), rng.uniform(0, 80, n)
    h = 0.8 * np.exp(3.0 * x / 400) * rng.uniform(0.9, 1.1, n)
    nl = NeighbourList(x, y, h, skin=0.0)
    assert _listed_pairs(nl, n) == _reference_pairs(x, y, h)


@pytest.mark.parametrize("capacity", [None, 3])
def test_lists_of_some_rows_equal_kdtree_and_survive_undersized_buffers(monkeypatch, capacity):
    """Lists for a subset of rows (local time stepping) are exact for those rows and empty
    for the others. With the build's per-chunk buffers forced far too small (``capacity``
    slots), every chunk overflows, is counted and searched again: the same lists, in the
    same order."""
    from floodsph.sph import neighbours

    rng = np.random.default_rng(13)
    n = 5000
    x, y = rng.uniform(0, 100, n), rng.uniform(0, 60, n)
    h = rng.uniform(0.4, 1.2, n)
    h[rng.random(n) < 0.02] = 6.0
    rows = np.sort(rng.choice(n, 2500, replace=False)).astype(np.int64)
    sized = NeighbourList(x, y, h, skin=0.0, rows=rows)
    if capacity is not None:
        monkeypatch.setattr(neighbours, "_chunk_capacity",
                            lambda args, r: np.full(-(-r.shape[0] // neighbours.CHUNK),
                                                    capacity, dtype=np.int64))
    nl = NeighbourList(x, y, h, skin=0.0, rows=rows)
    mine = set(rows.tolist())
    assert _listed_pairs(nl, n) == {(i, j) for i, j in _reference_pairs(x, y, h) if i in mine}
    np.testing.assert_array_equal(nl.start, sized.start)
    np.testing.assert_array_equal(nl.nbr, sized.nbr)


def test_skin_keeps_list_valid_until_h_grows_past_it():
    rng = np.random.default_rng(3)
    x, y = rng.uniform(0, 50, 2000), rng.uniform(0, 50, 2000)
    h = np.full(2000, 1.0)
    nl = NeighbourList(x, y, h, skin=0.1)
    assert nl.still_valid(x, y, h * 1.09)
    assert not nl.still_valid(x, y, h * 1.11)
    assert _reference_pairs(x, y, h * 1.1) <= _listed_pairs(nl, 2000)


def test_verlet_list_stays_exact_while_particles_move_within_the_skin():
    """Moves of up to D h_b and growth of h up to G h_b with G + D = 1 + skin lose no pair."""
    rng = np.random.default_rng(5)
    n = 3000
    x, y = rng.uniform(0, 60, n), rng.uniform(0, 60, n)
    h = rng.uniform(0.8, 1.6, n)
    skin = 0.3
    nl = NeighbourList(x, y, h, skin=skin)
    move, grow = 0.12, 1.0 + skin - 0.12
    angle = rng.uniform(0, 2 * np.pi, n)
    x1 = x + move * h * np.cos(angle) * 0.999
    y1 = y + move * h * np.sin(angle) * 0.999
    h1 = h * grow
    assert nl.still_valid(x1, y1, h1)
    assert _reference_pairs(x1, y1, h1) <= _listed_pairs(nl, n)
    assert not nl.still_valid(x1 + 0.2 * h, y1, h1)
    assert not nl.still_valid(x1[:-1], y1[:-1], h1[:-1])  # a particle removed


def test_verlet_lists_kept_over_steps_give_the_flow_of_lists_rebuilt_every_step():
    """Dam break across a closed box (walls, corners, near-wall lists) until the front meets
    the far wall: a wide skin keeps the lists over several steps, and the flow is that of
    lists rebuilt at (nearly) every step (to round-off: the density is solved tightly, so the
    Newton path does not matter, and no h is held back by its lists)."""

    def depth(x, y):
        return np.where(x < 150.0, 4.0, 0.0)

    states, lists = [], []
    for skin in (0.1, 0.6):
        model = model_on(lambda x, y: 0 * x, (0, 300), (0, 200), 10.0, depth, 10.0,
                         neighbour_skin=skin, density_tol=1e-12)
        built, last = 0, None
        while model.t < 30.0:
            model.step()
            built += model.work.nl is not last
            last = model.work.nl
        p = model.particles
        order = np.argsort(p.pid)
        states.append(np.c_[p.x, p.y, p.u, p.v, p.rho][order])
        lists.append((built, model.steps))
        assert model.state.counters["density_capped"] == 0
    (rebuilt, steps), (kept, steps_kept) = lists
    assert rebuilt >= 0.9 * steps and steps_kept == steps
    assert kept < steps / 2
    assert states[0][:, 0].max() > 285.0  # the front has reached the far wall
    np.testing.assert_allclose(states[1], states[0], rtol=1e-8, atol=1e-8)


def test_wall_lists_equal_a_brute_force_search():
    """Segments longer than the buckets, diagonal ones, radii spanning several buckets and
    the coarse levels of the bucket pyramid: every segment within reach is listed once, in
    index order, with its distance, its right-angled corners and the pairs it blocks."""
    from floodsph.walls import geometry, index, sight

    rng = np.random.default_rng(7)
    start = rng.uniform(0.0, 400.0, (120, 2))
    seg = np.c_[start, start + rng.normal(0.0, 60.0, (120, 2))]
    seg[1::2, :2] = seg[:-1:2, 2:]  # every odd segment starts where the one before ends
    turn = seg[0:-1:4, 2:] - seg[0:-1:4, :2]  # and every other one of them turns 90 degrees
    seg[1::4, 2:] = seg[1::4, :2] + 0.7 * np.c_[-turn[:, 1], turn[:, 0]]
    n = 3000
    x, y = rng.uniform(-30.0, 430.0, n), rng.uniform(-30.0, 430.0, n)
    h = rng.uniform(2.0, 40.0, n)
    h[::300] = 300.0  # lone thin particles: they and their neighbours query the coarse levels
    nl = NeighbourList(x, y, h)
    index = index.WallIndex(seg, (0.0, 0.0, 400.0, 400.0), bucket=15.0)
    assert index.lv_bucket.size == 6  # 15 m to 480 m buckets
    wstart, wseg, cstart, cpair = index.near_lists(x, y, h, nl.start, nl.nbr, nl.reach)
    blocked = np.empty(nl.nbr.size, dtype=np.bool_)
    wdist = np.empty(wseg.size)
    sight.blocked_pairs(nl.rows, x, y, nl.start, nl.nbr, wstart, wseg, seg, blocked, wdist)
    assert cpair.shape[0] > 50 and blocked.sum() > 100
    for i in range(0, n, 7):
        nbrs = nl.nbr[nl.start[i]:nl.start[i + 1]]
        radius = nl.reach * max(h[i], h[nbrs].max(initial=0.0))
        dist = np.array([geometry.segment_distance(x[i], y[i], *s) for s in seg])
        near = np.flatnonzero(dist < radius)
        np.testing.assert_array_equal(wseg[wstart[i]:wstart[i + 1]], near)
        np.testing.assert_allclose(wdist[wstart[i]:wstart[i + 1]], dist[near], rtol=1e-12)
        corners = [[a, b] for k, a in enumerate(near) for b in near[k + 1:]
                   if {tuple(seg[a, :2]), tuple(seg[a, 2:])} & {tuple(seg[b, :2]),
                                                                tuple(seg[b, 2:])}
                   and abs(np.dot(seg[a, 2:] - seg[a, :2], seg[b, 2:] - seg[b, :2]))
                   < 1e-6 * np.hypot(*(seg[a, 2:] - seg[a, :2])) * np.hypot(*(seg[b, 2:]
                                                                              - seg[b, :2]))]
        assert cpair[cstart[i]:cstart[i + 1]].tolist() == corners
        for q, j in enumerate(nbrs):
            crossed = any(geometry.crosses(x[i], y[i], x[j], y[j], *seg[s]) for s in near)
            assert blocked[nl.start[i] + q] == crossed


def test_bucket_clearance_bounds_the_wall_distance_and_keeps_lists_exact():
    """Few walls in a large domain (one partly beyond its bounds): every point lies at least
    its bucket's ``clear`` distance from every segment, most buckets are clear, and the near
    lists that skip the walk on clear buckets still equal a brute-force search."""
    from floodsph.walls import geometry, index

    seg = np.array([[100.0, 100.0, 300.0, 140.0], [300.0, 140.0, 320.0, 400.0],
                    [-50.0, 700.0, 150.0, 760.0], [600.0, 20.0, 610.0, 25.0]])
    index = index.WallIndex(seg, (0.0, 0.0, 800.0, 800.0), bucket=20.0)
    rng = np.random.default_rng(3)
    n = 4000
    x, y = rng.uniform(0.0, 800.0, n), rng.uniform(0.0, 800.0, n)
    dist = np.array([[geometry.segment_distance(x[i], y[i], *s) for s in seg] for i in range(n)])
    b = (y // 20.0).astype(int) * index.lv_nbx[0] + (x // 20.0).astype(int)
    assert np.all(dist.min(axis=1) >= index.clear[b])
    assert np.mean(index.clear > 0.0) > 0.7
    h = rng.uniform(5.0, 30.0, n)
    nl = NeighbourList(x, y, h)
    wstart, wseg, _, _ = index.near_lists(x, y, h, nl.start, nl.nbr, nl.reach)
    for i in range(n):
        nbrs = nl.nbr[nl.start[i]:nl.start[i + 1]]
        radius = nl.reach * max(h[i], h[nbrs].max(initial=0.0))
        np.testing.assert_array_equal(wseg[wstart[i]:wstart[i + 1]],
                                      np.flatnonzero(dist[i] < radius))
