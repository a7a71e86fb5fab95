"""Water over a crest wall: a broad-crested weir along the wall, exact in mass.

A wall with a crest (``[[walls]] crest_m``) stays a wall to the particles (they never cross
it), but where the water on one side stands above its crest, water passes over it as over a
broad-crested weir (``docs/structures.md`` §2). Per metre of crest, in free flow,

    q = C sqrt(g) H_u^(3/2),   H_u = eta_u - z_c                       (1)

with eta_u the upstream level and z_c the crest [m]; C = (2/3)^(3/2) = 0.544 for an ideal
broad crest (critical depth 2 H_u / 3 on the crest; Henderson, Open Channel Flow (1966)),
i.e. C sqrt(g) = 1.705 m^0.5/s. With the downstream level above the crest (H_d = eta_d - z_c
> 0) the flow is reduced as Villemonte (1947) found, "Submerged weir discharge studies",
Engineering News-Record 139, 866-869:

    q_s = q (1 - (H_d / H_u)^n)^0.385,   n = 3/2                       (2)

Scheme: the wall is cut into pieces about one particle spacing long. Each particle within
3.5 h0 of a piece's midpoint (its nearest piece) belongs to that piece's side. Each step the
level on each side is the mean of d + b over those particles, weighted by their area m / rho
and the kernel W(r, h0) of the distance r to the point 1.5 h0 off the midpoint on that side
(no particle: a dry side, no level). The
higher side is upstream; (1)-(2) give the piece's discharge Q = q L, and Q dt is owed to the
downstream side. Once a piece owes a particle's worth, V_e = d_e L dx with d_e the larger of
the critical depth (q^2 / g)^(1/3) and the downstream depth, that volume (at most half the
water of the piece's upstream side) is taken from its upstream particles nearest the wall
first (one left with less than a quarter of a lattice particle, m < rho dx^2 / 4, is taken
whole: taking from all in proportion to their mass left a layer of ever smaller particles
against the wall, which read the level low) and injected as one new particle half a
spacing downstream of the piece, moving away from the wall at q / d_e (critical flow
sqrt(g d_c) when free). The mass taken is the mass injected, to the last bit, so the weir
leaves the water volume unchanged; the volume passed each way is counted
(:meth:`Weir.summary`, run.json's ``walls_overtopped_m3``).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from floodsph.boundaries.crest import Crest
from floodsph.boundaries.protocol import Site, Water
from floodsph.constants import GRAVITY, RHO_WATER
from floodsph.sph.kernels import seeded_smoothing_length

IDEAL_COEFFICIENT = (2.0 / 3.0) ** 1.5
"""C of (1) for an ideal broad crest, (2/3)^(3/2) = 0.5443 (critical flow on the crest)."""
VILLEMONTE_N = 1.5
"""Villemonte's exponent n of (2): 3/2, the exponent of the free weir law (1)."""
VILLEMONTE_POWER = 0.385
"""The power of Villemonte's submergence factor (2)."""
DEPTH_MIN_M = 1e-3
"""Least depth d_e [m] of an injected particle."""
GAUGE_OFFSET = 1.5
"""The level of a side is measured around the point this many h0 from the piece's midpoint,
off the layer next to the wall that the withdrawal thins (the approach level)."""
TAKE_MAX = 0.5
"""At most this fraction of the water on a piece's upstream side is taken at once."""
KEEP_MIN = 0.25
"""A particle left with less than this many lattice particles' mass rho dx^2 is taken whole."""


def unit_discharge(head_up, head_down=0.0, coefficient: float = IDEAL_COEFFICIENT):
    """Discharge per metre of crest q [m2/s] of (1)-(2) for heads H_u, H_d above the crest [m].

    q = 0 where H_u <= 0; H_d is clipped to [0, H_u] (free flow below the crest, no flow at
    equal levels).
    """
    hu = np.asarray(head_up, dtype=np.float64)
    positive = np.isfinite(hu) & (hu > 0.0)
    hu_safe = np.where(positive, hu, 1.0)
    hd = np.clip(np.nan_to_num(np.asarray(head_down, dtype=np.float64), nan=0.0,
                               neginf=0.0), 0.0, None)
    ratio = np.clip(hd / hu_safe, 0.0, 1.0)
    free = coefficient * math.sqrt(GRAVITY) * hu_safe ** 1.5
    q = free * (1.0 - ratio ** VILLEMONTE_N) ** VILLEMONTE_POWER
    return np.where(positive, q, 0.0)


