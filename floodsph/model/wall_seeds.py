"""Still-water seeds by walls, settled and their masses matched when the model is set up.

The kernels and constants are ``floodsph.walls.seeding``'s (its module docstring gives the
method); this module drives them on the parts of a model being set up
(``floodsph.model.stages.Parts``), solving density and forces for the rows they may change
(``floodsph.model.stages.interactions(settle=True, rows=...)``).
"""

from __future__ import annotations

import numpy as np

from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.model.stages import Parts, interactions, stable_dt
from floodsph.sph.bed import BED
from floodsph.walls import seeding as wall_seeding


def settle_at_walls(parts: Parts, rho_seed: np.ndarray) -> float:
    """Settle the seeds of still water next to walls, then match their depth to the seeded
    rho_seed / rho_w [kg m^-2 / kg m^-3 = m]; return the volume change [m3]. The counters
    ``seeds_settled`` and ``settle_steps`` record what was done."""
    idx = wall_seeds(parts, rho_seed)
    parts.state.counters["seeds_settled"] = int(idx.size)
    if idx.size == 0:
        return 0.0
    nl = parts.work.nl
    assert nl is not None  # built by the set-up's first solve
    rows = wall_seeding.neighbourhood(idx, nl.start, nl.nbr, parts.state.particles.n,
                                      wall_seeding.RINGS)
    rounds = _settle(parts, idx, rows)
    v0 = parts.state.particles.volume()
    rounds += _match_masses(parts, idx, rho_seed[idx], rows)
    if rounds:  # lists and sums of every particle again, for the first step
        interactions(parts.domain, parts.state, parts.work, parts.boundaries, settle=True)
    return parts.state.particles.volume() - v0


def wall_seeds(parts: Parts, rho_seed: np.ndarray) -> np.ndarray:
    """Indices of the lattice seeds (m = rho_seed spacing^2) near a wall, out of open
    boundaries' zones, in still water (``wall_seeding.still_water``) and enclosed within
    ``wall_seeding.ENCLOSURE`` h (``wall_seeding.enclosed_seeds``)."""
    p, nl = parts.state.particles, parts.work.nl
    dx = parts.domain.numerics.particle_spacing_m
    assert nl is not None and dx is not None  # the set-up's first solve; set_up_model's check
    near_walls = parts.work.walls_near
    assert near_walls is not None  # the set-up's first solve
    n = p.n
    candidate = np.abs(p.m - rho_seed * dx * dx) <= 1e-9 * p.m
    candidate &= np.diff(near_walls.wstart[:n + 1]) > 0
    for boundary in parts.boundaries:
        candidate &= ~boundary.protected(p.x, p.y)
    everyone = np.arange(n, dtype=np.int64)
    still = np.empty(n, dtype=np.bool_)
    wall_seeding.still_water(everyone, nl.start, nl.nbr, n, p.u, p.v, parts.state.bed[:n, BED],
                             rho_seed / RHO_WATER, wall_seeding.LEVEL_TOLERANCE, still)
    rows = np.flatnonzero(candidate)
    calm = np.empty(rows.size, dtype=np.bool_)
    wall_seeding.with_neighbours(rows, nl.start, nl.nbr, n, still, calm)
    rows = rows[calm]
    near = parts.domain.wall_index.near_lists(p.x, p.y, p.h, np.zeros(n + 1, dtype=np.int64),
                                       np.zeros(0, dtype=np.int64), wall_seeding.ENCLOSURE)
    return wall_seeding.enclosed_seeds(p.x, p.y, wall_seeding.ENCLOSURE * p.h, rows, dx,
                                       near.wstart, near.wseg, parts.domain.seg)


def _settle(parts: Parts, idx: np.ndarray, rows: np.ndarray) -> int:
    """Move the particles ``idx`` by a dt^2 / 2 per round, along their acceleration (walls
    reflecting), with dt the model's CFL step, each at most ``wall_seeding.MAX_SHIFT``
    spacings in all from its seed, the others held, until |a| < ``wall_seeding.SETTLED`` g or
    for ``wall_seeding.SETTLE_STEPS`` rounds. Each round solves density and forces for
    ``rows`` alone: ``idx`` and every particle whose density they may change. Returns the
    number of rounds."""
    p = parts.state.particles
    x0, y0 = p.x[idx].copy(), p.y[idx].copy()
    mx, my = np.zeros(p.n), np.zeros(p.n)
    spacing = parts.domain.numerics.particle_spacing_m
    assert spacing is not None  # set_up_model refuses a model without it
    limit = wall_seeding.MAX_SHIFT * spacing
    taken = 0
    while (taken < wall_seeding.SETTLE_STEPS
           and np.hypot(p.ax[idx], p.ay[idx]).max() >= wall_seeding.SETTLED * GRAVITY):
        dt = stable_dt(parts.domain, parts.state, parts.boundaries)
        mx[idx], my[idx] = wall_seeding.limited_move(p.ax[idx], p.ay[idx], dt,
                                                     p.x[idx] - x0, p.y[idx] - y0, limit)
        parts.domain.wall_index.drift(p.x, p.y, mx, my, 1.0)
        interactions(parts.domain, parts.state, parts.work, parts.boundaries, settle=True,
                     rows=rows)
        taken += 1
    parts.state.counters["settle_steps"] = taken
    return taken


def _match_masses(parts: Parts, idx: np.ndarray, rho_target: np.ndarray,
                  rows: np.ndarray) -> int:
    """Jacobi iteration m_i <- m_i rho_target_i / rho_i on the particles ``idx``, each mass
    kept within [``MASS_MIN``, ``MASS_MAX``] times its start (``wall_seeding``); density and
    forces solved for ``rows`` alone (:func:`_settle`). Returns the number of solves."""
    p = parts.state.particles
    m0 = p.m[idx].copy()
    solves = 0
    while solves < wall_seeding.ROUNDS:
        ratio = rho_target / p.rho[idx]
        if np.abs(ratio - 1.0).max() < wall_seeding.TOLERANCE:
            break
        p.m[idx] = np.clip(p.m[idx] * ratio, wall_seeding.MASS_MIN * m0,
                           wall_seeding.MASS_MAX * m0)
        interactions(parts.domain, parts.state, parts.work, parts.boundaries, settle=True,
                     rows=rows)
        solves += 1
    return solves
