"""A level boundary: a section where the water level follows a given series eta(t).

Geometry as an inflow section (``floodsph.boundaries.inflow``, ``docs/method.md`` §8): the
segment A-B of length L with inward unit normal n, cut into N = round(L / dx) columns of width
dx_l = L / N; s is the distance along n (s < 0 behind the line), tau the distance along it.

Boundary state per column (``floodsph.boundaries.riemann.level_state``): the imposed depth
d_0 = eta(t) - z_k over the bed z_k of column k and the interior water within two spacings
of the line give d_B and the normal velocity w_B by the outgoing Riemann invariant; w_B > 0
where water enters.

Behind the line lies a buffer of ghost particles, down to the kernel reach 2 h (1 + skin). Each
moves along n at its column's w_B and carries rho = rho_w d_B, m = rho A for its area A, its
own h and alpha / rho, and the interior's normal velocity w_I n (the level is imposed, the
velocity continued with a zero gradient: ``LevelBoundary.add_ghosts``; w_B where the interior
is dry). Water and buffer trade places:

* a buffer particle that crosses the line (s >= 0) becomes water of mass rho_w d_B A, added to
  ``volume_in``, with its velocity; entering columns are refilled behind with rows of
  spacing dx (area dx_l dx, h = kappa sqrt(dx_l dx), the lattice's alpha:
  ``floodsph.boundaries.inflow``);
* water that crosses the line (s < 0) leaves: m / rho_w is added to ``volume_out`` and the
  particle joins the buffer, which so continues the water's own spacing, as the departed
  particles do at an open edge (``floodsph.boundaries.open_edges``).

The volumes exchanged are therefore exact: initial + in - out = final to round-off
(``docs/level-boundary.md``). At the start the buffer is the mirror image of the water within
reach of the line, so that water at rest at the boundary level stays at rest.
"""

from __future__ import annotations

import math

import numpy as np

from floodsph.boundaries.inflow import DEPTH_MIN_M, lattice_alpha_ratio
from floodsph.boundaries.protocol import Site, Water
from floodsph.boundaries.riemann import level_state
from floodsph.boundaries.section import section_coordinates, section_opening
from floodsph.boundaries.weir import bed_at
from floodsph.constants import GRAVITY, RHO_WATER

INTERIOR_BAND = 2.0
"""Depth of the band of interior water the boundary state is taken from [spacings]."""