def bed_at(terrain, x, y) -> np.ndarray:
    """Bilinear sample of the terrain's node-centred elevation at points (x, y) [m], as the
    particles see it (``floodsph.sph.bed``)."""
    b = terrain.elevation
    ny, nx = b.shape
    fx = np.asarray(x, dtype=np.float64) / terrain.dx - 0.5
    fy = np.asarray(y, dtype=np.float64) / terrain.dy - 0.5
    j0 = np.clip(np.floor(fx).astype(np.int64), 0, nx - 2)
    i0 = np.clip(np.floor(fy).astype(np.int64), 0, ny - 2)
    tx = np.clip(fx - j0, 0.0, 1.0)
    ty = np.clip(fy - i0, 0.0, 1.0)
    return ((1.0 - ty) * ((1.0 - tx) * b[i0, j0] + tx * b[i0, j0 + 1])
            + ty * ((1.0 - tx) * b[i0 + 1, j0] + tx * b[i0 + 1, j0 + 1]))


def _kernel(q: np.ndarray) -> np.ndarray:
    """The cubic spline's shape at r / h = q (unnormalised; only ratios are used)."""
    return np.where(q <= 1.0, 1.0 - 1.5 * q * q + 0.75 * q ** 3,
                    np.where(q <= 2.0, 0.25 * np.clip(2.0 - q, 0.0, None) ** 3, 0.0))


