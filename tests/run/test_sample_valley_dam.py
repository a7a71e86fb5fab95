"""The shipped sample ``data_samples/valley_dam``: a breach opening in a crest-wall dam.

Facts that could fail: ``floodsph check`` finds no error and no warning; the wall closes the
gorge (the DEM stands above its crest at both ends) and holds the lake (its crest stands
above the level); the breach resolves to Froehlich's (2008) final width and formation time
for the volume and height the sample states; both flux lines reach above the lake level at
both ends, so that all the flow crosses them.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import rasterio
from click.testing import CliRunner

from floodsph.boundaries.crest import Crest, resolve_breach
from floodsph.cli.main import cli
from floodsph.constants import GRAVITY
from floodsph.scenario.reader import load_scenario

SCENARIO = Path(__file__).resolve().parents[2] / "data_samples" / "valley_dam" / "scenario.toml"


def _bed(points) -> np.ndarray:
    """The DEM bed [m] at points (x, y) of the sample's CRS."""
    scenario = load_scenario(SCENARIO)
    with rasterio.open(scenario.terrain.dem) as src:
        return np.array([v[0] for v in src.sample([tuple(p) for p in points])])


def test_the_sample_passes_the_checks():
    result = CliRunner().invoke(cli, ["check", str(SCENARIO)])
    assert result.exit_code == 0, result.output
    assert "Warnings:        0" in result.output
    assert "OK: the scenario is valid." in result.output


def test_the_wall_closes_the_gorge_above_the_lake_and_the_breach_is_froehlichs():
    scenario = load_scenario(SCENARIO)
    wall = scenario.walls[0]
    level = scenario.initial_water[0].level_m
    ends = _bed([wall.polyline[0], wall.polyline[-1]])
    assert np.all(ends > wall.crest_m) and wall.crest_m > level
    crest = Crest(np.asarray(wall.polyline), wall.crest_m)
    breach = resolve_breach(wall.breach, crest, "walls[0].breach")
    height = wall.crest_m - wall.breach.invert_m
    volume = wall.breach.reservoir_volume_m3
    average = 0.27 * 1.3 * volume**0.32 * height**0.04  # Froehlich (2008), overtopping
    assert breach.bottom_width_m == pytest.approx(average - breach.side_slope * height, rel=1e-12)
    assert breach.formation_s == pytest.approx(63.2 * math.sqrt(volume / (GRAVITY * height**2)),
                                               rel=1e-12)
    # the breach reaches down to the gorge floor at the dam line, within 0.2 m
    centre = np.interp(breach.centre_m, crest.s, np.asarray(wall.polyline)[:, 1])
    floor = _bed([(wall.polyline[0][0], centre)])[0]
    assert abs(breach.invert_m - floor) < 0.2


def test_the_flux_lines_reach_above_the_lake_at_both_ends():
    scenario = load_scenario(SCENARIO)
    level = scenario.initial_water[0].level_m
    with rasterio.open(scenario.terrain.dem) as src:
        left, bottom, right, top = src.bounds
    for line in scenario.flux_lines:
        for x, y in (line.polyline[0], line.polyline[-1]):
            beyond = not (left < x < right and bottom < y < top)
            assert beyond or _bed([(x, y)])[0] > level, line.name
