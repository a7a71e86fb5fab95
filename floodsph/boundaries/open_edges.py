"""Open DEM edges: an outflow buffer of departed particles with the interior state imposed.

Method (``docs/method.md`` §8, open edges): fluid particles that cross an open side of the
DEM rectangle leave the model - their volume is counted as outflow - and become buffer
particles that keep moving outwards until they are farther than the kernel reach 2 h (1 + skin)
beyond the edge. Every step the buffer takes part in the neighbour search as ghosts, and after
the density solve each buffer particle is given the interior state, a Shepard average over its
fluid neighbours (the "inner" state d_I, v_I):

    d_I = sum_j V_j d_j W(r_ij, h_i) / sum_j V_j W(r_ij, h_i),  V_j = m_j / rho_j,

and the same for v_I. This imposes a zero normal gradient of depth and velocity, the
transmissive condition of finite-volume codes (Toro, Shock-capturing methods for free-surface
shallow flows, 2001, section 6.2): supercritical outflow carries its state out, and subcritical
outflow whose boundary state equals the interior state passes without a reflected wave. The
buffer moves with its imposed velocity, whose normal component is kept outward (>= 0): an open
edge lets water out, never in. The pressure force weighs each neighbour by rho / alpha, so the
buffer also carries the water's alpha: with the continuum value alpha = 2 rho instead of the
lattice's 2.02 rho, a uniform subcritical flow backs up by several per cent.

Because the buffer particles are the departed fluid particles themselves, the particle spacing
is continuous across the edge. At the start the buffer is seeded with the mirror image of the
water within reach of the edge, which continues the seeding lattice, so still water at an
open edge stays still.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from floodsph.boundaries.protocol import Site, Water
from floodsph.constants import RHO_WATER
from floodsph.sph.kernels import w_cubic

SIDES = ("west", "east", "south", "north")
_BUFFER_FIELDS = ("x", "y", "area", "h", "rho", "alpha", "u", "v")


@njit(parallel=True, cache=True)
def shepard_state(first, last, n_water, x, y, m, rho, alpha, u, v, h, start, nbr, out):
    """Shepard averages over the water neighbours of the ghosts first..last-1.

    out[k] = (sum_j V_j W_ij, d_I, u_I, v_I, (alpha/rho)_I) for ghost i = first + k, with
    V_j = m_j / rho_j, W_ij = W(r_ij, h_i) and only water particles j < n_water;
    d_I = rho_I / rho_w [m], u, v [m/s], alpha / rho [-] (the grad-h factor, 2 on an exact
    lattice, which the pressure force weighs each neighbour by). A ghost without water
    neighbours gets a zero weight sum.
    """
    for k in prange(last - first):
        i = first + k
        sw = 0.0
        sd = 0.0
        su = 0.0
        sv = 0.0
        sa = 0.0
        for jj in range(start[i], start[i + 1]):
            j = nbr[jj]
            if j >= n_water:
                continue
            r = math.hypot(x[i] - x[j], y[i] - y[j])
            w = m[j] / rho[j] * w_cubic(r, h[i])
            sw += w
            sd += w * rho[j]
            su += w * u[j]
            sv += w * v[j]
            sa += w * alpha[j] / rho[j]
        out[k, 0] = sw
        if sw > 0.0:
            out[k, 1] = sd / sw / RHO_WATER
            out[k, 2] = su / sw
            out[k, 3] = sv / sw
            out[k, 4] = sa / sw


def _outwards(u, v, side):
    """The velocity with its component normal to ``side`` made outward (or zero)."""
    if side == "west":
        return np.minimum(u, 0.0), v
    if side == "east":
        return np.maximum(u, 0.0), v
    if side == "south":
        return u, np.minimum(v, 0.0)
    return u, np.maximum(v, 0.0)


class OpenEdges:
    """Outflow through the open sides of the DEM rectangle [0, W] x [0, H].

    Parameters
    ----------
    width, height : float
        Extent of the local domain [m].
    sides : iterable of str
        Open sides among ``"west", "east", "south", "north"``.
    """

    STATE = ("buffer", "reach", "volume_out", "volume_out_sides", "seeded")
    """What changes during a run (``Boundary.STATE``): the buffer particles, their reach,
    the volumes out (in all and by side) and whether the buffer was seeded."""

    def __init__(self, width: float, height: float, sides):
        self.width = float(width)
        self.height = float(height)
        self.sides = tuple(s for s in SIDES if s in set(sides))
        self.buffer = {name: np.zeros(0) for name in _BUFFER_FIELDS}
        self.reach = 0.0
        self.volume_out = 0.0
        self.volume_out_sides = dict.fromkeys(self.sides, 0.0)
        self.seeded = False
        self._ghosts = slice(0, 0)

    def _beyond(self, x, y) -> np.ndarray:
        """(k, n) distances beyond each open side [m] (negative inside)."""
        full = {"west": -x, "east": x - self.width, "south": -y, "north": y - self.height}
        return np.array([full[side] for side in self.sides]).reshape(len(self.sides), -1)

    def _mirror(self, x, y, side):
        if side == "west":
            return -x, y
        if side == "east":
            return 2.0 * self.width - x, y
        if side == "south":
            return x, -y
        return x, 2.0 * self.height - y

    # -- the boundary protocol -------------------------------------------------------------
    def apply(self, water: Water, site: Site, dt: float) -> None:
        """Move the buffer, take in the water that crossed an open side, drop what left reach."""
        p = water.particles
        self._update_reach(p, site.neighbour_skin)
        if not self.seeded:
            self._seed(p)
            self.seeded = True
        b = self.buffer
        b["x"] += b["u"] * dt
        b["y"] += b["v"] * dt
        if p.n and self.sides:
            beyond = self._beyond(p.x, p.y)
            crossed = (beyond > 0.0).any(axis=0)
            if crossed.any():
                volume = float(p.m[crossed].sum()) / RHO_WATER
                self.volume_out += volume
                water.volume_out += volume
                self._count_sides(p.m[crossed], beyond[:, crossed])
                self._take(p, crossed)
                p.keep(~crossed)
        inside_reach = (self._beyond(b["x"], b["y"]) < self.reach).all(axis=0)
        for name in _BUFFER_FIELDS:
            b[name] = b[name][inside_reach]

    def _count_sides(self, m, beyond) -> None:
        """Add the volume m / rho_w [m3] of particles that left to the side each is furthest
        beyond (``beyond``: their (k, n) distances past the open sides; a corner goes to one)."""
        side = np.argmax(beyond, axis=0)
        volume = np.bincount(side, m, minlength=len(self.sides)) / RHO_WATER
        for name, v in zip(self.sides, volume, strict=True):
            self.volume_out_sides[name] += float(v)

    def _update_reach(self, p, skin: float) -> None:
        h = p.h
        reach = 0.0
        if p.n and self.sides:
            near = (self._beyond(p.x, p.y) > -2.0 * h).any(axis=0)
            if near.any():
                reach = 2.0 * float(h[near].max()) * (1.0 + skin)
        self.reach = reach

    def _take(self, p, mask) -> None:
        b = self.buffer
        new = {"x": p.x, "y": p.y, "area": p.m / p.rho, "h": p.h, "rho": p.rho,
               "alpha": p.alpha, "u": p.u, "v": p.v}
        for name in _BUFFER_FIELDS:
            b[name] = np.concatenate([b[name], new[name][mask]])

    def _seed(self, p) -> None:
        """Mirror the water within reach of each open side (and of open corners) across it.

        The mirror images keep the velocity of their source, with the normal component made
        outward, so that the seeded buffer never moves into the domain.
        """
        if not p.n or not self.sides:
            return
        beyond = dict(zip(self.sides, self._beyond(p.x, p.y), strict=True))
        groups: list[tuple[str, ...]] = [(side,) for side in self.sides]
        groups += [(a, b) for a in ("west", "east") for b in ("south", "north")
                   if a in beyond and b in beyond]
        for group in groups:
            mask = np.ones(p.n, dtype=bool)
            for side in group:
                mask &= beyond[side] > -self.reach
            x, y = p.x[mask], p.y[mask]
            u, v = p.u[mask], p.v[mask]
            for side in group:
                x, y = self._mirror(x, y, side)
                u, v = _outwards(u, v, side)
            b = self.buffer
            new = {"x": x, "y": y, "area": p.m[mask] / p.rho[mask], "h": p.h[mask],
                   "rho": p.rho[mask], "alpha": p.alpha[mask], "u": u, "v": v}
            for name in _BUFFER_FIELDS:
                b[name] = np.concatenate([b[name], new[name]])

    def add_ghosts(self, p) -> None:
        """Append the buffer as ghost particles."""
        b = self.buffer
        self._ghosts = p.append(x=b["x"], y=b["y"], m=b["rho"] * b["area"], rho=b["rho"],
                                alpha=b["alpha"], h=b["h"], u=b["u"], v=b["v"])

    def impose(self, p, lists) -> None:
        """Give each buffer particle the Shepard state of its water neighbours.

        Depth, velocity and alpha are the Shepard averages; the velocity's component normal
        to the side the particle is beyond is made outward (>= 0), and the buffer moves on
        with it. A particle without water neighbours keeps its previous state. Each buffer
        particle keeps the area A = m / rho and the h it left with; its mass is rho_I A, so
        that the mass density beyond the edge continues the depth inside it (zero gradient),
        also when a wave reaches a buffer seeded from shallower water.
        """
        g = self._ghosts
        if g.stop == g.start:
            return
        nl = lists
        state = np.zeros((g.stop - g.start, 5))
        shepard_state(g.start, g.stop, g.start, p.x, p.y, p.m, p.rho, p.alpha, p.u, p.v, p.h,
                      nl.start, nl.nbr, state)
        b = self.buffer
        wet = state[:, 0] > 0.0
        b["rho"][wet] = RHO_WATER * state[wet, 1]
        b["alpha"][wet] = state[wet, 4] * b["rho"][wet]
        p.rho[g] = b["rho"]
        p.m[g] = b["rho"] * b["area"]
        p.h[g] = b["h"]
        p.alpha[g] = b["alpha"]
        b["u"][wet] = state[wet, 2]
        b["v"][wet] = state[wet, 3]
        side = np.array(self.sides)[np.argmax(self._beyond(b["x"], b["y"]), axis=0)]
        for name in self.sides:
            sel = side == name
            b["u"][sel], b["v"][sel] = _outwards(b["u"][sel], b["v"][sel], name)
        p.u[g] = b["u"]
        p.v[g] = b["v"]

    opening = None
    """No section: walls are not cut for this boundary (``Boundary.opening``)."""

    def max_dt(self, cfl: float) -> float:
        """No limit of its own on the step [s] (``Boundary.max_dt``)."""
        return math.inf

    def protected(self, x, y) -> np.ndarray:
        """Particles within the buffer reach of an open side (no coalescing there)."""
        return np.asarray((self._beyond(x, y) > -self.reach).any(axis=0))

    def __repr__(self) -> str:
        return (f"OpenEdges({', '.join(self.sides) or 'none'}, buffer {self.buffer['x'].size}, "
                f"{self.volume_out:.6g} m3 out)")
