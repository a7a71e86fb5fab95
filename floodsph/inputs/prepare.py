"""From a validated scenario to the model's inputs: terrain, initial particles, hydrographs.

:func:`prepare_inputs` does every step that can fail on bad input, before a run folder is
created (``floodsph check`` stops after it and prints :func:`summary_lines`):

1. read or route the inflow hydrographs and integrate them up to the end time;
2. read the DEM's header and refuse a run too large for the memory available, from the grid
   shapes alone (``floodsph.inputs.memory``), before any grid is allocated;
3. load the DEM and roughness (``floodsph.inputs.dem.load_terrain``: fill values, feet, Manning
   values that are Strickler coefficients);
4. read the geometry given as vector files, reprojected into the DEM's CRS
   (``floodsph.inputs.vectors``), and check that all of it lies on the DEM
   (``floodsph.checks.placement``);
5. build the initial depth grid: the deepest of all ``[[initial_water]]`` bodies per cell
   (two overlapping still-water bodies hold the higher level, not the sum); refuse a
   scenario without water (``floodsph.checks.water``) and an inflow without a side to enter
   on (``floodsph.checks.inflows``);
6. estimate the memory again from the wet area (particles = wet area / spacing^2) and
   refuse before seeding; seed particles on the lattice of spacing
   ``numerics.particle_spacing_m`` (default: the DEM cell size);
7. read the gauge points (they must lie on the DEM);
8. the final memory estimate from the particle count; a warning above 5 million particles at
   peak or for a spacing finer than a quarter of the DEM cell (``floodsph.inputs.run_time``).

Problems the user may mean are warnings: logged, and kept in :attr:`Inputs.warnings` (the run
records them in ``run.json``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from rasterio.crs import CRS

from floodsph.checks.inflows import check_inflows
from floodsph.checks.levels import check_level_boundaries
from floodsph.checks.placement import check_geometry_on_dem
from floodsph.checks.water import check_has_water, dry_body_reason
from floodsph.errors import InputError
from floodsph.inputs.memory import (
    MemoryEstimate,
    check_memory,
    estimate_memory,
    format_bytes,
    kernels_cached,
)
from floodsph.inputs.run_time import estimate_run_time, run_threads, warn_if_huge
from floodsph.inputs.vectors import vector_gauges, with_vector_geometry
from floodsph.io.coordinates import inline_to_model
from floodsph.io.raster import crs_label
from floodsph.io.vector import is_vector_file
from floodsph.scenario.config import Scenario
from floodsph.sph.kernels import seeded_smoothing_length

if TYPE_CHECKING:
    from floodsph.model.particles import ParticleSet
    from floodsph.model.terrain import Terrain


@dataclass
class Inputs:
    """What a run starts from (all coordinates local to the terrain's origin).

    ``walls`` (polylines) and ``sinks`` (polygons) are (k, 2) arrays, inline ones and those
    read from vector files alike; ``flux_lines`` are (name, (k, 2) polyline) pairs.
    ``inflows`` are the scenario's ``[[inflows]]`` with their line and direction in the
    terrain's CRS (``floodsph.io.coordinates``). ``warnings`` lists the inputs accepted
    with a warning (each also logged at WARNING); ``conversions`` the units the input files
    were converted from (hydrographs in hours or cubic feet per second, dates), one sentence
    per file. ``wall_entries`` are the ``[[walls]]`` entries
    (``floodsph.scenario.config.Wall``, their crest and breach), one per polyline of
    ``walls``. ``level_boundaries`` are the ``[[level_boundaries]]`` entries (lines in the
    terrain's CRS) and ``level_series`` their levels
    (:class:`~floodsph.io.level_series.LevelSeries`), one per entry.
    """

    terrain: Terrain
    inflows: tuple
    depth: np.ndarray
    particles: ParticleSet
    spacing_m: float
    walls: list[np.ndarray]
    sinks: list[np.ndarray]
    hydrographs: list
    gauges: object | None
    volume_initial_m3: float
    volume_inflow_m3: float
    output_cells: int
    memory: MemoryEstimate
    warnings: list[str] = field(default_factory=list)
    conversions: list[str] = field(default_factory=list)
    flux_lines: list[tuple[str, np.ndarray]] = field(default_factory=list)
    wall_entries: tuple = ()
    level_boundaries: tuple = ()
    level_series: list = field(default_factory=list)


def prepare_inputs(scenario: Scenario) -> Inputs:
    """Load and check everything a run needs; raises ``InputError`` on bad input, including a
    run whose memory estimate exceeds the memory available (before allocating it)."""
    from floodsph.inputs.dem import load_terrain
    from floodsph.inputs.initial_water import seed_particles, wet_cells

    tc = scenario.terrain
    source = str(scenario.path.name)
    warnings: list[str] = []
    conversions: list[str] = []
    hydrographs = inflow_hydrographs(scenario, conversions)
    v_in = sum(float(hg.volume(0.0, scenario.end_time_s)) for hg in hydrographs)
    read = cells_read(scenario)
    check_memory(estimate_before_reading(scenario, v_in, read), source)

    terrain = load_terrain(
        tc.dem,
        crs=tc.crs,
        dem_variable=tc.dem_variable,
        manning=tc.manning,
        landcover=tc.landcover,
        manning_table=tc.manning_table,
        extent=tc.extent,
        coordinates_crs=scenario.scenario.crs,
        warnings=warnings,
    )
    spacing = scenario.numerics.particle_spacing_m or float(min(terrain.dx, terrain.dy))
    scenario = with_vector_geometry(inline_to_model(scenario, terrain), terrain)
    check_geometry_on_dem(scenario, terrain, spacing, source)
    wet = wet_cells(terrain, walled=tc.nodata_walled)
    dry: list[str] = []
    depth = initial_depth(scenario, terrain, wet, dry)
    levels = level_series(scenario)
    check_has_water(scenario, dry, bool(np.any(depth > 0.0)) or bool(levels), v_in, source,
                    warnings)
    check_inflows(scenario, terrain, depth, spacing, source, warnings)
    check_level_boundaries(scenario, terrain, levels, spacing, source, warnings)
    out_cells = output_cells(scenario, terrain.shape, terrain.dx, terrain.dy)
    n_wet = np.count_nonzero(depth > 0.0) * terrain.dx * terrain.dy / spacing / spacing
    lattice = lattice_cells(terrain.width, terrain.height, spacing)
    check_memory(_estimate(scenario, n_wet, v_in, spacing, terrain.elevation.size, out_cells,
                           lattice, read), source)

    particles = seed_particles(terrain, depth, spacing, scenario.numerics.kappa, wet=wet)
    if particles.n == 0 and v_in <= 0.0 and not levels:
        raise InputError(
            f"{source}: numerics.particle_spacing_m: the initial water seeds no particles at a "
            f"spacing of {spacing:g} m (its depth averaged over lattice cells of that size "
            "stays below 1 mm, or the lattice does not fit on the DEM); use a finer spacing")
    gauges = None
    if scenario.gauges is not None and is_vector_file(scenario.gauges.file):
        gauges = vector_gauges(scenario.gauges, terrain, source)
    elif scenario.gauges is not None:
        from floodsph.output.gauges import read_gauge_file

        gauges = read_gauge_file(scenario.gauges.file, terrain)
    memory = _estimate(scenario, particles.n, v_in, spacing, terrain.elevation.size, out_cells,
                       lattice, read)
    check_memory(memory, source)
    warn_if_huge(scenario, spacing, float(min(terrain.dx, terrain.dy)), memory.particles_peak,
                 source, warnings)
    walls = [local_points(terrain, w.polyline) for w in scenario.walls]
    return Inputs(
        terrain=terrain,
        inflows=scenario.inflows,
        depth=depth,
        particles=particles,
        spacing_m=spacing,
        walls=walls,
        sinks=[local_points(terrain, sink.polygon) for sink in scenario.sinks],
        hydrographs=hydrographs,
        gauges=gauges,
        volume_initial_m3=particles.volume(),
        volume_inflow_m3=v_in,
        output_cells=int(out_cells),
        memory=memory,
        warnings=warnings,
        conversions=conversions,
        flux_lines=[(line.name, local_points(terrain, line.polyline))
                    for line in scenario.flux_lines],
        wall_entries=tuple(scenario.walls),
        level_boundaries=scenario.level_boundaries,
        level_series=levels,
    )


def level_series(scenario: Scenario) -> list:
    """One :class:`~floodsph.io.level_series.LevelSeries` per ``[[level_boundaries]]``: its
    constant ``level_m``, or its CSV ``file`` read."""
    from floodsph.io.level_series import LevelSeries, read_level_series

    source = scenario.path.name
    out = []
    for i, entry in enumerate(scenario.level_boundaries):
        if entry.level_m is not None:
            out.append(LevelSeries.constant(entry.level_m))
        else:
            out.append(read_level_series(entry.file, f"{source}: level_boundaries[{i}].file"))
    return out


def local_points(terrain, points) -> np.ndarray:
    """World points [[x, y], ...] in the DEM's CRS as a (k, 2) array of local coordinates."""
    return np.column_stack(terrain.to_local(*np.asarray(points, dtype=np.float64).T))


def output_cells(scenario: Scenario, shape: tuple[int, int], dx: float, dy: float) -> float:
    """Cells of the map grid: the DEM grid, or ``output.resolution_m`` cells over it (a float:
    a resolution far too fine gives a count beyond any integer type, even infinity)."""
    ny, nx = shape
    res = scenario.output.resolution_m
    if res is None:
        return float(nx) * float(ny)
    with np.errstate(over="ignore"):
        return float(np.ceil(nx * dx / res) * np.ceil(ny * dy / res))


def lattice_cells(width: float, height: float, spacing: float) -> float:
    """Cells of the seeding lattice of ``spacing`` over a DEM (``floodsph.inputs.initial_water``),
    a float
    as :func:`output_cells`."""
    nx, ny = np.floor(width / spacing + 1e-9), np.floor(height / spacing + 1e-9)
    with np.errstate(over="ignore"):
        return float(nx * ny)


def _estimate(scenario, n_initial, v_in, spacing, dem_cells, out_cells, lattice,
              read_cells=None) -> MemoryEstimate:
    return estimate_memory(n_initial, v_in, spacing, scenario.numerics.refinement.value,
                           dem_cells, out_cells, read_cells=read_cells, lattice_cells=lattice,
                           compiling=not kernels_cached())


def cells_read(scenario: Scenario) -> float:
    """Cells of the rasters held at once while the terrain is loaded, from their headers: the
    DEM file and the largest of the Manning, land-cover and depth rasters (each read whole)."""
    from floodsph.io.mosaic import read_dem_header
    from floodsph.io.raster import read_header

    tc = scenario.terrain
    dem = read_dem_header(tc.dem, variable=tc.dem_variable, crs=tc.crs).cells
    others = [(tc.landcover, "landcover")]
    if isinstance(tc.manning, Path):
        others.append((tc.manning, "manning raster"))
    others += [(body.depth, f"initial_water[{i}].depth raster")
               for i, body in enumerate(scenario.initial_water)]
    largest = max((read_header(path, what=what).cells for path, what in others
                   if path is not None), default=0)
    return float(dem) + float(largest)


def estimate_before_reading(scenario: Scenario, volume_inflow_m3: float,
                            read_cells: float | None = None) -> MemoryEstimate:
    """The memory estimate from the rasters' headers, before any raster's values are read:
    the DEM's grids, the rasters read (``read_cells``, default :func:`cells_read`), the map
    grids, the seeding lattice and the inflow particles (no initial particles yet: they need
    the depth grid)."""
    from floodsph.inputs.dem import check_dem_size, planned_grid
    from floodsph.io.mosaic import read_dem_header, tile_names

    tc = scenario.terrain
    header = read_dem_header(tc.dem, variable=tc.dem_variable, crs=tc.crs)
    check_dem_size(header.shape, tile_names(tc.dem))
    grid = planned_grid(header, tc.extent, scenario.scenario.crs)
    spacing = scenario.numerics.particle_spacing_m or min(grid.dx, grid.dy)
    return _estimate(scenario, 0.0, volume_inflow_m3, spacing, grid.cells,
                     output_cells(scenario, (grid.rows, grid.cols), grid.dx, grid.dy),
                     lattice_cells(grid.width, grid.height, spacing),
                     cells_read(scenario) if read_cells is None else read_cells)


def initial_depth(scenario: Scenario, terrain, wet=None, dry: list[str] | None = None
                  ) -> np.ndarray:
    """Depth grid [m] (row 0 = south) of all initial water bodies: the cell-wise maximum,
    on the cells ``wet`` (default: the valid ones; ``floodsph.inputs.initial_water.wet_cells``).

    ``dry``, when a list, receives why each body that holds no water holds none
    (:func:`floodsph.checks.water.dry_body_reason`).
    """
    from floodsph.inputs.initial_water import depth_from_level, depth_from_raster

    source = str(scenario.path.name)
    depth = np.zeros(terrain.shape)
    for i, body in enumerate(scenario.initial_water):
        key = body.feature or f"initial_water[{i}]"
        if body.depth is not None:
            d = depth_from_raster(terrain, body.depth, f"{source}: {key}.depth", wet)
            polygon = None
        else:
            polygon = local_points(terrain, body.polygon)
            assert body.level_m is not None  # the reader requires level_m without a depth
            d = depth_from_level(terrain, body.level_m, polygon, f"{source}: {key}.polygon", wet)
        if dry is not None and not np.any(d > 0.0):
            dry.append(dry_body_reason(terrain, wet, body, polygon, key))
        np.maximum(depth, d, out=depth)
    return depth


def inflow_hydrographs(scenario: Scenario, conversions: list[str] | None = None) -> list:
    """One :class:`~floodsph.io.hydrograph.Hydrograph` per ``[[inflows]]``: its CSV read (the
    one place it is read; dates count from ``scenario.start``), or its breach (validated by
    ``floodsph.scenario.config``) routed. ``conversions`` receives the units converted."""
    from floodsph.io.hydrograph import Hydrograph, read_hydrograph

    source = str(scenario.path.name)
    out = []
    for i, inflow in enumerate(scenario.inflows):
        if inflow.hydrograph is not None:
            out.append(read_hydrograph(inflow.hydrograph, f"{source}: inflows[{i}].hydrograph",
                                       start=scenario.start, conversions=conversions))
        else:
            from floodsph.breach import breach_hydrograph

            assert inflow.breach is not None  # the reader requires [breach] without a CSV
            t, Q, _ = breach_hydrograph(inflow.breach)
            out.append(Hydrograph(t, Q))
    return out


def crs_lines(terrain) -> list[str]:
    """The ``check`` lines on the CRSs: the model's and the maps' (with its scale factors over
    the domain), the DEM file's when it differs, and the one of the inline coordinates."""
    from floodsph.io.coordinates import coordinates_label
    from floodsph.io.crs import scale_range

    if not terrain.crs_wkt:
        return [f"CRS:             {crs_label(terrain.crs_wkt)}"]
    crs = CRS.from_wkt(terrain.crs_wkt)
    lo, hi = scale_range(crs, terrain.north_up_transform(), terrain.shape)
    lines = [f"CRS:             {crs_label(terrain.crs_wkt)} (the model and the maps), scale "
             f"factor {lo:.5f} to {hi:.5f} over the domain"]
    source = terrain.source_crs_wkt
    if source and CRS.from_wkt(source) != crs:
        found = ("geographic" if terrain.source_scale is None else
                 f"scale factor {terrain.source_scale[0]:.5f} to {terrain.source_scale[1]:.5f}")
        lines.append(f"DEM file CRS:    {crs_label(source)} ({found}); converted to the "
                     "model's CRS")
    lines.append(f"Coordinates:     {coordinates_label(terrain)} (inline coordinates)")
    return lines


def summary_lines(scenario: Scenario, inputs: Inputs, available: int | None) -> list[str]:
    """The ``floodsph check`` report: domain, CRS, volumes, particles, memory, run time."""
    t = inputs.terrain
    ny, nx = t.shape
    valid = int(np.count_nonzero(t.valid))
    n_in = len(scenario.inflows)
    mem = inputs.memory
    avail = "unknown" if available is None else format_bytes(available)
    return [
        f"Scenario:        {scenario.name} ({scenario.path})",
        f"End time:        {scenario.end_time_s:g} s",
        f"Domain:          {t.width / 1000:.3f} km x {t.height / 1000:.3f} km, "
        f"{nx} x {ny} cells of {t.dx:g} m x {t.dy:g} m ({valid} with data)",
        *crs_lines(t),
        f"Edges:           {scenario.terrain.edges.value}"
        + (f" (closed: {', '.join(scenario.terrain.closed_sides)})"
           if scenario.terrain.closed_sides else ""),
        f"Initial water:   {inputs.volume_initial_m3:.6g} m3 "
        f"({len(scenario.initial_water)} bodies)",
        f"Inflow volume:   {inputs.volume_inflow_m3:.6g} m3 up to the end time "
        f"({n_in} inflows)",
        f"Particles:       {inputs.particles.n}",
        f"Spacing:         {inputs.spacing_m:g} m "
        f"(h0 = {seeded_smoothing_length(scenario.numerics.kappa, inputs.spacing_m):g} m)",
        f"Peak memory:     ~{format_bytes(mem.total)} (estimate, {mem.particles_peak:,} "
        f"particles at peak); available {avail}",
        f"Run time:        {estimate_run_time(scenario, inputs, run_threads(scenario)).text()}",
        f"Warnings:        {len(inputs.warnings)}",
        *(f"Converted:       {note}" for note in inputs.conversions),
    ]
