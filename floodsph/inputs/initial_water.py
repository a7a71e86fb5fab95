"""Initial water: a depth grid on the DEM grid, and particles seeded on a square lattice.

Depth grids (row 0 = south, the terrain's grid) come from

* a still-water level inside a polygon, ``d = level - b`` where the bed is below it
  (:func:`depth_from_level`), e.g. a reservoir at t = 0 of an instant dam failure;
* a depth raster on any grid (:func:`depth_from_raster`).

:func:`seed_particles` puts one particle at each node of a square lattice of spacing
``dx`` aligned to the terrain's local origin (nodes at ``((k + 1/2) dx, (l + 1/2) dx)``),
with the water volume of the lattice cell around it: the depth is the exact area average of
the piecewise-constant depth grid over that cell, so the seeded volume equals the grid's
volume (to the shallow cells dropped below ``d_min``), at any ratio of particle spacing to
DEM cell. Following Vacondio et al. (2013), m = rho_w d dx^2, rho = rho_w d and
h = kappa dx; the solver then recomputes rho and h by summation. Cells much thinner than a
neighbour (a steep shore) first give their water to it (:func:`lump_thin_cells`). Water is
seeded on valid cells, and where the nodata border is walled also on the nodata slivers inside
its simplified walls (:func:`wet_cells`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from rasterio.crs import CRS
from rasterio.enums import Resampling
from scipy import sparse

from floodsph.constants import RHO_WATER
from floodsph.errors import InputError
from floodsph.io.polygons import check_polygon, points_in_polygon
from floodsph.io.raster import read_grid, resample_onto
from floodsph.model.particles import ParticleSet
from floodsph.model.terrain import Terrain
from floodsph.sph.kernels import seeded_smoothing_length
from floodsph.walls.nodata import walled_slivers

LUMP_RATIO = 9.0
"""A lattice cell thinner than its deepest neighbour by this factor (h about 3 times smaller,
at equal density) gives its water to that neighbour (:func:`lump_thin_cells`)."""


def wet_cells(terrain: Terrain, walled: bool) -> np.ndarray:
    """The cells initial water may fill: the valid ones, and where the nodata border is walled
    (closed edges) the nodata slivers inside its simplified walls
    (:func:`floodsph.walls.nodata.walled_slivers`), which the water reaches in the
    model as well; their bed is the nearest valid elevation (``floodsph.inputs.dem``)."""
    if not walled:
        return terrain.valid
    return terrain.valid | walled_slivers(terrain.valid, terrain.dx, terrain.dy)


def depth_from_level(
    terrain: Terrain, level_m: float, polygon_local, name: str = "initial_water.polygon",
    wet: np.ndarray | None = None,
) -> np.ndarray:
    """Water depth d = max(level - b, 0) [m] at the cell centres inside a polygon.

    Parameters
    ----------
    terrain : Terrain
    level_m : float
        Free-surface elevation [m].
    polygon_local : (k, 2) array-like
        Polygon in LOCAL coordinates [m] (world minus ``(x0, y0)``).
    name : str
        Key path of the polygon for error messages.
    wet : (ny, nx) bool array, optional
        Cells that may hold water (default: the valid cells; :func:`wet_cells`).

    Returns
    -------
    (ny, nx) float64 array, row 0 = south; 0 outside the polygon and off ``wet``.
    """
    level = float(level_m)
    if not np.isfinite(level):
        raise InputError(f"{name}: level_m must be a finite number, got {level_m!r}")
    poly = check_polygon(polygon_local, name)
    xc, yc = terrain.cell_centres()
    X, Y = np.meshgrid(xc, yc)
    inside = points_in_polygon(X, Y, poly) & (terrain.valid if wet is None else wet)
    inside &= ~stray_slivers(inside, terrain.valid)
    return np.where(inside, np.maximum(level - terrain.elevation, 0.0), 0.0)


def stray_slivers(inside: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """The nodata cells of ``inside`` whose nearest valid cell is not inside: (ny, nx) bool.

    A nodata sliver takes the bed of its nearest valid cell (``floodsph.inputs.dem``) and belongs
    to that cell's side of the walls (:func:`floodsph.walls.nodata.walled_slivers`). A polygon
    may hold the sliver but not that cell: on Malpasset's 20 m DEM the slivers of a side
    valley beyond the dam, 1-2 cells from the reservoir across the nodata, took the valley's bed
    (60 m), were filled to the reservoir's 100 m and ran down the valley at up to 9 m/s, water
    no user put there. Such a sliver stays dry.
    """
    from scipy import ndimage

    sliver = inside & ~valid
    if not sliver.any() or not valid.any():
        return np.zeros_like(inside)
    _, (row, col) = ndimage.distance_transform_edt(~valid, return_indices=True)
    out = np.zeros_like(inside)
    out[sliver] = ~inside[row[sliver], col[sliver]]
    return out


def depth_from_raster(terrain: Terrain, path, name: str = "initial_water.depth",
                      wet: np.ndarray | None = None) -> np.ndarray:
    """Initial depth [m] from a raster on any grid, resampled (bilinear) onto the DEM grid.

    Nodata and cells outside the raster become 0, as do cells outside ``wet`` (default: the
    valid DEM cells; :func:`wet_cells`). A negative depth anywhere in the raster is an
    InputError naming ``name`` and the file.
    """
    path = Path(path)
    grid = read_grid(path, what=f"{name} raster")
    finite = grid.values[np.isfinite(grid.values)]
    if finite.size and finite.min() < 0.0:
        raise InputError(
            f"{name}: depth raster {path} has negative depths "
            f"({int((finite < 0).sum())} cells, minimum {finite.min():.4g} m)"
        )
    dst_crs = CRS.from_wkt(terrain.crs_wkt) if terrain.crs_wkt else None
    north_up = resample_onto(
        grid,
        terrain.north_up_transform(),
        terrain.shape,
        dst_crs,
        resampling=Resampling.bilinear,
        what=f"{name} raster",
        label=path,
    )
    d = np.nan_to_num(north_up[::-1], nan=0.0)
    return np.where(terrain.valid if wet is None else wet, np.maximum(d, 0.0), 0.0)


def _overlap_matrix(n_lattice: int, spacing: float, n_cells: int, cell: float):
    """Sparse (n_lattice, n_cells) lengths [m] of overlap of lattice and grid intervals.

    Lattice interval k is [k s, (k+1) s], grid interval j is [j c, (j+1) c].
    """
    lo = np.arange(n_lattice) * spacing
    hi = lo + spacing
    first = np.floor(lo / cell).astype(np.int64)
    span = int(np.ceil(spacing / cell)) + 1
    rows, cols, vals = [], [], []
    for off in range(span):
        j = first + off
        ok = j < n_cells
        length = np.minimum(hi, (j + 1) * cell) - np.maximum(lo, j * cell)
        ok &= length > 0
        rows.append(np.flatnonzero(ok))
        cols.append(j[ok])
        vals.append(length[ok])
    return sparse.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(n_lattice, n_cells),
    )


def lattice_depth(terrain: Terrain, depth_grid: np.ndarray, dx: float):
    """Area-averaged depth over each lattice cell of spacing ``dx``.

    d_kl = (1/dx^2) sum_ij d_ij |A_kl ∩ C_ij|, the lattice cells ``A`` being
    [k dx, (k+1) dx] x [l dx, (l+1) dx] and ``C`` the DEM cells; only lattice cells that lie
    wholly inside the grid are used.

    Returns
    -------
    xs, ys : 1-D arrays of the lattice node coordinates (local) [m]
    d : (len(ys), len(xs)) array of depths [m]
    """
    ny, nx = terrain.shape
    nlx = int(np.floor(terrain.width / dx + 1e-9))
    nly = int(np.floor(terrain.height / dx + 1e-9))
    wx = _overlap_matrix(nlx, dx, nx, terrain.dx)
    wy = _overlap_matrix(nly, dx, ny, terrain.dy)
    d = np.asarray((wx @ (wy @ depth_grid).T).T) / dx**2
    xs = (np.arange(nlx) + 0.5) * dx
    ys = (np.arange(nly) + 0.5) * dx
    return xs, ys, d


def lump_thin_cells(d: np.ndarray, ratio: float = LUMP_RATIO) -> np.ndarray:
    """Lattice depths with each cell thinner than 1/``ratio`` of its deepest neighbour (of 8)
    emptied into that neighbour, the thinnest first, until none is left; the total volume is
    unchanged.

    A seed's mass is rho_w d dx^2 and h^2 rho is proportional to its mass, so a seed from a
    thin cell at a steep shore, once in the water of its deeper neighbours, takes an h
    sqrt(ratio) or more times smaller than theirs. Such particles set the time step of the
    whole run (a reservoir's shore seeds of a few cm, whose h falls to the h0 / h_ratio bound
    when the flood carries them into metres of water), and neighbour h ratios above about 2-3
    degrade accuracy (``docs/method.md`` §1). Where the water is that thin the shore moves
    inwards, by one spacing, or more where a cell that received water is in turn lumped.
    """
    d = d.copy()
    ny, nx = d.shape
    while True:  # a cell that received water can leave a neighbour newly too thin
        padded = np.pad(d, 1)
        deepest = np.max([padded[1 + a:1 + a + ny, 1 + b:1 + b + nx]
                          for a in (-1, 0, 1) for b in (-1, 0, 1) if a or b], axis=0)
        rows, cols = np.nonzero((d > 0.0) & (d * ratio < deepest))
        if rows.size == 0:
            break
        for k in np.argsort(d[rows, cols], kind="stable"):
            r, c = rows[k], cols[k]
            r0, r1, c0, c1 = max(r - 1, 0), min(r + 2, ny), max(c - 1, 0), min(c + 2, nx)
            block = d[r0:r1, c0:c1].copy()
            block[r - r0, c - c0] = -1.0
            if d[r, c] * ratio >= block.max():  # its neighbours have been emptied meanwhile
                continue
            rb, cb = np.unravel_index(np.argmax(block), block.shape)
            d[r0 + rb, c0 + cb] += d[r, c]
            d[r, c] = 0.0
    return d


def seed_particles(
    terrain: Terrain,
    depth_grid: np.ndarray,
    dx: float,
    kappa: float,
    d_min: float = 1e-3,
    particles: ParticleSet | None = None,
    wet: np.ndarray | None = None,
) -> ParticleSet:
    """Particles at the lattice nodes where the lattice-cell depth exceeds ``d_min``.

    Parameters
    ----------
    terrain : Terrain
    depth_grid : (ny, nx) array
        Water depth [m] on the terrain grid (row 0 = south); summed over several
        ``[[initial_water]]`` entries by the caller.
    dx : float
        Particle spacing [m].
    kappa : float
        Smoothing-length factor, h = kappa dx.
    d_min : float
        Lattice cells with depth d <= d_min [m] get no particle.
    particles : ParticleSet, optional
        Set to append to; a new one is made by default.
    wet : (ny, nx) bool array, optional
        Cells that may hold water (default: the valid cells; :func:`wet_cells`).

    Returns
    -------
    ParticleSet with x, y (local m), m = rho_w d dx^2 [kg], rho = rho_w d [kg m-2],
    h = kappa dx [m], at rest.
    """
    depth_grid = np.asarray(depth_grid, dtype=np.float64)
    if depth_grid.shape != terrain.shape:
        raise ValueError(f"depth grid shape {depth_grid.shape} != terrain {terrain.shape}")
    if not (dx > 0 and kappa > 0):
        raise ValueError(f"particle spacing and kappa must be > 0, got {dx}, {kappa}")
    d_cells = np.where(terrain.valid if wet is None else wet,
                       np.nan_to_num(depth_grid, nan=0.0), 0.0)
    xs, ys, d = lattice_depth(terrain, d_cells, dx)
    level = seeded_level(terrain, d_cells, dx)
    d = lump_thin_cells(d)
    li, ki = np.nonzero(d > d_min)
    depth = d[li, ki]
    if particles is None:
        particles = ParticleSet(capacity=max(2 * depth.size, 1024))
    return particles_at(xs[ki], ys[li], depth, dx, kappa, particles=particles,
                        eta_seed=level[li, ki])


def seeded_level(terrain: Terrain, depth_grid: np.ndarray, dx: float) -> np.ndarray:
    """The water level [m] of each lattice cell of spacing ``dx``: the area mean of d + z over
    its wet DEM cells (d > 0), NaN where it has none (the level a particle seeded at rest
    carries under the balanced momentum, ``floodsph.sph.level_offsets``)."""
    wet = (depth_grid > 0.0).astype(np.float64)
    z = np.nan_to_num(np.asarray(terrain.elevation, dtype=np.float64), nan=0.0)
    _, _, area = lattice_depth(terrain, wet, dx)
    _, _, volume = lattice_depth(terrain, wet * (depth_grid + z), dx)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(area > 0.0, volume / area, np.nan)


def particles_at(x, y, d, dx: float, kappa: float, u=0.0, v=0.0, d_min: float = 0.0,
                 particles: ParticleSet | None = None, eta_seed=np.nan) -> ParticleSet:
    """Water particles at the lattice nodes (x, y) [m, local] of spacing dx [m] where the depth
    d [m] exceeds ``d_min``: the one seeding convention of runs, verification cases and tests.

    Each particle is the water column of its lattice cell: m = rho_w d dx^2 [kg],
    rho = rho_w d [kg m-2], h = kappa dx [m], velocity (u, v) [m s-1] (scalars or arrays like
    x). Appended to ``particles`` if given, else to a new set.
    """
    x, y, d = (np.asarray(a, dtype=np.float64) for a in (x, y, d))
    keep = d > d_min
    count = int(keep.sum())
    if particles is None:
        particles = ParticleSet(count)
    if count:
        h0 = seeded_smoothing_length(kappa, dx)
        particles.append(x=x[keep], y=y[keep], m=RHO_WATER * d[keep] * dx**2,
                         rho=RHO_WATER * d[keep], h=np.full(count, h0),
                         u=np.broadcast_to(u, x.shape)[keep],
                         v=np.broadcast_to(v, x.shape)[keep],
                         eta_seed=np.broadcast_to(eta_seed, x.shape)[keep])
    return particles