class LevelBoundary:
    """A section A-B where the water level follows ``series`` (module docstring).

    Parameters
    ----------
    line : (2, 2) array
        End points A, B in local coordinates [m], on the DEM.
    normal : (2,) array
        Inward unit normal (towards the modelled water).
    series : floodsph.io.level_series.LevelSeries
        The imposed level eta(t) [m].
    spacing, kappa : float
        Particle spacing dx [m] and h / dx of the buffer particles.
    terrain : Terrain
        The bed z the imposed depth eta - z is measured from.
    name : str
        The boundary's name (run.json) or key path.
    """

    STATE = ("buffer", "reach", "seeded", "d_b", "w_b", "w_i", "level", "volume_in",
             "volume_out")
    """What changes during a run (``Boundary.STATE``): the buffer particles, their reach and
    whether they were seeded, each column's boundary state (depth, invariants), the level
    imposed last and the volumes in and out."""

    def __init__(self, line, normal, series, spacing: float, kappa: float, terrain,
                 name: str = "level_boundaries[0]"):
        a, b = np.asarray(line, dtype=np.float64)
        self.a = a
        self.length = float(np.hypot(*(b - a)))
        self.tangent = (b - a) / self.length
        self.normal = np.asarray(normal, dtype=np.float64)
        self.series = series
        self.name = name
        self.count = max(1, int(round(self.length / spacing)))
        self.dx_l = self.length / self.count
        self.dx_n = float(spacing)
        self.h = kappa * math.sqrt(self.dx_l * self.dx_n)
        self.alpha_ratio = lattice_alpha_ratio(self.dx_l, self.dx_n, self.h)
        x, y = self._points(np.arange(self.count), 0.5 * self.dx_n)
        self.bed = bed_at(terrain, x, y)
        self.buffer = {name: np.zeros(0) for name in ("s", "tau", "area", "h", "ratio")}
        self.reach = 0.0
        self.seeded = False
        self.d_b = np.zeros(self.count)
        self.w_b = np.zeros(self.count)
        self.w_i = np.zeros(self.count)
        self.level = series.at(0.0)
        self.volume_in = 0.0
        self.volume_out = 0.0
        self._ghost_state: dict[str, np.ndarray] = {}
        self._ghosts = slice(0, 0)

    # -- geometry ------------------------------------------------------------------------------
    @property
    def opening(self) -> np.ndarray:
        """The section as a (2, 2) array [A, B] (walls along it are cut open)."""
        return section_opening(self.a, self.tangent, self.length)

    def _coordinates(self, x, y):
        """(s, tau): distance along the inward normal and along the line from A [m]."""
        return section_coordinates(self.a, self.normal, self.tangent, x, y)

    def _points(self, columns, s):
        """Positions (x, y) of the points of ``columns`` at normal offsets ``s`` [m]."""
        tau = (columns + 0.5) * self.dx_l
        return (self.a[0] + tau * self.tangent[0] + s * self.normal[0],
                self.a[1] + tau * self.tangent[1] + s * self.normal[1])

    # -- the boundary protocol -------------------------------------------------------------
    def apply(self, water: Water, site: Site, dt: float) -> None:
        """Move the buffer by w_B dt; buffer particles that crossed in become water, water that
        crossed out joins the buffer; refill the entering columns' buffers; then update
        (d_B, w_B) to the level at the step's end."""
        t_end = water.t + dt
        p = water.particles
        self._update_reach(p, site.neighbour_skin)
        if not self.seeded:
            self._seed(p)
            self.seeded = True
        b = self.buffer
        b["s"] += self.w_b[self._column(b["tau"])] * dt
        self._inject(water)
        self._take_departed(water)
        b = self.buffer
        self._keep_buffer(b["s"] > -self.reach)
        self._refill()
        self._update_state(water.particles, t_end)

    def _column(self, tau) -> np.ndarray:
        """The column index of points at distance ``tau`` along the line."""
        return np.clip((np.asarray(tau) / self.dx_l).astype(np.int64), 0, self.count - 1)

    def _keep_buffer(self, mask) -> None:
        self.buffer = {name: values[mask] for name, values in self.buffer.items()}

    def _add_buffer(self, **values) -> None:
        self.buffer = {name: np.concatenate([self.buffer[name], values[name]])
                       for name in self.buffer}

    def _update_reach(self, p, skin: float) -> None:
        """The buffer's depth behind the line [m]: the kernel reach 2 h (1 + skin) of the
        widest particle near it, water or buffer."""
        s, _ = self._coordinates(p.x, p.y)
        h = [self.h, float(self.buffer["h"].max(initial=0.0))]
        near = np.abs(s) < 4.0 * self.h
        if near.any():
            h.append(float(p.h[near].max()))
        self.reach = 2.0 * (1.0 + skin) * max(h)

    def _seed(self, p) -> None:
        """The first buffer: mirror images of the water within reach of the line, which
        continue the seeding lattice across it (still water at the boundary level stays),
        with the alpha / rho of that lattice (the seeds' own is not solved yet)."""
        s, tau = self._coordinates(p.x, p.y)
        near = (s >= 0.0) & (s < self.reach) & (tau >= 0.0) & (tau < self.length)
        self._add_buffer(s=-s[near], tau=tau[near], area=p.m[near] / p.rho[near],
                         h=p.h[near], ratio=np.full(int(near.sum()), self.alpha_ratio))

    def _inject(self, water: Water) -> None:
        """Buffer particles that crossed the line (s >= 0) become water of depth d_B, mass
        rho_w d_B A [kg] for their area A, counted in ``volume_in``, with the velocity they
        had as ghosts (entering at w_B instead, the far-end error of the tide benchmark was
        3.3 cm rather than 2.2 cm at a 2 m spacing)."""
        b = self.buffer
        crossed = b["s"] >= 0.0
        if not crossed.any():
            return
        col = self._column(b["tau"][crossed])
        wet = self.d_b[col] >= DEPTH_MIN_M
        col = col[wet]
        s, tau = b["s"][crossed][wet], b["tau"][crossed][wet]
        x = self.a[0] + tau * self.tangent[0] + s * self.normal[0]
        y = self.a[1] + tau * self.tangent[1] + s * self.normal[1]
        rho = RHO_WATER * self.d_b[col]
        m = rho * b["area"][crossed][wet]
        w = self.w_i[col]
        water.particles.append(x=x, y=y, u=w * self.normal[0], v=w * self.normal[1], m=m,
                               rho=rho, h=b["h"][crossed][wet], born=water.steps)
        volume = float(m.sum()) / RHO_WATER
        self.volume_in += volume
        water.volume_in += volume
        self._keep_buffer(~crossed)

    def _take_departed(self, water: Water) -> None:
        """Water behind the line (s < 0 within the buffer's depth, 0 <= tau <= L) leaves:
        its volume m / rho_w is counted in ``volume_out`` and it joins the buffer, which so
        continues the water's own spacing (as the departed particles do at an open edge)."""
        p = water.particles
        s, tau = self._coordinates(p.x, p.y)
        out = (s < 0.0) & (s > -self.reach) & (tau >= 0.0) & (tau <= self.length)
        if not out.any():
            return
        volume = float(p.m[out].sum()) / RHO_WATER
        self.volume_out += volume
        water.volume_out += volume
        self._add_buffer(s=s[out], tau=tau[out], area=p.m[out] / p.rho[out], h=p.h[out],
                         ratio=p.alpha[out] / p.rho[out])
        p.keep(~out)

    def _refill(self) -> None:
        """Rows of spacing dx behind the rearmost buffer particle of each entering column
        (w_B > 0), down to the buffer's depth; an empty column starts at s = -dx / 2."""
        entering = np.flatnonzero((self.w_b > 0.0) & (self.d_b >= DEPTH_MIN_M))
        if entering.size == 0:
            return
        rear = np.full(self.count, 0.5 * self.dx_n)
        np.minimum.at(rear, self._column(self.buffer["tau"]), self.buffer["s"])
        rear = rear[entering]
        rows = np.ceil((self.reach + rear) / self.dx_n).astype(np.int64) - 1
        rows = np.maximum(rows, 0)
        col = np.repeat(entering, rows)
        k = np.concatenate([np.arange(1, n + 1) for n in rows]) if col.size else np.zeros(0)
        s = np.repeat(rear, rows) - k * self.dx_n
        self._add_buffer(s=s, tau=(col + 0.5) * self.dx_l,
                         area=np.full(col.size, self.dx_l * self.dx_n),
                         h=np.full(col.size, self.h), ratio=np.full(col.size, self.alpha_ratio))

    def _update_state(self, p, t: float) -> None:
        """(d_B, w_B) per column from eta(t) and the interior water: the particles within
        ``INTERIOR_BAND`` spacings inside the line; and the normal velocity the ghosts and
        the water entering carry (``add_ghosts``): w_I, their mean, or w_B where the
        interior is dry."""
        s, tau = self._coordinates(p.x, p.y)
        near = ((s > 0.0) & (s < INTERIOR_BAND * self.dx_n) & (tau >= 0.0)
                & (tau < self.length))
        column = self._column(tau[near])
        count = np.bincount(column, minlength=self.count)
        rho_sum = np.bincount(column, p.rho[near], minlength=self.count)
        w = p.u[near] * self.normal[0] + p.v[near] * self.normal[1]
        w_sum = np.bincount(column, w, minlength=self.count)
        wet = count > 0
        d_i = np.where(wet, rho_sum / np.maximum(count, 1) / RHO_WATER, 0.0)
        w_i = np.where(wet, w_sum / np.maximum(count, 1), 0.0)
        self.level = self.series.at(t)
        self.d_b, self.w_b = level_state(self.level - self.bed, d_i, w_i)
        self.w_i = np.where(wet, w_i, self.w_b)

    def add_ghosts(self, p) -> None:
        """Append the buffer particles of the columns with water (d_B > 0) as ghosts.

        They carry the boundary depth d_B but the interior's normal velocity w_I (a zero
        gradient, as at an open edge), while the buffer moves at w_B: ghosts with the
        velocity w_B drag the water next to the line, whose w_I then follows w_B, and the
        invariant adds 2 (c_0 - c_I) to w_B step after step; in the tide benchmark the
        far-end error was 3.8 cm at a 2 m spacing but 10.7 cm at 1 m so (with w_I:
        ``docs/level-boundary-benchmark.md``).
        """
        b = self.buffer
        col = self._column(b["tau"])
        wet = self.d_b[col] >= DEPTH_MIN_M
        col = col[wet]
        s, tau = b["s"][wet], b["tau"][wet]
        rho = RHO_WATER * self.d_b[col]
        w = self.w_i[col]
        self._ghost_state = {"rho": rho, "m": rho * b["area"][wet], "h": b["h"][wet],
                             "alpha": rho * b["ratio"][wet], "u": w * self.normal[0],
                             "v": w * self.normal[1]}
        self._ghosts = p.append(
            x=self.a[0] + tau * self.tangent[0] + s * self.normal[0],
            y=self.a[1] + tau * self.tangent[1] + s * self.normal[1], **self._ghost_state)

    def impose(self, p, lists) -> None:
        """Reset the ghosts to their column's boundary state (after the density solve)."""
        g = self._ghosts
        for name, values in self._ghost_state.items():
            getattr(p, name)[g] = values

    def max_dt(self, cfl: float) -> float:
        """Longest stable step [s] for the buffer: cfl h / max(|w_B| + sqrt(g d_B)), at least
        as short as for the celerity of the highest level of the series over the lowest bed
        (so that a rising level does not find the step too long)."""
        speed = float(np.max(np.abs(self.w_b) + np.sqrt(GRAVITY * self.d_b)))
        deepest = max(self.series.highest() - float(self.bed.min()), 0.0)
        speed = max(speed, math.sqrt(GRAVITY * deepest))
        return math.inf if speed <= 0.0 else cfl * self.h / speed

    def protected(self, x, y) -> np.ndarray:
        """Particles within 4 h of the section (no coalescing there)."""
        s, tau = self._coordinates(x, y)
        reach = 4.0 * self.h
        return (np.abs(s) < reach) & (tau > -reach) & (tau < self.length + reach)

    def summary(self) -> dict:
        """The volumes that entered and left through the section [m3] (run.json)."""
        return {"volume_in_m3": float(self.volume_in), "volume_out_m3": float(self.volume_out),
                "level_m": float(self.level)}

    def __repr__(self) -> str:
        return (f"LevelBoundary({self.name}, L={self.length:g} m, level {self.level:.4g} m, "
                f"{self.volume_in:.6g} m3 in, {self.volume_out:.6g} m3 out)")
