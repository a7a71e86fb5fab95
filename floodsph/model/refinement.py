"""Dynamic refinement: particle splitting and coalescing (Vacondio et al. 2013).

A particle's area A_i = m_i / rho_i [m2] grows as its depth d_i = rho_i / rho_w shrinks, so a
thin flood front is carried by few, huge particles. :class:`Refiner` splits such particles
into seven daughters and coalesces pairs of small ones where the water has deepened again
(``docs/method.md`` §6), so that the particle count follows the flow's needs.
The numerics live in :mod:`floodsph.sph.refine`; this module selects the particles and does
the bookkeeping. Total mass and linear momentum are unchanged to round-off by every split
and every merge.

Criteria (thresholds are multiples of the initial particle area A0 = spacing^2; each name
below is a ``refine_*`` field of ``floodsph.scenario.numerics.Numerics``: area_max stands for
``refine_area_max``, d_min for ``refine_d_min_m``, and so on):

* split p when A_p > area_max A0, d_p >= d_min, level_p < max_level, and all seven daughters
  land on valid terrain on the parent's side of every wall, outside open-boundary zones;
* merge a and b when A < area_min A0 for both, each is the other's nearest such candidate, they are
  closer than min(h_a, h_b), neither is near a wall (none within the kernel reach of the
  larger of h and the merged particle's lattice h, kappa sqrt(2 A)) or in an open boundary's
  zone (:func:`protected`), neither was born (split, merge or inflow) in the last
  ``no_merge_steps`` steps, |d_a - d_b| <= depth_jump max(d_a, d_b) and
  |v_a - v_b| <= speed_jump sqrt(g max(d_a, d_b)) (no merging across fronts and bores);
* absorb a small candidate t (A_t < SMALL_FRACTION area_min A0) that found no such pair into
  its nearest particle b of any size, when A_t + A_b < 2 area_min A0, b is settled and
  unprotected, closer than h_b and without a velocity jump (:meth:`Refiner._absorptions`):
  a lone small particle in deep, fast water otherwise sets the global time step.

New particles (``docs/method.md`` §6): daughters take h = 0.9 h_p, merged particles the h_M
of ``floodsph.sph.refine.merged_h`` (floored at the lattice value kappa sqrt(A_M), see there).
Both get the reference values h0 = h and rho0 = rho (their smoothing length and density guess
at creation: for a daughter rho0 = rho_p, h0 = 0.9 h_p, Vacondio et al.'s h0_k = 0.9 h0_p, rho0_k =
rho0_p re-based to the parent's current state), so that the relation h = h0 (rho0 / rho)^(1/2)
of the density solve holds at creation and h stays consistent with density afterwards.
After creation, :func:`relax_smoothing` takes each over-smoothed particle to
h = sqrt(3) kappa sqrt(m / rho) within about ten steps (the notes' suggested re-basing), so
that repeated splitting does not compound the daughters' 2.4-fold smoothing length.
Daughters keep the parent's velocity, which conserves momentum exactly (the notes' optional
c_v (d_N / d_k) v_N rescaling is not applied).

Thresholds (defaults). Particles are kept between area_min = 0.9 A0 and area_max = 2 A0,
about the initial resolution: a parent split at 2 A0 leaves daughters of 0.27 - 0.36 A0,
which (no_merge_steps later, away from walls, fronts and bores) merge pairwise back to about
0.55 - 0.7 A0 and then 1.1 - 1.4 A0, so that the seven daughters of a thinning sheet become
two or three particles, not seven; a merged pair stays below 2 area_min < area_max, so it
does not split again at once (the hysteresis). With these defaults
``benchmarks/refinement_benchmark.py`` measured (README, one thread, kappa 1.3) 4.2 times the
speed of splitting alone on the sample valley and 8.6-9.0 times on Malpasset at 20 m (4.6
times before small particles were absorbed), with max-depth maps that agree to CSI 0.993 and
0.954;
area_min = 0.2 (the notes' A_max / 10) merged so rarely that it was no faster than splitting
alone.
d_min = 0.01 m is the default wet threshold of the maps and the friction depth floor: water
thinner than that is invisible on every output and dominated by the friction floor, and
refining it would only add particles.
"""

from __future__ import annotations

import math

import numpy as np

from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.errors import InputError
from floodsph.model.particles import INHERITED
from floodsph.model.refinement_site import RefinementSite, count_refinement_moves, protected
from floodsph.model.state import State
from floodsph.scenario.numerics import SMOOTHING_EXCESS, Momentum, Numerics

