"""Flux lines, the outflow per sink and open side, and snapshots at listed times.

Physical facts that could fail: the net volume through a line drawn across a dam break is the
volume that appeared beyond it (every displacement of water counted: drift, splits, merges);
reversing the line reverses the sign; the discharge through a line downstream of a steady
inflow is the inflow's; the outflow by sink and side adds up to the total; snapshots land on
the listed times and their level is depth + bed.
"""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest
import xarray as xr
from conftest import CELL, X0, Y0, write_geotiff

from floodsph.constants import RHO_WATER
from floodsph.errors import InputError
from floodsph.run.pipeline import run_scenario
from floodsph.scenario.reader import load_scenario
from floodsph.simulation.flux import FluxLines
from floodsph.simulation.schedules import IterationInterval

NX, NY = 40, 20
LINE_X = 150.0  # local x of the section across the flat valley [m]

DAM_BREAK = f"""
[scenario]
name = "flux"
end_time_s = 30.0

[terrain]
dem = "flat.tif"
manning = 0.03
edges = "closed"

[[initial_water]]
level_m = 102.0
polygon = [[{X0}, {Y0}], [{X0 + 100}, {Y0}], [{X0 + 100}, {Y0 + NY * CELL}],
           [{X0}, {Y0 + NY * CELL}]]

[[flux_lines]]
name = "section"
polyline = [[{X0 + LINE_X + 5}, {Y0 - 10}], [{X0 + LINE_X}, {Y0 + 100}],
            [{X0 + LINE_X + 5}, {Y0 + NY * CELL + 10}]]

[[flux_lines]]
name = "reversed"
polyline = [[{X0 + LINE_X + 5}, {Y0 + NY * CELL + 10}], [{X0 + LINE_X}, {Y0 + 100}],
            [{X0 + LINE_X + 5}, {Y0 - 10}]]

[numerics]
particle_spacing_m = 10.0
refinement = "split+coalesce"
time_stepping = "{{stepping}}"

[output]
resolution_m = 10.0
mass_balance_interval_s = 2.0
{{output}}
"""
"""A 2 m dam break on a flat, closed valley; the section (drawn south to north, with a kink
at y = 100 m) has the valley floor east of it on its right."""


def beyond_section(x, y) -> np.ndarray:
    """True east of the kinked section of :data:`DAM_BREAK` (local coordinates)."""
    line_x = np.where(y < 100.0, LINE_X + 5.0 - 5.0 * (y + 10.0) / 110.0,
                      LINE_X + 5.0 * (y - 100.0) / 110.0)
    return x > line_x


@pytest.fixture
def flat_valley(tmp_path):
    write_geotiff(tmp_path / "flat.tif", np.full((NY, NX), 100.0))

    def make(stepping: str = "global", output: str = "", name: str = "flux.toml"):
        path = tmp_path / name
        path.write_text(DAM_BREAK.replace("{stepping}", stepping).replace("{output}", output))
        return load_scenario(path)

    return make


