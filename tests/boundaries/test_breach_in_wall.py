"""A breach opening in a crest wall that holds a small reservoir, run from a scenario file
(``[[walls]] crest_m``, ``[walls.breach]``, ``[[flux_lines]]``; ``docs/structures.md`` §3).

Physical facts asserted: nothing leaves the reservoir until the breach's notch reaches the
water; then the reservoir loses what the wall reports passed, to round-off; the flux line
below the wall counts the water that appeared beyond it, and together with the water between
the wall and the line it is the reservoir's loss, to round-off.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import X0, Y0, write_geotiff

from floodsph.constants import RHO_WATER
from floodsph.run.pipeline import run_scenario
from floodsph.scenario.reader import load_scenario
from floodsph.simulation.schedules import IterationInterval

CELL = 1.0
NX, NY = 30, 6  # a channel 30 m long, 6 m wide
WALL_X = 10.0  # the crest wall across it [m, local]
LINE_X = 12.0  # the flux line across it [m, local]
LEVEL, CREST, INVERT = 101.0, 101.2, 100.05
START, FORMATION = 1.0, 4.0
#: When the breach's notch reaches the water: its bottom falls from the crest to the invert
#: linearly over the formation time.
REACHES_WATER = START + FORMATION * (CREST - LEVEL) / (CREST - INVERT)

SCENARIO = f"""
[scenario]
name = "breach-in-wall"
end_time_s = 12.0

[terrain]
dem = "channel.tif"
manning = 0.02
edges = "closed"

[[initial_water]]
level_m = {LEVEL}
polygon = [[{X0}, {Y0}], [{X0 + WALL_X}, {Y0}], [{X0 + WALL_X}, {Y0 + NY}], [{X0}, {Y0 + NY}]]

[[walls]]
polyline = [[{X0 + WALL_X}, {Y0 - 1}], [{X0 + WALL_X}, {Y0 + 3}], [{X0 + WALL_X}, {Y0 + NY + 1}]]
crest_m = {CREST}

[walls.breach]
centre_m = 4.0
invert_m = {INVERT}
bottom_width_m = 2.0
side_slope = 1.0
start_s = {START}
formation_s = {FORMATION}

[[flux_lines]]
name = "below"
polyline = [[{X0 + LINE_X}, {Y0 - 1}], [{X0 + LINE_X}, {Y0 + NY + 1}]]

[numerics]
particle_spacing_m = 0.5
time_stepping = "global"

[output]
resolution_m = 1.0
formats = []
"""


def test_the_flux_line_counts_what_the_reservoir_loses_through_the_breach(tmp_path):
    """A 1 m deep reservoir on a flat bed behind a crest wall 0.2 m above it; below the wall
    the bed falls 3 % towards the closed east end. The breach (2 m wide at the bottom, down
    to 5 cm above the bed) starts at 1 s and reaches the water at 1.7 s."""
    x = (np.arange(NX) + 0.5) * CELL
    bed = 100.0 - 0.03 * np.maximum(x - WALL_X, 0.0)
    write_geotiff(tmp_path / "channel.tif", np.tile(bed, (NY, 1)), cell=CELL)
    (tmp_path / "scenario.toml").write_text(SCENARIO)
    scenario = load_scenario(tmp_path / "scenario.toml")
    rows = []

    def count(sim):
        model = sim.model
        p = model.particles
        volume = p.m / RHO_WATER
        line = model.flux_lines
        rows.append((model.t, volume[p.x < WALL_X].sum(),
                     volume[(p.x > WALL_X) & (p.x < LINE_X)].sum(), volume[p.x > LINE_X].sum(),
                     line.forward[0] - line.backward[0]))

    m = run_scenario(scenario, tmp_path / "run", progress=False,
                     callbacks=[(count, IterationInterval(1))])
    t, reservoir, between, beyond, through = map(np.array, zip(*rows, strict=True))
    start = reservoir[0]
    # nothing passes before the notch reaches the water ...
    before = t <= REACHES_WATER
    assert before.sum() > 3 and np.all(reservoir[before] == start)
    assert np.all(through[before] == 0.0)
    # ... then much of the reservoir does, and its loss is what the wall passed
    lost = start - reservoir[-1]
    assert lost > 0.3 * start
    passed = m["walls_overtopped_m3"]["walls[0]"]
    assert passed["right_to_left_m3"] == 0.0  # a wall drawn northwards has the east on its right
    assert passed["left_to_right_m3"] == pytest.approx(lost, rel=1e-9)
    # the flux line counts the water that appeared beyond it; with the water between the
    # wall and the line, that is the reservoir's loss, at every step
    assert m["flux_lines"][0]["volume_net_m3"] == pytest.approx(through[-1], rel=1e-12)
    assert through[-1] > 0.8 * lost  # most of it has crossed the line
    np.testing.assert_allclose(through, beyond, rtol=1e-9, atol=1e-9 * start)
    np.testing.assert_allclose(through + between, start - reservoir, rtol=1e-9,
                               atol=1e-9 * start)
