"""From a validated scenario to the model's inputs: terrain, initial particles, hydrographs.

:func:`prepare_inputs` does every step that can fail on bad input, before a run folder is
created (``floodsph check`` stops after it and prints :func:`summary_lines`):

1. load the DEM and roughness (``floodsph.io.dem.load_terrain``);
2. check that the scenario's geometry lies on the DEM (inflow lines);
3. build the initial depth grid: the deepest of all ``[[initial_water]]`` bodies per cell
   (two overlapping still-water bodies hold the higher level, not the sum);
4. seed particles on the lattice of spacing ``numerics.particle_spacing_m`` (default: the DEM
   cell size);
5. read or route the inflow hydrographs and integrate them up to the end time;
6. read the gauge points (they must lie on the DEM);
7. estimate the peak memory (``floodsph.memory``).
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass

import numpy as np

from floodsph.errors import InputError
from floodsph.memory import MemoryEstimate, estimate_memory, format_bytes
from floodsph.scenario import Scenario

log = logging.getLogger(__name__)


@dataclass
class Inputs:
    """What a run starts from (all coordinates local to the terrain's origin)."""

    terrain: object
    depth: np.ndarray
    particles: object
    spacing_m: float
    walls: list[np.ndarray]
    hydrographs: list
    gauges: object | None
    volume_initial_m3: float
    volume_inflow_m3: float
    output_cells: int
    memory: MemoryEstimate


def prepare_inputs(scenario: Scenario) -> Inputs:
    """Load and check everything a run needs; raises ``InputError`` on bad input."""
    from floodsph.initial import seed_particles, wet_cells
    from floodsph.io.dem import load_terrain

    tc = scenario.terrain
    terrain = load_terrain(
        tc.dem,
        crs=tc.crs,
        dem_variable=tc.dem_variable,
        manning=tc.manning,
        landcover=tc.landcover,
        manning_table=tc.manning_table,
        extent=tc.extent,
    )
    source = str(scenario.path.name)
    for i, inflow in enumerate(scenario.inflows):
        for point in inflow.line:
            _check_on_dem(terrain, point, f"{source}: inflows[{i}].line")
    wet = wet_cells(terrain, walled=tc.nodata_walled)
    depth = initial_depth(scenario, terrain, wet)
    spacing = scenario.numerics.particle_spacing_m or float(min(terrain.dx, terrain.dy))
    particles = seed_particles(terrain, depth, spacing, scenario.numerics.kappa, wet=wet)
    hydrographs = inflow_hydrographs(scenario)
    gauges = None
    if scenario.gauges is not None:
        from floodsph.output.gauges import read_gauge_file

        gauges = read_gauge_file(scenario.gauges.file, terrain)
    v_in = sum(float(hg.volume(0.0, scenario.end_time_s)) for hg in hydrographs)
    res = scenario.output.resolution_m
    ny, nx = terrain.shape
    out_cells = nx * ny if res is None else int(np.ceil(terrain.width / res)) * int(
        np.ceil(terrain.height / res)
    )
    memory = estimate_memory(
        particles.n, v_in, spacing, scenario.numerics.refinement.value, nx * ny, out_cells
    )
    walls = [
        np.column_stack(terrain.to_local(*np.asarray(w.polyline, dtype=np.float64).T))
        for w in scenario.walls
    ]
    return Inputs(
        terrain=terrain,
        depth=depth,
        particles=particles,
        spacing_m=spacing,
        walls=walls,
        hydrographs=hydrographs,
        gauges=gauges,
        volume_initial_m3=particles.volume(),
        volume_inflow_m3=v_in,
        output_cells=out_cells,
        memory=memory,
    )


def _check_on_dem(terrain, point, where: str) -> None:
    """Refuse a world point off the DEM grid or on a nodata cell."""
    x, y = terrain.to_local(point[0], point[1])
    col, row = int(np.floor(x / terrain.dx)), int(np.floor(y / terrain.dy))
    ny, nx = terrain.shape
    if not (0 <= col < nx and 0 <= row < ny):
        xmin, ymin = terrain.x0, terrain.y0
        extent = [xmin, ymin, xmin + terrain.width, ymin + terrain.height]
        raise InputError(
            f"{where}: point [{point[0]:g}, {point[1]:g}] is outside the DEM extent "
            f"[{', '.join(f'{v:g}' for v in extent)}]"
        )
    if not terrain.valid[row, col]:
        raise InputError(f"{where}: point [{point[0]:g}, {point[1]:g}] lies on DEM nodata")


def initial_depth(scenario: Scenario, terrain, wet=None) -> np.ndarray:
    """Depth grid [m] (row 0 = south) of all initial water bodies: the cell-wise maximum,
    on the cells ``wet`` (default: the valid ones; ``floodsph.initial.wet_cells``)."""
    from floodsph.initial import depth_from_level, depth_from_raster

    source = str(scenario.path.name)
    depth = np.zeros(terrain.shape)
    for i, body in enumerate(scenario.initial_water):
        where = f"{source}: initial_water[{i}]"
        if body.depth is not None:
            d = depth_from_raster(terrain, body.depth, f"{where}.depth", wet)
        else:
            polygon = np.column_stack(
                terrain.to_local(*np.asarray(body.polygon, dtype=np.float64).T)
            )
            d = depth_from_level(terrain, body.level_m, polygon, f"{where}.polygon", wet)
        np.maximum(depth, d, out=depth)
    return depth


def inflow_hydrographs(scenario: Scenario) -> list:
    """One :class:`~floodsph.hydrograph.Hydrograph` per ``[[inflows]]`` (CSV or routed breach)."""
    from floodsph.hydrograph import Hydrograph, read_hydrograph

    source = str(scenario.path.name)
    out = []
    for i, inflow in enumerate(scenario.inflows):
        where = f"{source}: inflows[{i}]"
        if inflow.hydrograph is not None:
            out.append(read_hydrograph(inflow.hydrograph, f"{where}.hydrograph"))
        else:
            from floodsph.breach import BreachParams, breach_hydrograph

            table = {"method": inflow.breach.method, **inflow.breach.parameters}
            params = BreachParams.from_mapping(table, f"inflows[{i}].breach", source=source)
            t, Q, _ = breach_hydrograph(params)
            out.append(Hydrograph(t, Q))
    return out


def crs_label(crs_wkt: str | None) -> str:
    """``'EPSG:32632 (WGS 84 / UTM zone 32N)'`` from a WKT (name only if there is no code)."""
    if not crs_wkt:
        return "none (synthetic terrain)"
    from rasterio.crs import CRS

    match = re.search(r'^\s*\w+\["([^"]*)"', crs_wkt)
    name = match.group(1) if match else "unnamed"
    epsg = CRS.from_wkt(crs_wkt).to_epsg()
    return f"EPSG:{epsg} ({name})" if epsg else name


def summary_lines(scenario: Scenario, inputs: Inputs, available: int | None) -> list[str]:
    """The ``floodsph check`` report: domain, CRS, volumes, particles, memory."""
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
        f"CRS:             {crs_label(t.crs_wkt)}",
        f"Edges:           {scenario.terrain.edges.value}"
        + (f" (closed: {', '.join(scenario.terrain.closed_sides)})"
           if scenario.terrain.closed_sides else ""),
        f"Initial water:   {inputs.volume_initial_m3:.6g} m3 "
        f"({len(scenario.initial_water)} bodies)",
        f"Inflow volume:   {inputs.volume_inflow_m3:.6g} m3 up to the end time "
        f"({n_in} inflows)",
        f"Particles:       {inputs.particles.n}",
        f"Spacing:         {inputs.spacing_m:g} m "
        f"(h0 = {scenario.numerics.kappa * inputs.spacing_m:g} m)",
        f"Peak memory:     ~{format_bytes(mem.total)} (estimate, {mem.particles_peak} particles "
        f"at peak); available {avail}",
    ]
