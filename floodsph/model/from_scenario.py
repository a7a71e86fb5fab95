"""The model of a scenario: its numerics, walls, closed sides and open boundaries, set up.

The bridge between the scenario (``floodsph.scenario``) with its prepared inputs
(``floodsph.inputs.prepare.Inputs``) and ``floodsph.model.builder.set_up_model``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from floodsph.boundaries import Inflow, LevelBoundary, Sink
from floodsph.boundaries.crest import Crest, check_crest_above_bed, resolve_breach
from floodsph.boundaries.open_edges import SIDES
from floodsph.boundaries.protocol import Boundary
from floodsph.boundaries.weir import IDEAL_COEFFICIENT, Weir, bed_at
from floodsph.checks.levels import level_section
from floodsph.model.builder import set_up_model
from floodsph.model.refinement import Refiner
from floodsph.scenario.config import Edges, Scenario
from floodsph.sph.kernels import seeded_smoothing_length


def build_model(scenario: Scenario, inputs):
    """The FloodModel of ``scenario`` from prepared inputs, with its open boundaries.

    The model's numerics are the scenario's, with ``particle_spacing_m`` the spacing the
    particles were seeded at (the DEM cell size when the scenario gives none); the
    ``[[flux_lines]]`` count the water crossing them from the first step
    (``FloodModel.flux_lines``).
    """
    numerics = replace(scenario.numerics, particle_spacing_m=inputs.spacing_m)
    model = set_up_model(
        inputs.terrain,
        inputs.particles,
        numerics,
        walls=inputs.walls,
        closed_sides=_closed_sides(scenario),
        boundaries=open_boundaries(scenario, inputs, numerics),
        refiner=Refiner.of(numerics),
        held=inputs.depth > 0.0,
        level_sides=_level_sides(scenario),
    )
    if inputs.flux_lines:
        from floodsph.simulation.flux import FluxLines

        model.flux_lines = FluxLines(inputs.flux_lines)
    return model


def _closed_sides(scenario: Scenario) -> frozenset[str]:
    """``set_up_model(closed_sides=...)``: the sides of the DEM kept closed, all four when
    ``terrain.edges = "closed"``, less the sides of level boundaries."""
    terrain = scenario.terrain
    closed = SIDES if terrain.edges is Edges.CLOSED else terrain.closed_sides
    return frozenset(closed) - _level_sides(scenario)


def _level_sides(scenario: Scenario) -> frozenset[str]:
    """The sides of the DEM taken by ``[[level_boundaries]]``."""
    return frozenset(b.side for b in scenario.level_boundaries if b.side is not None)


def open_boundaries(scenario: Scenario, inputs, numerics) -> list[Boundary]:
    """The ``[[inflows]]`` sections (``inputs.inflows``, in the terrain's CRS), ``[[sinks]]``
    polygons (``inputs.sinks``, inline or from vector files), crest walls and
    ``[[level_boundaries]]`` as model boundaries."""
    terrain = inputs.terrain
    source = scenario.path.name
    out: list[Boundary] = []
    for i, (inflow, hydrograph) in enumerate(zip(inputs.inflows, inputs.hydrographs,
                                                 strict=True)):
        line = np.column_stack(terrain.to_local(*np.asarray(inflow.line, dtype=np.float64).T))
        out.append(Inflow(line, hydrograph, numerics.particle_spacing_m, numerics.kappa, terrain,
                          direction=inflow.direction, name=f"{source}: inflows[{i}]"))
    reach = 4.0 * seeded_smoothing_length(numerics.kappa, numerics.particle_spacing_m)
    for polygon in inputs.sinks:
        out.append(Sink(polygon, terrain, reach))
    out.extend(weirs(inputs, numerics, source))
    out.extend(level_boundaries(inputs, numerics, source))
    return out


def level_boundaries(inputs, numerics, source: str) -> list[LevelBoundary]:
    """The ``[[level_boundaries]]`` (``inputs.level_boundaries``, lines in the terrain's CRS)
    with their level series, sections checked on the DEM (``floodsph.checks.levels``)."""
    terrain = inputs.terrain
    out = []
    for i, (entry, series) in enumerate(zip(inputs.level_boundaries, inputs.level_series,
                                            strict=True)):
        line, normal = level_section(entry, terrain, numerics.particle_spacing_m,
                                     f"{source}: level_boundaries[{i}]")
        out.append(LevelBoundary(line, normal, series, numerics.particle_spacing_m,
                                 numerics.kappa, terrain, name=entry.name))
    return out


def weirs(inputs, numerics, source: str) -> list[Weir]:
    """The ``[[walls]]`` with a ``crest_m`` as weirs (``floodsph.boundaries.weir``), their
    breaches resolved and checked on the wall and the DEM."""
    terrain = inputs.terrain
    out = []
    for i, (entry, line) in enumerate(zip(getattr(inputs, "wall_entries", ()), inputs.walls,
                                          strict=False)):
        if entry.crest_m is None:
            continue
        label = f"walls[{i}]" if entry.feature is None else f"walls[{i}] ({entry.feature})"
        name = f"{source}: {label}"
        crest = Crest(line, entry.crest_m)
        check_crest_above_bed(crest, lambda x, y: bed_at(terrain, x, y), name)
        if entry.breach is not None:
            crest = Crest(line, entry.crest_m, resolve_breach(entry.breach, crest,
                                                              f"{name}.breach"))
        coefficient = entry.discharge_coefficient or IDEAL_COEFFICIENT
        out.append(Weir(crest, numerics.particle_spacing_m, numerics.kappa, coefficient,
                        name=label))
    return out
