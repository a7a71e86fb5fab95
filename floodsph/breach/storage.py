"""Reservoir storage-elevation relation V(H) and its inverse H(V) for level-pool routing.

Three inputs give one representation: on each elevation interval [z_i, z_{i+1}] the storage is
V(z) = V_i + a_i s + c_i s^2 / 2 with s = z - z_i, i.e. a surface area A(z) = a_i + c_i s that
is linear in z. A volume table (CSV ``elevation_m, volume_m3``) interpolated linearly has
c_i = 0; an area table (CSV ``elevation_m, area_m2``) interpolated linearly integrates exactly
to the quadratic form; a constant area A is one interval with a = A, c = 0. Above the table the
top surface area continues (a vertical-walled extension); below the lowest elevation the
storage is empty.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

from floodsph.errors import InputError
from floodsph.io.hydrograph import read_csv_columns


@dataclass(frozen=True, eq=False)
class Storage:
    """Piecewise storage curve V(z) = V_i + a_i (z - z_i) + c_i (z - z_i)^2 / 2 [m3]."""

    z: tuple  # node elevations [m], strictly increasing
    V: tuple  # storage at the nodes [m3], strictly increasing
    a: tuple  # surface area at the start of each interval [m2]
    c: tuple  # rate of change of area with elevation on each interval [m]

    @classmethod
    def constant_area(cls, area_m2, bottom_m):
        """Prismatic reservoir: V = A (z - bottom_m)."""
        return cls((bottom_m, bottom_m + 1.0), (0.0, area_m2), (area_m2,), (0.0,))

    @classmethod
    def from_volume_table(cls, z, V):
        """Linear interpolation of a storage table (z and V strictly increasing)."""
        z, V = list(map(float, z)), list(map(float, V))
        a = [(V[i + 1] - V[i]) / (z[i + 1] - z[i]) for i in range(len(z) - 1)]
        return cls(tuple(z), tuple(V), tuple(a), (0.0,) * len(a))

    @classmethod
    def from_area_table(cls, z, A):
        """Exact integral of a linearly interpolated area table; V = 0 at the lowest elevation."""
        z, A = list(map(float, z)), list(map(float, A))
        V, c = [0.0], []
        for i in range(len(z) - 1):
            dz = z[i + 1] - z[i]
            c.append((A[i + 1] - A[i]) / dz)
            V.append(V[-1] + 0.5 * (A[i] + A[i + 1]) * dz)
        return cls(tuple(z), tuple(V), tuple(A[:-1]), tuple(c))

    def _top_area(self):
        dz = self.z[-1] - self.z[-2]
        return self.a[-1] + self.c[-1] * dz

    def volume(self, level_m):
        """Storage V at water level ``level_m`` [m3] (0 below the lowest elevation)."""
        z = self.z
        if level_m <= z[0]:
            return self.V[0]
        if level_m >= z[-1]:
            return self.V[-1] + self._top_area() * (level_m - z[-1])
        i = bisect.bisect_right(z, level_m) - 1
        s = level_m - z[i]
        return self.V[i] + self.a[i] * s + 0.5 * self.c[i] * s * s

    def level(self, volume_m3):
        """Water level H at storage ``volume_m3`` [m], the inverse of :meth:`volume`.

        On an interval the quadratic a s + c s^2/2 = dV is solved in the cancellation-free
        form s = 2 dV / (a + sqrt(a^2 + 2 c dV)).
        """
        V = self.V
        if volume_m3 <= V[0]:
            return self.z[0]
        if volume_m3 >= V[-1]:
            return self.z[-1] + (volume_m3 - V[-1]) / self._top_area()
        i = bisect.bisect_right(V, volume_m3) - 1
        dv = volume_m3 - V[i]
        a, c = self.a[i], self.c[i]
        root = a + math.sqrt(max(a * a + 2.0 * c * dv, 0.0))
        return self.z[i] + (2.0 * dv / root if root > 0.0 else 0.0)


def read_storage_table(path, name):
    """Read a storage CSV (``elevation_m`` with ``volume_m3`` or ``area_m2``) into a Storage.

    Raises
    ------
    InputError
        Naming the key, the file and the line: the generic CSV errors of
        :func:`floodsph.io.hydrograph.read_csv_columns`, elevations or volumes not strictly
        increasing, negative areas, fewer than 2 rows.
    """
    values, lines = read_csv_columns(path, name, ("elevation_m",), one_of=("volume_m3", "area_m2"))
    z = values["elevation_m"]
    where = f"{name}: {path}"
    if len(lines) < 2:
        raise InputError(f"{where}: needs at least 2 data rows, found {len(lines)}")
    for k in range(1, len(z)):
        if z[k] <= z[k - 1]:
            raise InputError(f"{where}, line {lines[k]}: elevation_m = {z[k]:g} is not greater "
                             f"than the previous elevation {z[k - 1]:g}")
    if "volume_m3" in values:
        V = values["volume_m3"]
        for k in range(1, len(V)):
            if V[k] <= V[k - 1]:
                raise InputError(f"{where}, line {lines[k]}: volume_m3 = {V[k]:g} is not greater "
                                 f"than the previous volume {V[k - 1]:g}")
        return Storage.from_volume_table(z, V)
    A = values["area_m2"]
    for k, n in enumerate(lines):
        if A[k] < 0.0:
            raise InputError(f"{where}, line {n}: area_m2 = {A[k]:g} is negative")
        if k > 0 and A[k] == 0.0 and A[k - 1] == 0.0:
            raise InputError(f"{where}, line {n}: two consecutive zero areas hold no volume")
    if A[-1] <= 0.0:
        raise InputError(f"{where}, line {lines[-1]}: the top area_m2 must be > 0")
    return Storage.from_area_table(z, A)
