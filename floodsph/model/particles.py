"""Structure-of-arrays particle container with spare capacity.

Every per-particle quantity is one contiguous 1-D NumPy array of length ``capacity``; the
first ``n`` entries are the active particles. Kernels never see this class: they receive
the array views returned by attribute access (``p.x`` is already ``x[:n]``).

Positions are in the terrain's local origin (metres east and north of the lower-left
corner of the DEM), never in raw projected coordinates, so float64 keeps millimetre
precision over the whole run.
"""

from __future__ import annotations

import numpy as np

FIELDS: dict[str, tuple[type, str]] = {
    "x": (np.float64, "m, local easting"),
    "y": (np.float64, "m, local northing"),
    "u": (np.float64, "m s-1, depth-averaged velocity east"),
    "v": (np.float64, "m s-1, depth-averaged velocity north"),
    "m": (np.float64, "kg, particle mass (rho_w times its water volume)"),
    "rho": (np.float64, "kg m-2, areal density rho = rho_w d"),
    "h": (np.float64, "m, smoothing length (never depth)"),
    "h0": (np.float64, "m, reference smoothing length of h = h0 (rho0/rho)^(1/2)"),
    "rho0": (np.float64, "kg m-2, reference density of the same relation"),
    "alpha": (np.float64, "kg m-2, grad-h correction -sum m r dW/dr (= 2 rho on a lattice)"),
    "ax": (np.float64, "m s-2, acceleration east at the last force evaluation"),
    "ay": (np.float64, "m s-2, acceleration north at the last force evaluation"),
    "divv": (np.float64, "s-1, SPH velocity divergence at the last force evaluation"),
    "hgrow": (np.float64, "h after / h before the last density solve (widens the next search)"),
    "kxx": (np.float64, "-, pressure renormalisation K, xx (floodsph.sph.consistency)"),
    "kxy": (np.float64, "-, the same, xy"),
    "kyy": (np.float64, "-, the same, yy"),
    "dudx": (np.float64, "s-1, velocity gradient du/dx at the last force evaluation"),
    "dudy": (np.float64, "s-1, the same, du/dy"),
    "dvdx": (np.float64, "s-1, the same, dv/dx"),
    "dvdy": (np.float64, "s-1, the same, dv/dy"),
    "level": (np.int64, "refinement level: number of splits in the particle's ancestry"),
    "born": (np.int64, "step at which the particle was created (split, merge or inflow)"),
    "stride": (np.int64, "local time stepping: own step in finest steps (0: not yet set)"),
    "eta_offset": (np.float64, "m, level offset o of the balanced momentum, eta = d + b + o "
                               "(floodsph.sph.level_offsets)"),
    "eta_seed": (np.float64, "m, the level a particle seeded at rest was seeded at "
                             "(NaN for water seeded moving, injected or born in the run)"),
    "bank_held": (np.int64, "1 for water seeded at rest whose support had no free edge at "
                            "set-up: it keeps none until it moves (floodsph.sph.level_momentum)"),
    "x_seed": (np.float64, "m, local easting of still water held by its banks at set-up "
                           "(floodsph.sph.level_offsets.hold_still)"),
    "y_seed": (np.float64, "m, the same, northing"),
    "pid": (np.int64, "unique particle id, never reused"),
}

VELOCITY_GRADIENT = ("dudx", "dudy", "dvdx", "dvdy")
"""The fields of the velocity gradient (``floodsph.sph.forces.reconstructed_jump``): daughters
inherit their parent's, a merged particle takes its pair's mass-weighted mean."""
INHERITED = VELOCITY_GRADIENT + ("eta_offset",)
"""The fields that daughters inherit from their parent and a merged particle takes as its
pair's mass-weighted mean: the velocity gradient and the level offset."""


