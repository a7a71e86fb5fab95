"""A documented estimate of a run's peak memory, and the check against what is available.

The estimate is deliberately simple and errs high; it exists to refuse a run that cannot fit
*before* hours are spent on it (``floodsph check`` prints it, ``floodsph run`` enforces it).

Peak particle count::

    N_peak = (N_initial + V_inflow / (D_TYPICAL * dx^2)) * F_refinement

where ``V_inflow`` is the hydrograph volume [m3] entering before the end time, ``dx`` the
particle spacing [m], ``D_TYPICAL`` = 1 m a typical depth of the released water, and
``F_refinement`` the growth from splitting (4 daughters per split particle, so ``split``
allows 4x, ``split+coalesce`` 2x since coalescing removes particles again, ``none`` 1x).

Bytes, at the larger of the two peaks (seeding, then the run)::

    BASE_BYTES + DEM + max(SEEDING, N_peak * BYTES_PER_PARTICLE + OUTPUT)

* DEM = (cells_dem * (DEM_GRIDS - 1) + cells_read) * 8: elevation, 5 derivative grids and
  Manning n in float64 on the model grid, and the rasters as read (each file whole, before
  any crop or resampling: the DEM and the largest of the Manning, land-cover and depth
  rasters);
* SEEDING = cells_lattice * SEEDING_ARRAYS * 8: the initial water is seeded on a dense
  lattice of the particle spacing over the whole DEM (``floodsph.inputs.initial_water``): the
  lattice depths, their padded copy, the 8 shifted neighbour grids stacked, the deepest neighbour
  and the masks. ``tracemalloc`` measured a peak of 12.3-13.0 float64 per lattice cell
  (lattices of 1.6e5 and 6.4e5 cells, 1 % wet); 14 errs high;
* per particle: the 13 float64/int64 particle arrays held twice (capacity doubles when it
  grows: 208 B), ~24 float64 solver scratch arrays (192 B) and a neighbour list of ~30
  neighbours x 8 B (240 B): 640 B;
* OUTPUT = cells_out * 12 * 8: ~12 float64 envelope maps (max depth, speed, ..., arrival,
  duration);
* ``BASE_BYTES`` = 420 MiB: the interpreter with numpy, numba, rasterio, xarray, netCDF4 and
  matplotlib imported and the kernels loaded from numba's cache, plus ``COMPILE_BYTES`` =
  240 MiB when the cache holds no kernel yet (:func:`kernels_cached`: LLVM's working memory
  on the first run after an install). Measured peak resident memory (``getrusage``
  ``ru_maxrss``) of a whole run of a 200-particle valley, where the base is all there is:
  399-418 MiB with the kernels cached, 649 MiB when they compile. On the sample
  (``data_samples/valley``, 9,300 particles at peak, cached kernels) the peak is 454 MiB; on
  Malpasset (``benchmarks/malpasset``, the sea as particles, 17,900 at peak, one thread)
  612 MiB.

Every count comes from shapes and areas known before the arrays exist (``floodsph.inputs.prepare``
estimates before reading the DEM, and again before seeding), so a run too large is refused
before it is allocated. Counts are clamped at ``COUNT_LIMIT``: a spacing of 1e-300 m gives an
estimate that is merely enormous, not an overflow.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

D_TYPICAL_M = 1.0
REFINEMENT_FACTOR = {"none": 1.0, "split": 4.0, "split+coalesce": 2.0}
BYTES_PER_PARTICLE = 2 * 13 * 8 + 24 * 8 + 30 * 8
OUTPUT_MAPS = 12
DEM_GRIDS = 8
SEEDING_ARRAYS = 14
BASE_BYTES = 420 * 2**20
COMPILE_BYTES = 240 * 2**20
COUNT_LIMIT = 1.0e24

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
    seeding_bytes: int = 0

    @property
    def total(self) -> int:
        running = self.particle_bytes + self.output_bytes
        return self.base_bytes + self.dem_bytes + max(self.seeding_bytes, running)

    def parts_text(self) -> str:
        """``'seeding lattice 46.9 GB (while seeding), terrain grids 1.2 GB, ...'``: the
        parts of the estimate, largest first, for messages.

        The two phases are told apart (the seeding lattice is freed before the particles and
        maps are allocated: the peak is the larger of the two), and particles appear once
        they are counted (not in the estimate made before the initial water is known, whose
        only particles are the inflows').
        """
        seeding = self.seeding_bytes >= self.particle_bytes + self.output_bytes
        parts = [(self.seeding_bytes,
                  f"seeding lattice {format_bytes(self.seeding_bytes)}"
                  + (" (while seeding: the peak)" if seeding else " (while seeding)")),
                 (self.dem_bytes, f"terrain grids {format_bytes(self.dem_bytes)}"),
                 (self.output_bytes, f"map grids {format_bytes(self.output_bytes)}"),
                 (self.base_bytes, f"program and libraries {format_bytes(self.base_bytes)}")]
        if self.particles_peak > 1:
            parts.append((self.particle_bytes,
                          f"particles {format_bytes(self.particle_bytes)} "
                          f"({self.particles_peak:,} at peak)"))
        return ", ".join(text for size, text in sorted(parts, key=lambda p: -p[0]) if size)


def _count(x: float) -> int:
    """A non-negative count from a float that may be huge or infinite (clamped)."""
    return int(min(max(float(x), 0.0), COUNT_LIMIT))


def estimate_memory(
    n_initial: float,
    inflow_volume_m3: float,
    spacing_m: float,
    refinement: str,
    dem_cells: float,
    output_cells: float,
    *,
    read_cells: float | None = None,
    lattice_cells: float = 0.0,
    compiling: bool = False,
) -> MemoryEstimate:
    """Estimate the peak memory of a run (formula in the module docstring).

    ``n_initial`` may be an estimate (wet area / spacing^2, before seeding); ``read_cells``
    is the size of the rasters as read (default ``dem_cells``), ``lattice_cells`` that of the
    seeding lattice; ``compiling``: the kernels will compile (``COMPILE_BYTES`` more).
    """
    n_inflow = inflow_volume_m3 / D_TYPICAL_M / spacing_m / spacing_m
    n_peak = _count((n_initial + n_inflow) * REFINEMENT_FACTOR[refinement]) + 1
    dem, read = _count(dem_cells), _count(dem_cells if read_cells is None else read_cells)
    return MemoryEstimate(
        particles_peak=n_peak,
        particle_bytes=n_peak * BYTES_PER_PARTICLE,
        output_bytes=_count(output_cells) * OUTPUT_MAPS * 8,
        dem_bytes=(dem * (DEM_GRIDS - 1) + read) * 8,
        seeding_bytes=_count(lattice_cells) * SEEDING_ARRAYS * 8,
        base_bytes=BASE_BYTES + (COMPILE_BYTES if compiling else 0),
    )


def kernels_cached() -> bool:
    """True if numba's cache holds the force kernel (an index file of
    ``floodsph.sph.forces.internal_acceleration``, in ``NUMBA_CACHE_DIR`` when it is set, else
    beside the module): the run loads its kernels instead of compiling them."""
    from pathlib import Path

    pattern = "forces.internal_acceleration*.nbi"
    root = os.environ.get("NUMBA_CACHE_DIR")
    if root:
        return any(Path(root).rglob(pattern))
    return any((Path(__file__).resolve().parents[1] / "sph" / "__pycache__").glob(pattern))


def available_memory() -> tuple[int | None, str]:
    """Bytes available to a new run and where the number comes from.

    ``FLOODSPH_MEMORY_LIMIT_BYTES`` if set, else the memory the operating system can give
    without swapping (``psutil.virtual_memory().available``: ``MemAvailable`` on Linux);
    ``(None, ...)`` where psutil cannot tell (no check is then made).
    """
    value = os.environ.get(LIMIT_ENV)
    if value:
        try:
            return int(float(value)), LIMIT_ENV
        except ValueError:
            from floodsph.errors import InputError

            raise InputError(f"{LIMIT_ENV}: expected a number of bytes, got {value!r}") from None
    import psutil

    try:
        return int(psutil.virtual_memory().available), "available memory"
    except (OSError, RuntimeError):
        return None, "unknown"


def format_bytes(n: float) -> str:
    """``1234567`` -> ``'1.2 MB'`` (powers of 1024)."""
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if abs(n) < 1024 or unit == "TB":
            break
        n /= 1024.0
    if unit == "B":
        return f"{n:.0f} B"
    return f"{n:.1f} {unit}" if abs(n) < 1e5 else f"{n:.3g} {unit}"


def check_memory(estimate: MemoryEstimate, source: str) -> None:
    """Raise ``InputError`` naming ``source`` if the estimate exceeds the available memory."""
    available, origin = available_memory()
    if available is None or estimate.total <= available:
        return
    from floodsph.errors import InputError

    raise InputError(
        f"{source}: the run needs an estimated {format_bytes(estimate.total)} at peak "
        f"({estimate.parts_text()}) but only {format_bytes(available)} is available "
        f"({origin}); increase numerics.particle_spacing_m or output.resolution_m, or crop "
        "terrain.extent"
    )