HEXAGON_MARGIN = 1.01
"""Radius, relative to a parent's hexagon, within which wall segments are tested against the
lines to its daughters (a segment across such a line is closer than the radius itself)."""
RELAX_RATE = 0.2
"""Fraction of the excess ln(h^2 rho / (smoothing_excess kappa^2 m)) removed per step."""
EDGE_ALPHA = 0.8
"""Particles with alpha_i < EDGE_ALPHA 2 rho_i (a kernel support short of neighbours: a wet/dry
edge) are not relaxed (:func:`relax_smoothing`)."""
STILL_SPEED = 1e-3
"""Under the balanced momentum, particles slower than this [m s-1] are still water: neither
split nor merged (a split or merge changes summation depths that their level offsets were
matched to, ``floodsph.sph.level_offsets``)."""
SMALL_FRACTION = 0.25
"""A merge candidate below SMALL_FRACTION area_min that finds no fellow candidate is absorbed
by its nearest particle of any size (:meth:`Refiner._absorptions`): its h is half or less of
an area_min particle's, and such a particle, a shallow seed or a daughter carried into deep,
fast water, sets the global time step (on Malpasset at 20 m the step-setting particles had h
of 4-5 m among neighbours of 26 m)."""


class Refiner:
    """Splits and coalesces the particles of a ``FloodModel`` (its ``refiner`` hook).

    Parameters
    ----------
    numerics : Numerics
        Its ``refinement`` mode and ``refine_*`` thresholds, and the initial particle spacing
        ``particle_spacing_m`` [m]: the area thresholds are multiples of spacing^2.
    """

    STATE = ("last_call",)
    """What changes during a run (``floodsph.simulation.state_arrays``): the step of the last
    call, which the merge interval and the relaxation rate count from."""

    def __init__(self, numerics: Numerics):
        spacing = numerics.particle_spacing_m
        if spacing is None:
            raise InputError("refinement: numerics.particle_spacing_m must be given")
        self.numerics = numerics
        self.spacing = float(spacing)
        self.area_max = numerics.refine_area_max * self.spacing**2
        self.area_min = numerics.refine_area_min * self.spacing**2
        self.last_call = -1  # state.steps at the last apply: merges are due every
        # refine_merge_interval steps, also when a call ends several (local time stepping)

    @classmethod
    def of(cls, numerics: Numerics) -> Refiner | None:
        """The refiner of ``numerics.refinement`` (None for ``Refinement.NONE``)."""
        return cls(numerics) if numerics.refinement.splits else None

    def __repr__(self) -> str:
        return f"Refiner({self.numerics.refinement}, spacing={self.spacing})"

    def apply(self, state: State, site: RefinementSite) -> tuple[int, int]:
        """Split and coalesce the particles of ``state`` in place; return (splits, merges).

        Called by ``floodsph.model.stages.synchronise`` after the drift and the density
        prediction; the step then rebuilds the neighbour lists and solves density and h for
        all particles. Every call first relaxes over-smoothed particles
        (:func:`relax_smoothing`), by the compounded rate of the steps since the last call
        (several with local time stepping).
        """
        s = self.numerics
        steps = state.steps - self.last_call
        every = s.refine_merge_interval
        merge_due = state.steps // every != self.last_call // every
        self.last_call = state.steps
        if not s.refinement.splits or state.particles.n == 0:
            return 0, 0
        rate = RELAX_RATE if steps == 1 else 1.0 - (1.0 - RELAX_RATE) ** steps
        relax_smoothing(state.particles, site.domain.numerics.kappa, rate,
                        s.refine_smoothing_excess)
        parents = self.split_candidates(state, site)
        a = b = np.zeros(0, dtype=np.int64)
        if s.refinement.coalesces and merge_due:
            a, b = self.merge_pairs(state, site)
        if parents.size == 0 and a.size == 0:
            return 0, 0
        return self.execute(state, site, parents, a, b)

    def execute(self, state: State, site: RefinementSite, parents, a, b) -> tuple[int, int]:
        """Split the particles ``parents`` and merge the pairs (a[k], b[k]); return the counts.

        The index arrays refer to the current particle order and must be disjoint. The
        parents and the pairs are removed, the daughters and merged particles appended, and the
        neighbour lists dropped (``site.particles_changed``); the step rebuilds them (with the
        boundaries' ghosts) and solves density and h.
        """
        parents, a, b = (np.asarray(i, dtype=np.int64) for i in (parents, a, b))
        born = self._split(state, site, parents)
        merged = self._merged(state, site, a, b)
        if site.count_moves is not None:
            count_refinement_moves(site, state.particles, parents, a, b, born, merged)
        keep = np.ones(state.particles.n, dtype=bool)
        keep[parents] = False
        keep[a] = False
        keep[b] = False
        p = state.particles
        p.keep(keep)
        for fields in (born, merged):
            if fields is not None:
                p.append(**fields)
        site.particles_changed()
        return int(parents.size), int(a.size)

    def still(self, p) -> np.ndarray:
        """True for the particles of still water, which the balanced momentum holds at rest
        and refinement leaves alone (slower than ``STILL_SPEED``); none under the variational
        momentum."""
        if self.numerics.momentum is not Momentum.BALANCED:
            return np.zeros(p.n, dtype=bool)
        return p.u * p.u + p.v * p.v < STILL_SPEED * STILL_SPEED

    # -- splitting ---------------------------------------------------------------------------
    def split_candidates(self, state: State, site: RefinementSite) -> np.ndarray:
        """Indices of the particles to split (criteria in the module docstring)."""
        from floodsph.sph import refine

        p = state.particles
        s = self.numerics
        big = (p.m > self.area_max * p.rho) & (p.rho >= RHO_WATER * s.refine_d_min_m)
        big &= p.level < s.refine_max_level
        big &= ~self.still(p)
        for boundary in site.boundaries:
            big &= ~boundary.protected(p.x, p.y)
        idx = np.flatnonzero(big)
        if idx.size == 0:
            return idx
        h_parent = _parent_h(p, idx, site.domain.numerics.kappa, s.refine_smoothing_excess)
        x, y, _ = _daughter_positions(p, idx, h_parent)
        walled = bool(site.domain.closed_sides)
        # walled nodata slivers are wet area
        covered = site.domain.terrain.covers(x, y, valid_only=not walled)
        ok = covered.reshape(-1, refine.DAUGHTERS).all(axis=1)
        wi = site.domain.wall_index
        if wi.seg.shape[0]:
            n = idx.size
            d = refine.DAUGHTERS
            radius = np.hypot(x[1::d] - p.x[idx], y[1::d] - p.y[idx])
            near = wi.near_lists(p.x[idx], p.y[idx], radius, np.zeros(n + 1, np.int64),
                                 np.zeros(0, np.int64), HEXAGON_MARGIN)
            clear = np.empty(n, dtype=np.bool_)
            refine.daughters_clear(p.x[idx], p.y[idx], x, y, near.wstart, near.wseg, wi.seg,
                                   clear)
            ok &= clear
        return idx[ok]

    def _split(self, state: State, site: RefinementSite, idx) -> dict | None:
        """Fields of the daughters of the parents ``idx`` (None if there are none)."""
        from floodsph.sph import refine

        if idx.size == 0:
            return None
        p = state.particles
        h_parent = _parent_h(p, idx, site.domain.numerics.kappa,
                             self.numerics.refine_smoothing_excess)
        x, y, m = _daughter_positions(p, idx, h_parent)
        rep = np.repeat(idx, refine.DAUGHTERS)
        h = refine.H_FACTOR * np.repeat(h_parent, refine.DAUGHTERS)
        rho = p.rho[rep]
        return dict(x=x, y=y, u=p.u[rep], v=p.v[rep], m=m, rho=rho, h=h, h0=h, rho0=rho,
                    alpha=2.0 * rho, level=p.level[rep] + 1, born=np.full(x.size, state.steps),
                    stride=p.stride[rep], **{g: getattr(p, g)[rep] for g in INHERITED})

    # -- coalescing --------------------------------------------------------------------------
    def merge_pairs(self, state: State, site: RefinementSite) -> tuple[np.ndarray, np.ndarray]:
        """Index arrays (a, b) of the particle pairs to merge (module docstring): the mutual
        nearest candidates (a < b), then the small candidates left and their absorbers
        (:meth:`_absorptions`; a is the small one)."""
        p = state.particles
        idx = np.flatnonzero((p.m < self.area_min * p.rho)
                             & (state.steps - p.born >= self.numerics.refine_no_merge_steps)
                             & ~self.still(p))
        if idx.size:  # the wall test covers the support of the merged particle, too
            reach_h = np.maximum(p.h[idx], site.domain.numerics.kappa
                                 * np.sqrt(2.0 * p.m[idx] / p.rho[idx]))
            idx = idx[~protected(site, p.x[idx], p.y[idx], reach_h)]
        a, b = self._mutual_pairs(p, idx)
        small_a, small_b = self._absorptions(state, site, idx, np.concatenate([a, b]))
        return np.concatenate([a, small_a]), np.concatenate([b, small_b])

    def _mutual_pairs(self, p, idx) -> tuple[np.ndarray, np.ndarray]:
        """Pairs (a < b) of the candidates ``idx`` that are each other's nearest candidate.

        The nearest candidates are searched among the candidates alone, in lists of the pairs
        with r_ab < max(h_a, h_b): that holds every pair that may merge (r_ab < min(h_a, h_b)),
        and a candidate's nearest fellow, when it may merge with it, is within that range.
        """
        from floodsph.sph import refine
        from floodsph.sph.neighbours import NeighbourList

        if idx.size < 2:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        x, y = p.x[idx], p.y[idx]
        near = NeighbourList(x, y, 0.5 * p.h[idx], skin=0.0)
        nn = np.empty(idx.size, dtype=np.int64)
        refine.nearest_of(np.arange(idx.size), x, y, near.start, near.nbr,
                          np.ones(idx.size, dtype=np.bool_), nn)
        a = np.flatnonzero(nn > np.arange(idx.size))
        b = nn[a]
        mutual = nn[b] == a
        a, b = idx[a[mutual]], idx[b[mutual]]
        s = self.numerics
        d_a, d_b = p.rho[a] / RHO_WATER, p.rho[b] / RHO_WATER
        d_max = np.maximum(d_a, d_b)
        dv = np.hypot(p.u[a] - p.u[b], p.v[a] - p.v[b])
        r = np.hypot(p.x[a] - p.x[b], p.y[a] - p.y[b])
        ok = (np.abs(d_a - d_b) <= s.refine_depth_jump * d_max)
        ok &= dv <= s.refine_speed_jump * np.sqrt(GRAVITY * d_max)
        ok &= r < np.minimum(p.h[a], p.h[b])
        return a[ok], b[ok]

    def _absorptions(self, state: State, site: RefinementSite, cand,
                     paired) -> tuple[np.ndarray, np.ndarray]:
        """Pairs (t, b) in which a small particle t is absorbed by a larger neighbour b.

        t is a merge candidate left unpaired (``cand`` minus ``paired``) with an area below
        SMALL_FRACTION area_min, and b its nearest particle that is neither small nor paired;
        of the small particles with the same b only the closest is absorbed, so no particle is
        in two merges. b must be settled (born at least ``no_merge_steps`` ago), away from
        walls and open boundaries (:func:`protected`, over the merged particle's lattice
        support), closer than h_b, with A_t + A_b < 2 area_min (the merged particle does not
        split at once) and |v_t - v_b| <= speed_jump sqrt(g d_b). There is no depth test
        (across a bore or a front the speeds differ too): with h below half of its
        neighbours', t's own summed depth is mostly its self term and its nearest neighbour's,
        2.9 m in 1 m of water 0.24 m from a neighbour (``tests/sph/test_refine.py``).
        """
        from floodsph.sph import refine
        from floodsph.sph.neighbours import NeighbourList

        p = state.particles
        empty = np.zeros(0, dtype=np.int64)
        small = np.setdiff1d(cand[p.m[cand] < SMALL_FRACTION * self.area_min * p.rho[cand]],
                             paired)
        if small.size == 0:
            return empty, empty
        n = p.n
        near = NeighbourList(p.x[:n], p.y[:n], 0.5 * p.h[:n], skin=0.0, rows=small)
        partner = np.ones(n, dtype=np.bool_)
        partner[paired] = False
        partner[small] = False
        partner &= state.steps - p.born[:n] >= self.numerics.refine_no_merge_steps
        nn = np.full(n, -1, dtype=np.int64)
        refine.nearest_of(small, p.x, p.y, near.start, near.nbr, partner, nn)
        t = small[nn[small] >= 0]
        b = nn[t]
        # of the small particles that chose the same b, keep the closest
        r = np.hypot(p.x[t] - p.x[b], p.y[t] - p.y[b])
        first = np.lexsort((t, r, b))
        keep = np.ones(first.size, dtype=bool)
        keep[1:] = b[first[1:]] != b[first[:-1]]
        t, b, r = t[first[keep]], b[first[keep]], r[first[keep]]
        dv = np.hypot(p.u[t] - p.u[b], p.v[t] - p.v[b])
        ok = (dv <= self.numerics.refine_speed_jump * np.sqrt(GRAVITY * p.rho[b] / RHO_WATER))
        ok &= r < p.h[b]
        ok &= p.m[t] / p.rho[t] + p.m[b] / p.rho[b] < 2.0 * self.area_min
        t, b = t[ok], b[ok]
        if t.size:
            reach_h = np.maximum(p.h[b], site.domain.numerics.kappa
                                 * np.sqrt((p.m[t] + p.m[b]) / p.rho[b]))
            clear = ~protected(site, p.x[b], p.y[b], reach_h)
            t, b = t[clear], b[clear]
        return t, b

    @staticmethod
    def _merged(state: State, site: RefinementSite, a, b) -> dict | None:
        """Fields of the particles merged from the pairs (a, b) (None if there are none)."""
        from floodsph.sph import refine

        if a.size == 0:
            return None
        p = state.particles
        out = np.empty((a.size, 7))
        refine.merge_pairs(a, b, p.x, p.y, p.u, p.v, p.m, p.rho, p.h,
                           site.domain.numerics.kappa, out)
        rho, h = out[:, 5], out[:, 6]
        wa = p.m[a] / (p.m[a] + p.m[b])
        inherited = {g: wa * getattr(p, g)[a] + (1.0 - wa) * getattr(p, g)[b]
                     for g in INHERITED}
        return dict(x=out[:, 0], y=out[:, 1], u=out[:, 2], v=out[:, 3], m=out[:, 4], rho=rho,
                    h=h, h0=h, rho0=rho, alpha=2.0 * rho, **inherited,
                    level=np.minimum(p.level[a], p.level[b]), born=np.full(a.size, state.steps),
                    stride=np.minimum(p.stride[a], p.stride[b]))