class ParticleSet:
    """Particles stored as contiguous float64/int64 arrays with room to grow.

    Parameters
    ----------
    capacity : int
        Number of particles the arrays can hold before they are reallocated (doubled).
    """

    STATE = ("capacity", "n", "next_pid", *FIELDS)
    """What a checkpoint holds (``floodsph.simulation.state_arrays``): the room, the count and
    the next id, then every field of the active particles; restored in this order."""

    def __init__(self, capacity: int = 1024):
        capacity = max(int(capacity), 1)
        self._data: dict[str, np.ndarray] = {
            name: np.zeros(capacity, dtype=dt) for name, (dt, _) in FIELDS.items()}
        self.n = 0
        self.next_pid = 0

    @property
    def capacity(self) -> int:
        return self._data["x"].shape[0]

    @capacity.setter
    def capacity(self, capacity: int) -> None:
        """Reallocate every field to exactly ``capacity`` particles, keeping the first ones
        (as many as fit)."""
        capacity = max(int(capacity), 1)
        self.n = min(self.n, capacity)
        for name, arr in self._data.items():
            room = np.zeros(capacity, dtype=arr.dtype)
            room[: self.n] = arr[: self.n]
            self._data[name] = room

    def __getattr__(self, name: str) -> np.ndarray:
        data = self.__dict__.get("_data")
        if data is not None and name in data:
            return data[name][: self.n]
        raise AttributeError(name)

    def __setattr__(self, name: str, value) -> None:
        """``p.u = values`` and ``p.u += du`` write into the active particles' array (an
        attribute of that name would hide the field from every later reallocation)."""
        if name in FIELDS:
            self._data[name][: self.n] = value
        else:
            super().__setattr__(name, value)

    def __len__(self) -> int:
        return self.n

    def __repr__(self) -> str:
        return f"ParticleSet(n={self.n}, capacity={self.capacity})"

    def _reserve(self, n_total: int) -> None:
        if n_total <= self.capacity:
            return
        new_cap = max(n_total, 2 * self.capacity)
        for name, arr in self._data.items():
            grown = np.zeros(new_cap, dtype=arr.dtype)
            grown[: self.n] = arr[: self.n]
            self._data[name] = grown

    def append(self, **fields: np.ndarray) -> slice:
        """Append particles; ``x, y, m, rho, h`` are required, the rest default sensibly.

        ``u, v`` default to 0, ``h0``/``rho0`` to the given ``h``/``rho``, ``alpha`` to
        2 rho (its lattice value), ``hgrow`` to 1, ``level``, ``born``, ``stride`` and
        ``eta_offset`` and ``bank_held`` to 0, ``eta_seed``, ``x_seed`` and ``y_seed`` to NaN.
        New ids are assigned.
        Returns the slice of the new particles.
        """
        unknown = set(fields) - set(FIELDS)
        if unknown:
            raise KeyError(f"unknown particle fields: {sorted(unknown)}")
        count = len(np.atleast_1d(fields["x"]))
        defaults = {
            "u": 0.0,
            "v": 0.0,
            "h0": fields["h"],
            "rho0": fields["rho"],
            "alpha": 2.0 * np.asarray(fields["rho"], dtype=np.float64),
            "ax": 0.0,
            "ay": 0.0,
            "divv": 0.0,
            "hgrow": 1.0,
            "kxx": 0.0,
            "kxy": 0.0,
            "kyy": 0.0,
            "dudx": 0.0,
            "dudy": 0.0,
            "dvdx": 0.0,
            "dvdy": 0.0,
            "level": 0,
            "born": 0,
            "stride": 0,
            "eta_offset": 0.0,
            "eta_seed": np.nan,
            "bank_held": 0,
            "x_seed": np.nan,
            "y_seed": np.nan,
        }
        start = self.n
        self._reserve(start + count)
        for name in FIELDS:
            if name == "pid":
                continue
            value = fields.get(name, defaults.get(name))
            if value is None:
                raise KeyError(f"particle field {name!r} is required")
            self._data[name][start : start + count] = value
        self._data["pid"][start : start + count] = np.arange(
            self.next_pid, self.next_pid + count, dtype=np.int64
        )
        self.next_pid += count
        self.n = start + count
        return slice(start, start + count)

    def keep(self, mask: np.ndarray) -> None:
        """Keep only the particles where ``mask`` is true, preserving their order."""
        idx = np.flatnonzero(mask)
        self.permute(idx)

    def permute(self, order: np.ndarray) -> None:
        """Reorder (and possibly shrink) the active particles to ``order`` (indices)."""
        k = len(order)
        for arr in self._data.values():
            arr[:k] = arr[: self.n][order]
        self.n = k

    def mark(self) -> tuple[int, int]:
        """(n, next id): pass to :meth:`truncate` to drop everything appended after it."""
        return self.n, self.next_pid

    def truncate(self, mark: tuple[int, int]) -> None:
        """Drop the particles appended since ``mark`` (the step's ghosts); ids are reused."""
        self.n, self.next_pid = mark

    def volume(self) -> float:
        """Total water volume sum(m) / rho_w [m3]."""
        from floodsph.constants import RHO_WATER

        return float(self.m.sum() / RHO_WATER)
