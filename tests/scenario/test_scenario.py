"""Scenario TOML: defaults, path resolution, the resolved copy, and exact error messages."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import BASE_SCENARIO, X0, Y0

from floodsph.errors import InputError
from floodsph.scenario.config import Edges, OutputFormat
from floodsph.scenario.numerics import Refinement
from floodsph.scenario.reader import load_scenario
from floodsph.scenario.writer import write_resolved

MINIMAL = """\
[scenario]
name = "mini"
end_time_s = 60

[terrain]
dem = "dem.tif"
"""


def test_defaults_and_relative_paths(write_scenario, tmp_path):
    sc = load_scenario(write_scenario(MINIMAL))
    assert sc.terrain.dem == (tmp_path / "dem.tif").resolve()
    assert sc.end_time_s == 60.0 and isinstance(sc.end_time_s, float)
    assert sc.terrain.manning == 0.035
    assert sc.terrain.edges is Edges.OPEN
    assert sc.numerics.cfl == 0.3
    assert sc.numerics.refinement is Refinement.SPLIT_COALESCE
    assert sc.numerics.particle_spacing_m is None
    assert sc.output.wet_threshold_m == 0.01
    assert sc.output.formats == (OutputFormat.GEOTIFF, OutputFormat.NETCDF)
    assert sc.output_directory == tmp_path.resolve() / "out" / "mini"
    assert sc.initial_water == () and sc.inflows == () and sc.gauges is None


def test_output_directory_relative_to_scenario(write_scenario, tmp_path):
    sc = load_scenario(write_scenario(MINIMAL + '\n[output]\ndirectory = "runs/a"\n'))
    assert sc.output_directory == tmp_path.resolve() / "runs" / "a"


def test_resolved_copy_reloads_to_the_same_scenario(scenario_file, tmp_path):
    sc = load_scenario(scenario_file)
    other = tmp_path / "elsewhere"
    other.mkdir()
    write_resolved(sc, other / "scenario.resolved.toml")
    again = load_scenario(other / "scenario.resolved.toml")
    assert again.to_dict() == sc.to_dict()
    assert again.initial_water[0].polygon[1] == (X0 + 400.0, Y0)


def test_resolved_copy_keeps_awkward_strings(write_scenario, tmp_path):
    # Quotes, backslashes, a tab and non-ASCII letters in a string survive the resolved copy.
    description = 'quote " back \\ tab \t é'
    text = BASE_SCENARIO.replace('name = "valley"',
                                 f'name = "valley"\ndescription = {json.dumps(description)}')
    assert text != BASE_SCENARIO
    sc = load_scenario(write_scenario(text))
    write_resolved(sc, tmp_path / "resolved.toml")
    again = load_scenario(tmp_path / "resolved.toml")
    assert again.scenario.description == description
    assert again.to_dict() == sc.to_dict()


def error_of(write_scenario, text) -> str:
    with pytest.raises(InputError) as err:
        load_scenario(write_scenario(text))
    return str(err.value)


POLY = "[[0, 0], [10, 0], [10, 10]]"


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("end_time_s = 20.0", 'end_time_s = "ten"'),
         "scenario.end_time_s: expected a number, got string 'ten'"),
        (("end_time_s = 20.0", "end_time_s = 0"), "scenario.end_time_s: must be > 0, got 0"),
        (("end_time_s = 20.0", "end_time_s = nan"),
         "scenario.end_time_s: expected a finite number, got nan"),
        (("cfl = 0.3", "cfl = 2"), "numerics.cfl: must be <= 1, got 2"),
        (("cfl = 0.3", "cfl = true"), "numerics.cfl: expected a number, got boolean True"),
        (("particle_spacing_m = 10.0", "particle_spacing_m = -1"),
         "numerics.particle_spacing_m: must be > 0, got -1"),
        (('refinement = "none"', 'refinement = "lots"'),
         "numerics.refinement: expected one of 'split+coalesce', 'split', 'none', "
         "got string 'lots'"),
        (('refinement = "none"', 'refinement = "split"\nrefine_area_min = 1.5'),
         "numerics.refine_area_min: must be below refine_area_max / 2 = 1 so that a merged "
         "pair is not split again at once; got 1.5"),
        (('refinement = "none"', "refine_max_level = -1"),
         "numerics.refine_max_level: must be >= 0, got -1"),
        (('time_stepping = "global"', 'time_stepping = "sideways"'),
         "numerics.time_stepping: expected one of 'global', 'local', got string 'sideways'"),
        (('refinement = "none"', "step_levels = 9"),
         "numerics.step_levels: must be <= 6, got 9"),
        (('edges = "closed"', 'edges = "closed"\nclosed_sides = ["west"]'),
         'terrain.closed_sides: only applies with edges = "open"'),
        (('edges = "closed"', 'edges = "open"\nclosed_sides = ["up"]'),
         "terrain.closed_sides: expected a list of sides from ['west', 'east', 'south', "
         "'north'], got array ['up']"),
        (('edges = "closed"', 'edges = "sometimes"'),
         "terrain.edges: expected one of 'open', 'closed', got string 'sometimes'"),
        (("resolution_m = 10.0", "wet_threshold_m = -0.1"),
         "output.wet_threshold_m: must be >= 0, got -0.1"),
        (("resolution_m = 10.0", 'formats = ["geotiff", "png"]'),
         "output.formats[1]: expected one of 'geotiff', 'netcdf', got string 'png'"),
        (("manning = 0.03", "manning = 0"), "terrain.manning: must be > 0, got 0"),
        (("manning = 0.03", 'manning = "n.tif"'), "terrain.manning: file not found: "),
        (('name = "valley"', 'name = "a/b"'), "scenario.name: must be a non-empty folder name"),
        (('name = "valley"\n', ""), "scenario.name: required key is missing"),
        (("cfl = 0.3", "cfll = 0.3"),
         "numerics.cfll: unknown key; allowed keys: cfl, density_tol, "),
        (("[scenario]", "bogus = 1\n[scenario]"),
         "bogus: unknown key; allowed keys: flux_lines, gauges, inflows, initial_water, "
         "level_boundaries, numerics, output, scenario, sinks, terrain, walls"),
        (("level_m = 100.0", "level_m = 100.0\ncolour = 1"),
         "initial_water[0].colour: unknown key; allowed keys: crs, depth, file, layer, level_m, "
         "polygon"),
    ],
)
def test_bad_values_name_the_key(write_scenario, change, message):
    text = BASE_SCENARIO.replace(*change)
    assert text != BASE_SCENARIO
    assert error_of(write_scenario, text).startswith(
        f"{write_scenario().parent / 'scenario.toml'}: "
    )
    assert message in error_of(write_scenario, text)


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ("[[walls]]\npolyline = [[0, 0]]\n",
         "walls[0].polyline: expected at least 2 [x, y] points, got 1"),
        ("[[walls]]\npolyline = [[0, 0], [1, \"x\"]]\n",
         "walls[0].polyline[1][1]: expected a finite number, got string 'x'"),
        ("[[sinks]]\npolygon = [[0, 0], [1, 1]]\n",
         "sinks[0].polygon: expected at least 3 [x, y] points, got 2"),
        ("[[sinks]]\npolygon = [[0, 0], [1, 1], [2, 2]]\n",
         "sinks[0].polygon: polygon encloses no area (its points are collinear)"),
        ("[[inflows]]\nline = [[0, 0]]\nhydrograph = \"q.csv\"\n",
         "inflows[0].line: expected two [x, y] points, got 1"),
        ("[[inflows]]\nline = [[0, 0], [0, 0]]\nhydrograph = \"q.csv\"\n",
         "inflows[0].line: the two end points are the same"),
        ("[[inflows]]\nline = [[0, 0], [1, 0]]\n",
         "inflows[0]: expected exactly one of hydrograph (a CSV file) or [breach]"),
        ("[[inflows]]\nline = [[0, 0], [1, 0]]\nhydrograph = \"q.csv\"\n",
         "inflows[0].hydrograph: file not found: "),
        ("[[inflows]]\nline = [[0, 0], [1, 0]]\nhydrograph = \"dem.tif\"\ndirection = [0, 0]\n",
         "inflows[0].direction: must not be the zero vector"),
        ("[gauges]\nfile = \"g.csv\"\n", "gauges.file: file not found: "),
        ("[[initial_water]]\nlevel_m = 3\n",
         "initial_water[1].polygon: required with level_m (the area to fill)"),
        (f"[[initial_water]]\nlevel_m = 3\npolygon = {POLY}\ndepth = \"d.tif\"\n",
         "initial_water[1].depth: give either depth or level_m + polygon, not both"),
        ("walls = 3\n", "walls: expected an array of tables [[walls]], got integer 3"),
    ],
)
def test_bad_geometry_names_the_key(write_scenario, extra, message):
    # Top-level keys must come before the first table; arrays of tables go at the end.
    text = extra + BASE_SCENARIO if not extra.startswith("[") else BASE_SCENARIO + extra
    assert message in error_of(write_scenario, text)


def test_invalid_toml_names_line_and_column(write_scenario):
    text = BASE_SCENARIO.replace("end_time_s = 20.0", "end_time_s = = 20.0")
    message = error_of(write_scenario, text)
    assert "scenario.toml: invalid TOML" in message
    assert "line 3, column" in message


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="nope.toml: scenario file not found"):
        load_scenario(tmp_path / "nope.toml")


def test_missing_required_tables(write_scenario):
    assert "scenario: required table [scenario] is missing" in error_of(
        write_scenario, "[terrain]\ndem = 'dem.tif'\n"
    )
    assert "terrain: required table [terrain] is missing" in error_of(
        write_scenario, "[scenario]\nname = 'a'\nend_time_s = 1\n"
    )


def test_a_bad_hydrograph_is_refused_with_the_inputs_naming_file_key_and_line(write_scenario,
                                                                              tmp_path):
    """The scenario checks that the CSV exists; the inputs read it, once, before any run
    folder is touched."""
    from floodsph.inputs.prepare import prepare_inputs

    (tmp_path / "q.csv").write_text("time_s,discharge_m3s\n0,0\n10,5\n5,1\n")
    text = BASE_SCENARIO + f"[[inflows]]\nline = [[{X0}, {Y0}], [{X0}, {Y0 + 50}]]\n" \
        'hydrograph = "q.csv"\n'
    scenario = load_scenario(write_scenario(text))
    with pytest.raises(InputError) as err:
        prepare_inputs(scenario)
    message = str(err.value)
    assert message.startswith(f"scenario.toml: inflows[0].hydrograph: {tmp_path / 'q.csv'}, "
                              "line 4: ")
    assert "times must increase strictly" in message


def test_hydrograph_dates_count_from_scenario_start_and_check_names_the_units(write_scenario,
                                                                               tmp_path):
    from floodsph.inputs.prepare import prepare_inputs, summary_lines

    # 20 m3/s from 06:10 to 06:20 local time (UTC+2): 04:10-04:20 UTC, from a 04:00 UTC start.
    (tmp_path / "q.csv").write_text("time,discharge_cfs\n2024-05-01T06:10+02:00,706.2933\n"
                                    "2024-05-01T06:20+02:00,706.2933\n")
    text = BASE_SCENARIO.replace("end_time_s = 20.0", "end_time_s = 1000.0\n"
                                 "start = 2024-05-01T04:00:00Z")
    text += f"[[inflows]]\nline = [[{X0 + 5}, {Y0 + 5}], [{X0 + 5}, {Y0 + 55}]]\n" \
        'hydrograph = "q.csv"\n'
    scenario = load_scenario(write_scenario(text))
    assert scenario.start.isoformat() == "2024-05-01T04:00:00+00:00"
    inputs = prepare_inputs(scenario)
    np.testing.assert_allclose(inputs.hydrographs[0].t, [600.0, 1200.0])
    assert inputs.volume_inflow_m3 == pytest.approx(20.0 * 400.0, rel=1e-6)  # 600 -> 1000 s
    lines = summary_lines(scenario, inputs, None)
    assert [line for line in lines if line.startswith("Converted:") and "q.csv" in line
            and "scenario.start (2024-05-01T04:00:00+00:00)" in line
            and "cubic feet per second" in line]
    # The same instant as a string, with its offset.
    again = text.replace("start = 2024-05-01T04:00:00Z", 'start = "2024-05-01T06:00:00+02:00"')
    assert again != text
    assert load_scenario(write_scenario(again)).start == scenario.start
    write_resolved(scenario, tmp_path / "resolved.toml")  # and back from the run folder's copy
    assert load_scenario(tmp_path / "resolved.toml").start == scenario.start


def test_a_start_that_is_no_instant_names_the_key(write_scenario):
    text = BASE_SCENARIO.replace("end_time_s = 20.0", 'end_time_s = 20.0\nstart = "May 1st"')
    assert error_of(write_scenario, text).endswith(
        "scenario.start: 'May 1st' is not an ISO 8601 date-time such as 2024-01-15T06:00:00Z")


def test_refinement_thresholds_reach_the_refiner(write_scenario):
    from floodsph.inputs.prepare import prepare_inputs
    from floodsph.model.from_scenario import build_model

    text = BASE_SCENARIO.replace(
        'refinement = "none"',
        'refinement = "split+coalesce"\nrefine_area_max = 3.0\nrefine_area_min = 0.5\n'
        "refine_d_min_m = 0.05\nrefine_max_level = 2")
    scenario = load_scenario(write_scenario(text))
    inputs = prepare_inputs(scenario)
    refiner = build_model(scenario, inputs).refiner
    spacing = inputs.spacing_m
    assert refiner.area_max == pytest.approx(3.0 * spacing**2)
    assert refiner.area_min == pytest.approx(0.5 * spacing**2)
    assert (refiner.numerics.refine_d_min_m, refiner.numerics.refine_max_level) == (0.05, 2)
    assert refiner.numerics.refinement is Refinement.SPLIT_COALESCE


def test_closed_sides_are_walls_and_the_other_sides_open(write_scenario):
    from floodsph.boundaries import OpenEdges
    from floodsph.inputs.prepare import prepare_inputs
    from floodsph.model.from_scenario import build_model

    text = BASE_SCENARIO.replace('edges = "closed"', 'edges = "open"\nclosed_sides = ["west"]')
    scenario = load_scenario(write_scenario(text))
    assert scenario.terrain.closed_sides == ("west",)
    model = build_model(scenario, prepare_inputs(scenario))
    (edges,) = [b for b in model.boundaries if isinstance(b, OpenEdges)]
    assert set(edges.sides) == {"east", "south", "north"}
    west = model.domain.seg[(model.domain.seg[:, 0] == 0.0) & (model.domain.seg[:, 2] == 0.0)]
    assert west.shape[0] == 1
    assert abs(west[0, 3] - west[0, 1]) >= model.terrain.height  # the whole side, and beyond


def test_worldcover_manning_table_from_toml(write_scenario, tmp_path):
    # Land cover on the DEM grid: the western half tree cover (ESA WorldCover class 10), the
    # eastern half cropland (40); the shipped table documents n for each class by name.
    import csv

    import numpy as np
    from conftest import NX, NY, write_geotiff

    from floodsph.inputs.prepare import prepare_inputs

    classes = np.where(np.arange(NX)[None, :] < NX // 2, 10, 40) * np.ones((NY, 1))
    write_geotiff(tmp_path / "landcover.tif", classes, nodata=0)
    text = BASE_SCENARIO.replace(
        "manning = 0.03", 'landcover = "landcover.tif"\nmanning_table = "worldcover"')
    sc = load_scenario(write_scenario(text))
    assert sc.terrain.manning_table == "worldcover" and sc.terrain.manning is None
    table_file = Path(__file__).parents[2] / "floodsph" / "data" / "worldcover_manning.csv"
    with open(table_file, encoding="utf-8") as f:
        documented = {row["name"]: float(row["manning_n"]) for row in csv.DictReader(f)}
    n = prepare_inputs(sc).terrain.manning
    assert np.all(n[:, : NX // 2] == documented["Tree cover"])
    assert np.all(n[:, NX // 2:] == documented["Cropland"])
    resolved = tmp_path / "resolved.toml"
    write_resolved(sc, resolved)
    assert load_scenario(resolved).terrain.manning_table == "worldcover"


@pytest.mark.parametrize("value", ["2024-01-15T07:00:00+01:00", '"2024-01-15T07:00:00+01:00"',
                                   '"2024-01-15T06:00:00Z"', "2024-01-15 06:00:00Z"])
def test_start_is_a_time_zone_aware_instant(write_scenario, tmp_path, value):
    """A TOML offset date-time or an ISO 8601 string; the same instant whatever its offset,
    kept through the resolved copy."""
    from datetime import UTC, datetime

    text = MINIMAL.replace("end_time_s = 60\n", f"end_time_s = 60\nstart = {value}\n")
    sc = load_scenario(write_scenario(text))
    assert sc.start == datetime(2024, 1, 15, 6, tzinfo=UTC) and sc.start.utcoffset() is not None
    write_resolved(sc, tmp_path / "scenario.resolved.toml")
    assert load_scenario(tmp_path / "scenario.resolved.toml").start == sc.start
    assert load_scenario(write_scenario(MINIMAL)).start is None


@pytest.mark.parametrize("value, message", [
    ("2024-01-15T06:00:00", "scenario.start: 2024-01-15T06:00:00 has no time zone; add Z"),
    ('"2024-01-15 06:00"', "scenario.start: 2024-01-15T06:00:00 has no time zone"),
    ('"15/01/2024 06:00"', "scenario.start: '15/01/2024 06:00' is not an ISO 8601 date-time"),
    ("2024-01-15", "scenario.start: expected a date-time with its time zone"),
    ("3600", "scenario.start: expected a date-time with its time zone"),
])
def test_a_start_without_time_zone_or_not_a_date_time_is_refused(write_scenario, value,
                                                                 message):
    text = MINIMAL.replace("end_time_s = 60\n", f"end_time_s = 60\nstart = {value}\n")
    with pytest.raises(InputError, match="scenario.toml: " + message.replace("(", r"\(")):
        load_scenario(write_scenario(text))