def relax_smoothing(p, kappa: float, rate: float = RELAX_RATE,
                    excess: float = SMOOTHING_EXCESS) -> None:
    """Relax over-smoothed particles toward h^2 rho = excess kappa^2 m.

    The density solve keeps C_i = h0_i^2 rho0_i = h_i^2 rho_i fixed. A daughter starts with
    C = (0.9 h_p)^2 rho_p, about 5.7 times kappa^2 m_k, and a second split compounds it, so
    its neighbour count and smoothing grow with every generation (``docs/method.md`` §6).
    Each step, ln C moves by ``rate`` of the way to ln(excess kappa^2 m) where C
    exceeds it; h0 and the current h (the Newton guess) are rescaled alike, so the density
    solve follows in a few iterations and the excess is gone about 10 steps after a split.

    Particles at a wet/dry edge keep their smoothing: those whose kernel support is short of
    neighbours, alpha_i < EDGE_ALPHA 2 rho_i (alpha_i = 2 rho_i with full support on a
    lattice, and 0 for a lone particle, whose density is its own term m_i W(0, h_i)). Changing
    C is not part of the variational dynamics, so it does work on the water. Inside the water
    that work is small, but at an edge shrinking h raises the particle's own term, which grows
    as 1 / h^2, and with it the depth and the pressure that push the edge forward: the thin
    front of a refined dam break ran at up to 28 m/s, 40 % above the bound 2 sqrt(g d0) of the
    exact solution (``tests/sph/test_refine.py``).
    """
    target = excess * kappa * kappa * p.m
    c = p.h0 * p.h0 * p.rho0
    over = np.flatnonzero((c > target * (1.0 + 1e-9)) & (p.alpha >= EDGE_ALPHA * 2.0 * p.rho))
    if over.size:
        f = np.sqrt((target[over] / c[over]) ** rate)
        p.h0[over] *= f
        p.h[over] *= f