@pytest.mark.parametrize("stepping", ["global", "local"])
def test_the_net_volume_through_a_section_is_the_volume_that_appeared_beyond_it(
        flat_valley, tmp_path, stepping):
    scenario = flat_valley(stepping)
    beyond = []

    def measure(sim):
        p = sim.model.particles
        beyond.append(float(p.m[beyond_section(p.x, p.y)].sum()) / RHO_WATER)

    m = run_scenario(scenario, tmp_path / "run", progress=False,
                     callbacks=[(measure, IterationInterval(1))])
    assert m["splits"] > 0 and m["merges"] > 0  # refinement moves water too
    section, reversed_ = m["flux_lines"]
    assert beyond[0] == 0.0 and beyond[-1] > 1000.0  # a fifth of the reservoir passed
    assert section["volume_net_m3"] == pytest.approx(beyond[-1], rel=1e-12)
    assert section["volume_net_m3"] == pytest.approx(
        section["volume_left_to_right_m3"] - section["volume_right_to_left_m3"], rel=1e-12)
    # the same line drawn the other way: the same volume, the other sign and direction
    assert reversed_["volume_net_m3"] == pytest.approx(-section["volume_net_m3"], rel=1e-12)
    assert reversed_["volume_right_to_left_m3"] == pytest.approx(
        section["volume_left_to_right_m3"], rel=1e-12)

    with open(tmp_path / "run" / "flux.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == ["time_s", "section_m3s", "reversed_m3s"]
    times = np.array([float(r["time_s"]) for r in rows])
    q = np.array([float(r["section_m3s"]) for r in rows])
    assert np.allclose(times, np.arange(2.0, 30.1, 2.0))  # every mass-balance interval
    np.testing.assert_allclose(q, -np.array([float(r["reversed_m3s"]) for r in rows]),
                               rtol=1e-12)
    assert float(np.sum(q * 2.0)) == pytest.approx(section["volume_net_m3"], rel=1e-9)


def test_the_discharge_through_a_line_below_a_steady_inflow_is_the_inflow(tmp_path):
    """100 m3/s enter a sloping channel open to the east; once the flow is steady, the mean
    discharge through a line half-way down is 100 m3/s (within 1.1 % measured at this 10 m
    spacing, 0.02 % at 5 m). A sink takes part of the water near the outlet: the outflow by
    sink and side adds up to volume_out_m3."""
    nx, q_in, end = 30, 100.0, 500.0
    x = (np.arange(nx) + 0.5) * CELL
    write_geotiff(tmp_path / "slope.tif", np.tile(100.0 - 0.005 * x, (NY, 1)))
    (tmp_path / "q.csv").write_text(f"time_s,discharge_m3s\n0,{q_in}\n{end},{q_in}\n")
    path = tmp_path / "steady.toml"
    path.write_text(f"""
[scenario]
name = "steady"
end_time_s = {end}

[terrain]
dem = "slope.tif"
manning = 0.03
edges = "open"
closed_sides = ["west", "south", "north"]

[[inflows]]
line = [[{X0 + 5}, {Y0 + 10}], [{X0 + 5}, {Y0 + NY * CELL - 10}]]
hydrograph = "q.csv"
direction = [1.0, 0.0]

[[sinks]]
polygon = [[{X0 + 260}, {Y0 + 150}], [{X0 + 300}, {Y0 + 150}], [{X0 + 300}, {Y0 + 200}],
           [{X0 + 260}, {Y0 + 200}]]

[[flux_lines]]
name = "mid"
polyline = [[{X0 + 150}, {Y0}], [{X0 + 150}, {Y0 + NY * CELL}]]

[numerics]
particle_spacing_m = 10.0

[output]
resolution_m = 10.0
mass_balance_interval_s = 10.0
""")
    m = run_scenario(load_scenario(path), tmp_path / "run", progress=False)
    with open(tmp_path / "run" / "flux.csv", newline="") as f:
        rows = [(float(r["time_s"]), float(r["mid_m3s"])) for r in csv.DictReader(f)]
    steady = [q for t, q in rows if t > 250.0]
    assert len(steady) == 25
    assert np.mean(steady) == pytest.approx(q_in, rel=0.03)
    assert rows[0][1] == 0.0  # nothing has reached the line in the first 10 s

    sinks, sides = m["volume_out_sinks_m3"], m["volume_out_sides_m3"]
    assert len(sinks) == 1 and sinks[0] > 0.0
    assert set(sides) == {"east"} and sides["east"] > 0.0
    total = sum(sinks) + sum(sides.values()) + m["volume_out_other_m3"]
    assert total == pytest.approx(m["volume_out_m3"], rel=1e-12)


def test_snapshots_land_on_the_listed_times_with_the_level(flat_valley, tmp_path):
    scenario = flat_valley(output="snapshot_times_s = [3.3, 7.7, 30.0]")
    run_scenario(scenario, tmp_path / "run", progress=False)
    with xr.open_dataset(tmp_path / "run" / "snapshots.nc", decode_times=False) as ds:
        assert ds["time"].values.tolist() == [3.3, 7.7, 30.0]  # exactly, not the steps near
        depth, level = ds["depth"].values, ds["level"].values
        bed = 100.0
        assert ds["level"].attrs["units"] == "m"
        assert ds["level"].attrs["standard_name"] == "water_surface_height_above_reference_datum"
        assert ds["level"].attrs["grid_mapping"] == "crs"
    wet = depth > scenario.output.wet_threshold_m
    assert wet.any() and (~wet).any()
    np.testing.assert_allclose(level[wet], depth[wet] + bed, rtol=0, atol=1e-4)  # float32
    assert np.isnan(level[~wet]).all()


def test_listed_snapshot_times_join_the_interval(flat_valley, tmp_path):
    scenario = flat_valley(output="snapshot_interval_s = 10.0\nsnapshot_times_s = [3.3, 10.0]")
    run_scenario(scenario, tmp_path / "run", progress=False)
    with xr.open_dataset(tmp_path / "run" / "snapshots.nc", decode_times=False) as ds:
        assert ds["time"].values.tolist() == [0.0, 3.3, 10.0, 20.0, 30.0]


def test_a_crossing_is_counted_once_at_a_vertex_and_not_beside_the_line():
    lines = FluxLines([("bend", np.array([[0.0, 0.0], [0.0, 1.0], [1.0, 2.0]]))])
    x0 = np.array([-1.0, -1.0, 1.0, -1.0, 0.5])
    y0 = np.array([1.0, 0.5, 0.5, -0.5, 3.0])
    x1 = np.array([1.0, 1.0, -1.0, 1.0, 0.5])
    y1 = np.array([1.0, 0.5, 0.5, -0.5, 1.0])
    m = np.array([1.0, 2.0, 4.0, 8.0, 16.0]) * RHO_WATER
    lines.count(x0, y0, x1, y1, m)
    # through the vertex (1), across the first segment (2), back across it (4), below its
    # first end (8: not counted), down across the second segment from its left (16)
    assert lines.summary()[0] == {"name": "bend", "volume_net_m3": 1.0 + 2.0 - 4.0 + 16.0,
                                  "volume_left_to_right_m3": 19.0,
                                  "volume_right_to_left_m3": 4.0}
    lines.record(0.0)
    lines.record(5.0)
    assert lines.rows == [(5.0, 15.0 / 5.0)]
    assert math.isclose(lines.since_row[0], 0.0)


def flux_line(name: str = "a", points: str = "[[500100.0, 4000010.0], [500100.0, 4000190.0]]"):
    return f'[[flux_lines]]\nname = "{name}"\npolyline = {points}\n'


@pytest.mark.parametrize(("flux", "output", "message"), [
    (flux_line(points="[[500100.0, 4000010.0]]"), "",
     r"flux_lines\[0\]\.polyline: expected at least 2 \[x, y\] points, got 1"),
    (flux_line(points="[[500100.0, 4000010.0], [500100.0, 4000010.0]]"), "",
     r"flux_lines\[0\]\.polyline: the line has zero length"),
    (flux_line() + flux_line(), "", r"flux_lines\[1\]\.name: 'a' names an earlier flux line"),
    (flux_line("a,b"), "", r"flux_lines\[0\]\.name: must be a name without commas"),
    ("[[flux_lines]]\npolyline = [[500100.0, 4000010.0], [500110.0, 4000010.0]]\n", "",
     r"flux_lines\[0\]\.name"),
    ("", "snapshot_times_s = [5.0, 5.0]",
     r"output\.snapshot_times_s\[1\]: 5 s does not follow 5 s"),
    ("", "snapshot_times_s = [-1.0]", r"output\.snapshot_times_s\[0\]: -1 s is before the start"),
    ("", "snapshot_times_s = [5.0, 25.0]",
     r"output\.snapshot_times_s\[1\]: 25 s is beyond the end of the run, "
     r"scenario\.end_time_s = 20 s"),
    ("", "snapshot_times_s = 5.0", r"output\.snapshot_times_s: expected an array"),
])
def test_bad_flux_lines_and_snapshot_times_are_refused_naming_the_key(write_scenario, flux,
                                                                       output, message):
    from conftest import BASE_SCENARIO

    text = BASE_SCENARIO.replace("\n[numerics]", "\n" + flux + "\n[numerics]") + output + "\n"
    with pytest.raises(InputError, match=message):
        load_scenario(write_scenario(text))


def test_a_flux_line_off_the_dem_is_refused(write_scenario):
    from conftest import BASE_SCENARIO

    from floodsph.inputs.prepare import prepare_inputs

    text = BASE_SCENARIO.replace("\n[numerics]", '\n[[flux_lines]]\nname = "far"\n'
                                 "polyline = [[0.0, 0.0], [10.0, 0.0]]\n\n[numerics]")
    with pytest.raises(InputError, match=r"flux_lines\[0\]\.polyline: the flux line 'far' "
                                         r"lies wholly outside the DEM extent"):
        prepare_inputs(load_scenario(write_scenario(text)))
