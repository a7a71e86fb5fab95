"""A documented estimate of a run's peak memory, and the check against what is available.

The estimate is deliberately simple and errs high; it exists to refuse a run that cannot fit
*before* hours are spent on it (``floodsph check`` prints it, ``floodsph run`` enforces it).

Peak particle count::

    N_peak = (N_initial + V_inflow / (D_TYPICAL * dx^2)) * F_refinement

where ``V_inflow`` is the hydrograph volume [m3] entering before the end time, ``dx`` the
particle spacing [m], ``D_TYPICAL`` = 1 m a typical depth of the released water, and
``F_refinement`` the growth from splitting (4 daughters per split particle, so ``split``
allows 4x, ``split+coalesce`` 2x since coalescing removes particles again, ``none`` 1x).

Bytes::

    N_peak * BYTES_PER_PARTICLE + cells_out * 12 * 8 + cells_dem * 8 * 8 + BASE_BYTES

* per particle: the 13 float64/int64 particle arrays held twice (capacity doubles when it
  grows: 208 B), ~24 float64 solver scratch arrays (192 B) and a neighbour list of ~30
  neighbours x 8 B (240 B): 640 B;
* the output grid: ~12 float64 envelope maps (max depth, speed, ..., arrival, duration);
* the DEM grid: elevation, 5 derivative grids, Manning n and a read buffer, float64;
* ``BASE_BYTES`` = 350 MB: the interpreter with numpy, numba, rasterio and xarray imported
  (153 MiB resident on the project machine, 183 MiB with floodsph imported: VmRSS) plus
  compiled kernels.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

D_TYPICAL_M = 1.0
REFINEMENT_FACTOR = {"none": 1.0, "split": 4.0, "split+coalesce": 2.0}
BYTES_PER_PARTICLE = 2 * 13 * 8 + 24 * 8 + 30 * 8
OUTPUT_MAPS = 12
DEM_GRIDS = 8
BASE_BYTES = 350 * 2**20

#: Environment variable that overrides the available memory [bytes] (used by tests).
LIMIT_ENV = "FLOODSPH_MEMORY_LIMIT_BYTES"


@dataclass(frozen=True)
class MemoryEstimate:
    """The peak-memory estimate of one run and its parts [bytes]."""

    particles_peak: int
    particle_bytes: int
    output_bytes: int
    dem_bytes: int
    base_bytes: int = BASE_BYTES

    @property
    def total(self) -> int:
        return self.particle_bytes + self.output_bytes + self.dem_bytes + self.base_bytes


def estimate_memory(
    n_initial: int,
    inflow_volume_m3: float,
    spacing_m: float,
    refinement: str,
    dem_cells: int,
    output_cells: int,
) -> MemoryEstimate:
    """Estimate the peak memory of a run (formula in the module docstring)."""
    n_inflow = inflow_volume_m3 / (D_TYPICAL_M * spacing_m**2)
    n_peak = int((n_initial + n_inflow) * REFINEMENT_FACTOR[refinement]) + 1
    return MemoryEstimate(
        particles_peak=n_peak,
        particle_bytes=n_peak * BYTES_PER_PARTICLE,
        output_bytes=int(output_cells) * OUTPUT_MAPS * 8,
        dem_bytes=int(dem_cells) * DEM_GRIDS * 8,
    )


def available_memory() -> tuple[int | None, str]:
    """Bytes available to a new run and where the number comes from.

    ``FLOODSPH_MEMORY_LIMIT_BYTES`` if set, else ``MemAvailable`` of ``/proc/meminfo``;
    ``(None, ...)`` where neither exists (no check is then made).
    """
    value = os.environ.get(LIMIT_ENV)
    if value:
        try:
            return int(float(value)), LIMIT_ENV
        except ValueError:
            from floodsph.errors import InputError

            raise InputError(f"{LIMIT_ENV}: expected a number of bytes, got {value!r}") from None
    meminfo = Path("/proc/meminfo")
    if meminfo.exists():
        for line in meminfo.read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024, "MemAvailable"
    return None, "unknown"


def format_bytes(n: float) -> str:
    """``1234567`` -> ``'1.2 MB'`` (powers of 1024)."""
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if abs(n) < 1024 or unit == "TB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024.0
    return f"{n:.1f} TB"


def check_memory(estimate: MemoryEstimate, source: str) -> None:
    """Raise ``InputError`` naming ``source`` if the estimate exceeds the available memory."""
    available, origin = available_memory()
    if available is None or estimate.total <= available:
        return
    from floodsph.errors import InputError

    raise InputError(
        f"{source}: the run needs an estimated {format_bytes(estimate.total)} at peak "
        f"({estimate.particles_peak} particles) but only {format_bytes(available)} is available "
        f"({origin}); increase numerics.particle_spacing_m or output.resolution_m, or crop "
        "terrain.extent"
    )