def _daughter_positions(p, idx, h_parent: np.ndarray):
    """Positions [m] and masses [kg] of the seven daughters of each parent ``idx``: a centre and
    a hexagon of radius eps h_parent [m], turned along the parent's velocity
    (``floodsph.sph.refine.daughters``, ``docs/method.md`` §6)."""
    from floodsph.sph import refine

    n = refine.DAUGHTERS * idx.size
    x, y, m = np.empty(n), np.empty(n), np.empty(n)
    refine.daughters(p.x[idx], p.y[idx], p.u[idx], p.v[idx], p.m[idx], h_parent, refine.EPS,
                     refine.STILL_SPEED, x, y, m)
    return x, y, m


def _parent_h(p, idx, kappa: float, excess: float) -> np.ndarray:
    """Smoothing lengths [m] the parents ``idx`` pass on to their daughters: h_p, but at most
    the relaxed value sqrt(excess) kappa sqrt(m_p / rho_p) (``excess``: see
    :func:`relax_smoothing`).

    A parent at a wet/dry edge is not relaxed (:func:`relax_smoothing`) and may still carry a
    daughter's inflated h. Passing that on would compound it generation by generation: the
    daughters of a daughter born 5.7 times over its relaxed h^2 rho would start at 34 times
    (in the refined 5 m Ritter run, the largest excess seen is 10.2 without this bound and
    5.9 with it).
    """
    return np.minimum(p.h[idx], math.sqrt(excess) * kappa
                      * np.sqrt(p.m[idx] / p.rho[idx]))