class Weir:
    """A crest wall that passes water over its crest (module docstring).

    Parameters
    ----------
    crest : Crest
        The wall (its polyline in local coordinates) and its crest along it, with its breach.
    spacing, kappa : float
        Particle spacing dx [m] and h / dx.
    coefficient : float
        C of (1), dimensionless.
    name : str
        Key path for reports, e.g. ``"walls[0]"``.
    """

    opening = None
    """No section: the wall stays a wall to the particles (``Boundary.opening``)."""
    STATE = ("owed", "emitted", "volume_to_right", "volume_to_left", "discharge", "head",
             "levels")
    """What changes during a run (``Boundary.STATE``): each piece's volume owed, particles
    emitted, last discharge, head and levels, and the volumes passed each way."""

    def __init__(self, crest: Crest, spacing: float, kappa: float,
                 coefficient: float = IDEAL_COEFFICIENT, name: str = "walls[0]"):
        self.crest = crest
        self.name = name
        self.coefficient = float(coefficient)
        self.dx = float(spacing)
        self.kappa = float(kappa)
        self.h0 = seeded_smoothing_length(kappa, spacing)
        self.reach = 2.0 * self.h0
        mids, tangents, lengths, chain = [], [], [], []
        pts = crest.polyline
        for k in range(pts.shape[0] - 1):
            a, b = pts[k], pts[k + 1]
            seg = float(np.hypot(*(b - a)))
            if seg == 0.0:
                continue
            n = max(1, int(round(seg / spacing)))
            f = (np.arange(n) + 0.5) / n
            mids.append(a + f[:, None] * (b - a))
            tangents.append(np.repeat(((b - a) / seg)[None, :], n, axis=0))
            lengths.append(np.full(n, seg / n))
            chain.append(crest.s[k] + f * seg)
        self.mid = np.concatenate(mids)
        self.tangent = np.concatenate(tangents)
        self.normal = np.column_stack([-self.tangent[:, 1], self.tangent[:, 0]])
        self.length = np.concatenate(lengths)
        self.chainage = np.concatenate(chain)
        self.pieces = self.mid.shape[0]
        self._tree = cKDTree(self.mid)
        lo = pts.min(axis=0) - 2.0 * self.reach
        hi = pts.max(axis=0) + 2.0 * self.reach
        self._box = (lo, hi)
        self.owed = np.zeros(self.pieces)
        self.emitted = np.zeros(self.pieces, dtype=np.int64)
        self.volume_to_right = 0.0
        self.volume_to_left = 0.0
        self.discharge = np.zeros(self.pieces)
        self.head = np.full(self.pieces, -np.inf)
        self.levels = np.full((self.pieces, 2), -np.inf)

    # -- geometry --------------------------------------------------------------------------
    def _near(self, x, y, reach):
        """(indices, piece, distance) of the points within ``reach`` of a piece's midpoint."""
        lo, hi = self._box
        cand = np.flatnonzero((x >= lo[0]) & (x <= hi[0]) & (y >= lo[1]) & (y <= hi[1]))
        if cand.size == 0:
            return cand, cand, np.zeros(0)
        dist, piece = self._tree.query(np.column_stack([x[cand], y[cand]]),
                                       distance_upper_bound=reach)
        ok = np.isfinite(dist)
        return cand[ok], piece[ok], dist[ok]

    def crest_now(self, t: float) -> np.ndarray:
        """The crest [m] of each piece at time t [s]."""
        return self.crest.at(self.chainage, t)

    # -- the levels on both sides ----------------------------------------------------------
    def measure(self, p, site: Site):
        """Levels [m] on both sides of every piece, (pieces, 2): side 1 is the side the piece
        normal (the tangent turned left) points to; -inf where dry. Also returns the members
        (particle indices, piece, side) and the mean depths (pieces, 2) [m]."""
        idx, piece, _ = self._near(p.x, p.y, self.reach + GAUGE_OFFSET * self.h0)
        rel_x = p.x[idx] - self.mid[piece, 0]
        rel_y = p.y[idx] - self.mid[piece, 1]
        normal = rel_x * self.normal[piece, 0] + rel_y * self.normal[piece, 1]
        side = (normal > 0.0).astype(np.int64)
        along = rel_x * self.tangent[piece, 0] + rel_y * self.tangent[piece, 1]
        off = np.abs(normal) - GAUGE_OFFSET * self.h0
        dist = np.hypot(along, off)  # from the gauge point of the particle's side
        depth = p.rho[idx] / RHO_WATER
        if site.balanced:
            depth = depth + p.eta_offset[idx]
        eta = depth + bed_at(site.terrain, p.x[idx], p.y[idx])
        w = p.m[idx] / p.rho[idx] * _kernel(dist / self.h0)
        cell = 2 * piece + side
        size = 2 * self.pieces
        wsum = np.bincount(cell, w, size)
        with np.errstate(invalid="ignore", divide="ignore"):
            level = np.where(wsum > 0.0, np.bincount(cell, w * eta, size) / wsum, -np.inf)
            mean_depth = np.where(wsum > 0.0, np.bincount(cell, w * depth, size) / wsum, 0.0)
        return level.reshape(-1, 2), (idx, piece, side), mean_depth.reshape(-1, 2)

    # -- the boundary protocol -------------------------------------------------------------
    def apply(self, water: Water, site: Site, dt: float) -> None:
        """Pass Q dt over each piece's crest (module docstring), exactly in mass."""
        p = water.particles
        if dt <= 0.0 or p.n == 0:
            return
        t = water.t + dt
        level, (idx, piece, side), depth = self.measure(p, site)
        crest = self.crest_now(t)
        up = np.argmax(level, axis=1)
        rows = np.arange(self.pieces)
        head_up = level[rows, up] - crest
        head_down = level[rows, 1 - up] - crest
        q = unit_discharge(head_up, head_down, self.coefficient)
        self.levels = level
        self.head = head_up
        self.discharge = q * self.length
        flowing = self.discharge > 0.0
        self.owed = np.where(flowing, self.owed + self.discharge * dt, np.minimum(self.owed, 0.0))
        d_crit = np.cbrt(q * q / GRAVITY)
        d_e = np.maximum(np.maximum(d_crit, depth[rows, 1 - up]), DEPTH_MIN_M)
        due = np.flatnonzero(flowing & (self.owed >= d_e * self.length * self.dx))
        if due.size == 0:
            return
        cell = 2 * piece + side
        order = np.argsort(cell, kind="stable")
        starts = np.searchsorted(cell[order], 2 * due + up[due])
        ends = np.searchsorted(cell[order], 2 * due + up[due], side="right")
        drop = np.zeros(p.n, dtype=bool)
        new = []
        for k, a, b in zip(due, starts, ends, strict=True):
            members = idx[order[a:b]]
            members = members[~drop[members]]
            if members.size == 0:
                continue
            gap = np.abs((p.x[members] - self.mid[k, 0]) * self.normal[k, 0]
                         + (p.y[members] - self.mid[k, 1]) * self.normal[k, 1])
            mass = self._take(p, site.balanced, members, gap,
                              d_e[k] * self.length[k] * self.dx, drop)
            if mass <= 0.0:
                continue
            volume = mass / RHO_WATER
            self.owed[k] -= volume
            if up[k] == 1:
                self.volume_to_right += volume
            else:
                self.volume_to_left += volume
            new.append(self._particle(int(k), int(up[k]), mass, float(d_e[k]), float(q[k])))
        if drop.any():
            p.keep(~drop)
        if new:
            fields = {key: np.array([n[key] for n in new]) for key in new[0]}
            p.append(**fields, born=water.steps)

    def _take(self, p, balanced: bool, members: np.ndarray, wall_distance: np.ndarray,
              volume: float, drop: np.ndarray) -> float:
        """Take about ``volume`` [m3] from the particles ``members`` nearest the wall first
        (module docstring); mark those taken whole in ``drop``; return the mass taken [kg]."""
        order = np.argsort(wall_distance, kind="stable")
        members = members[order]
        m = p.m[members]
        total = float(m.sum())
        want = min(volume * RHO_WATER, TAKE_MAX * total)
        before = np.concatenate([[0.0], np.cumsum(m)[:-1]])
        taken = np.clip(want - before, 0.0, m)
        left = m - taken
        whole = (left < KEEP_MIN * p.rho[members] * self.dx * self.dx) & (taken > 0.0)
        taken[whole] = m[whole]
        part = (taken > 0.0) & ~whole
        mass = float(np.sum(taken))
        cut = members[part]
        keep = (m[part] - taken[part]) / m[part]
        p.m[cut] = m[part] - taken[part]
        p.h0[cut] *= np.sqrt(keep)  # h = h0 (rho0 / rho)^(1/2) with rho0 h0^2 ~ m
        drop[members[whole]] = True
        if balanced:
            from floodsph.sph.level_offsets import HELD, RELEASED

            held = cut[p.bank_held[cut] == HELD]
            p.bank_held[held] = RELEASED
        return mass

    def _particle(self, k: int, up: int, mass: float, depth: float, q: float) -> dict:
        """The fields of the particle injected downstream of piece k."""
        n_down = self.normal[k] * (-1.0 if up == 1 else 1.0)
        jitter = ((self.emitted[k] * 0.6180339887) % 1.0 - 0.5) * 0.5 * self.length[k]
        self.emitted[k] += 1
        pos = self.mid[k] + 0.5 * self.dx * n_down + jitter * self.tangent[k]
        speed = q / depth
        rho = RHO_WATER * depth
        return {"x": pos[0], "y": pos[1], "u": speed * n_down[0], "v": speed * n_down[1],
                "m": mass, "rho": rho, "h": self.kappa * math.sqrt(mass / rho)}

    def add_ghosts(self, p) -> None:
        """A weir has no ghosts."""

    def impose(self, p, lists) -> None:
        """A weir imposes no state."""

    def max_dt(self, cfl: float) -> float:
        """No limit of its own [s]: the injected particles take the water's CFL step."""
        return math.inf

    def protected(self, x, y) -> np.ndarray:
        """Particles within 4 h0 of the wall's pieces (no coalescing; the finest local step)."""
        mask = np.zeros(np.shape(x)[0], dtype=bool)
        idx, _, _ = self._near(x, y, 2.0 * self.reach)
        mask[idx] = True
        return mask

    @property
    def volume_passed(self) -> float:
        """The volume passed over the wall so far [m3], both ways."""
        return self.volume_to_right + self.volume_to_left

    @property
    def volume_net(self) -> float:
        """The volume passed from the left of the wall to its right [m3], less that passed the
        other way (left and right looking along the polyline from its first vertex)."""
        return self.volume_to_right - self.volume_to_left

    def summary(self) -> dict:
        """The volumes passed over the wall so far [m3], each way, for run.json."""
        return {"left_to_right_m3": float(self.volume_to_right),
                "right_to_left_m3": float(self.volume_to_left)}

    def __repr__(self) -> str:
        return (f"Weir({self.name}, {self.pieces} pieces over {self.crest.length:g} m, "
                f"{self.volume_passed:.6g} m3 passed)")
