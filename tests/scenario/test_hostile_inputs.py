"""Hostile but ordinary inputs: each is refused by ``check`` and ``run`` with one line naming the
file, key or value (exit 2, no traceback, no completed run); conversions and warnings of the
inputs floodsph accepts (a DEM in feet, CSV files with a BOM, high Manning values).

The scenarios are the conftest valley (40 x 20 cells of 10 m in EPSG:32632 at (X0, Y0), a 2 m
deep basin in its western 100 m) with one thing broken.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
import rasterio
from click.testing import CliRunner
from conftest import BASE_SCENARIO, CELL, NX, NY, X0, Y0, valley_elevation, write_geotiff
from rasterio.transform import from_origin

from floodsph.cli.main import cli

X1, Y1 = X0 + NX * CELL, Y0 + NY * CELL
POLYGON = re.compile(r"polygon = \[\[.*?\]\]\n", re.S)


def polygon_text(points) -> str:
    return "polygon = [" + ", ".join(f"[{x!r}, {y!r}]" for x, y in points) + "]\n"


def with_polygon(points, text=BASE_SCENARIO) -> str:
    """The base scenario with the reservoir polygon replaced."""
    return POLYGON.sub(lambda _: polygon_text(points), text, count=1)


def replaced(*pairs, text=BASE_SCENARIO) -> str:
    for old, new in pairs:
        assert old in text, old
        text = text.replace(old, new)
    return text


def without_water() -> str:
    return BASE_SCENARIO[:BASE_SCENARIO.index("[[initial_water]]")] + \
        BASE_SCENARIO[BASE_SCENARIO.index("[numerics]"):]


INFLOW = f"""
[[inflows]]
line = [[{X0 + 150.0}, {Y0 + 50.0}], [{X0 + 150.0}, {Y0 + 150.0}]]
hydrograph = "q.csv"
"""

BOWTIE = [(X0 + 100.0, Y0 + 50.0), (X0 + 300.0, Y0 + 150.0), (X0 + 300.0, Y0 + 50.0),
          (X0 + 100.0, Y0 + 150.0)]
LONLAT = [(9.0, 45.0), (9.1, 45.0), (9.1, 45.1)]
OFF_DEM = [(X0 + 10_000.0, Y0), (X0 + 10_400.0, Y0), (X0 + 10_400.0, Y0 + 200.0)]


def wall(points) -> str:
    return "\n[[walls]]\npolyline = [" + ", ".join(f"[{x!r}, {y!r}]" for x, y in points) + "]\n"


def sink(points) -> str:
    return "\n[[sinks]]\n" + polygon_text(points)


def write_hydrograph(folder: Path, rows, encoding="utf-8", extra_header="") -> None:
    text = "time_s,discharge_m3s" + extra_header + "\n" + "".join(f"{r}\n" for r in rows)
    (folder / "q.csv").write_bytes(text.encode(encoding))


def dem_with(value, folder: Path, *, nodata=None, dtype="float32") -> None:
    """The valley DEM with a 3 x 5 block of ``value`` (15 cells), tagged ``nodata``."""
    z = valley_elevation()
    z[3:6, 20:25] = value
    transform = from_origin(X0, Y1, CELL, CELL)
    with rasterio.open(folder / "dem.tif", "w", driver="GTiff", width=NX, height=NY, count=1,
                       dtype=dtype, crs="EPSG:32632", transform=transform,
                       nodata=nodata) as dst:
        dst.write(z.astype(dtype), 1)


def sparse_dem(folder: Path, size: int, name: str = "dem.tif") -> None:
    """A tiled GeoTIFF of size x size cells whose tiles are never written (a small file),
    centred east-west on X0, the UTM zone's central meridian (so that its scale factor stays
    within 0.5 % up to 1000 km wide and it is not reprojected)."""
    west = X0 - 0.5 * size * CELL
    with rasterio.open(folder / name, "w", driver="GTiff", width=size, height=size,
                       count=1, dtype="float32", crs="EPSG:32632",
                       transform=from_origin(west, Y0 + size * CELL, CELL, CELL), tiled=True,
                       blockxsize=512, blockysize=512, compress="deflate", sparse_ok=True,
                       nodata=-9999.0):
        pass


def asc_dem_without_nodata_line(folder: Path) -> None:
    z = valley_elevation()
    z[0, :4] = -9999.0
    rows = "\n".join(" ".join(f"{v:.2f}" for v in row) for row in z)
    (folder / "dem.asc").write_text(f"ncols {NX}\nnrows {NY}\nxllcorner {X0}\nyllcorner {Y0}\n"
                                    f"cellsize {CELL}\n{rows}\n")
    (folder / "dem.prj").write_text(rasterio.crs.CRS.from_epsg(32632).to_wkt())


GAUGES = '\n[gauges]\nfile = "gauges.csv"\n'


def landcover_scenario(folder: Path) -> str:
    """The base scenario with Manning n from a land-cover raster of class 10 and classes.csv."""
    write_geotiff(folder / "lc.tif", np.full((NY, NX), 10.0))
    return replaced(("manning = 0.03", 'landcover = "lc.tif"\nmanning_table = "classes.csv"'))


CASES = []


def case(*fragments):
    """Register ``build(folder) -> scenario text`` as a hostile case whose one-line error
    must contain every fragment; its id is the function's name."""

    def register(build):
        CASES.append(pytest.param(build, fragments, id=build.__name__.replace("_", "-")))
        return build

    return register


# -- DEM values (the undeclared fill values share one shape: see UNDECLARED_FILLS) ----------

UNDECLARED_FILLS = [
    pytest.param(-3.4028235e38, "float32", None,
                 ["15 cells hold -3.4028235e+38", "no nodata value", "gdal_edit.py -a_nodata"],
                 id="float32-lowest"),
    pytest.param(-1e38, "float32", None, ["15 cells hold -1e+38", "no nodata value"],
                 id="minus-1e38"),
    pytest.param(-32768, "int16", None, ["15 cells hold -32768", "no nodata value"],
                 id="int16-lowest"),
    pytest.param(-9999.0, "float32", None, ["15 cells hold -9999", "no nodata value"],
                 id="minus-9999"),
    pytest.param(12_000.0, "float32", None, ["15 cells hold 12000", "beyond 10000 m"],
                 id="12-km-high"),
    pytest.param(-3.4028235e38, "float32", -9999.0,
                 ["15 cells hold -3.4028235e+38", "declares nodata = -9999"],
                 id="beside-another-nodata-tag"),
]


@case("dem.asc", "4 cells hold -9999", "no nodata value")
def dem_asc_without_nodata_line(folder):
    asc_dem_without_nodata_line(folder)
    return replaced(('dem = "dem.tif"', 'dem = "dem.asc"'))


@case("dem.tif", "2 x 2 cells", "at least 3 x 3")
def dem_2x2(folder):
    write_geotiff(folder / "dem.tif", np.full((2, 2), 100.0))
    return BASE_SCENARIO


# -- polygons, walls, lines -------------------------------------------------------------------

@case("scenario.toml: initial_water[0].polygon: the polygon lies wholly outside the DEM extent")
def polygon_off_the_dem(folder):
    return with_polygon(OFF_DEM)


@case("initial_water[0].polygon", "look like longitude/latitude", "EPSG:32632")
def polygon_in_lonlat(folder):
    return with_polygon(LONLAT)


@case("initial_water[0].polygon: the polygon crosses itself near [500200, 4000100]")
def polygon_bow_tie(folder):
    return with_polygon(BOWTIE)


@case("initial_water[0].polygon: a polygon needs at least 3 distinct points, got 2")
def polygon_of_two_distinct_points(folder):
    return with_polygon([(X0, Y0), (X1, Y1), (X0, Y0), (X1, Y1)])


@case("sinks[0].polygon: the polygon lies wholly outside the DEM extent")
def sink_off_the_dem(folder):
    return BASE_SCENARIO + sink(OFF_DEM)


@case("sinks[0].polygon: the polygon crosses itself")
def sink_bow_tie(folder):
    return BASE_SCENARIO + sink(BOWTIE)


@case("walls[0].polyline: the wall has zero length")
def wall_of_zero_length(folder):
    return BASE_SCENARIO + wall([(X0 + 200.0, Y0 + 100.0)] * 3)


@case("walls[2].polyline: the wall crosses or runs back along itself near [500200, 4000100]")
def wall_crossing_itself(folder):
    return (BASE_SCENARIO + wall([(X0 + 10.0, Y0 + 10.0), (X0 + 20.0, Y0 + 10.0)])
            + wall([(X0 + 10.0, Y0 + 30.0), (X0 + 20.0, Y0 + 30.0)])
            + wall([(X0 + 150.0, Y0 + 50.0), (X0 + 250.0, Y0 + 150.0), (X0 + 250.0, Y0 + 50.0),
                    (X0 + 150.0, Y0 + 150.0)]))


@case("walls[0].polyline: the wall crosses or runs back along itself near [500150, "
      "4000010]")
def wall_doubling_back(folder):
    return BASE_SCENARIO + wall([(X0 + 100.0, Y0 + 10.0), (X0 + 200.0, Y0 + 10.0),
                                 (X0 + 150.0, Y0 + 10.0)])


@case("walls[0].polyline: closed wall (a footprint): a polygon needs at least 3 distinct")
def wall_footprint_without_area(folder):
    return BASE_SCENARIO + wall([(X0 + 100.0, Y0 + 10.0), (X0 + 200.0, Y0 + 10.0),
                                 (X0 + 100.0, Y0 + 10.0)])


@case("walls[0].polyline: the wall lies wholly outside the DEM extent")
def wall_off_the_dem(folder):
    return BASE_SCENARIO + wall(OFF_DEM[:2])


@case("inflows[0].line: the line is 0.001 m long, shorter than half the particle spacing (5 m)")
def inflow_line_of_1_mm(folder):
    write_hydrograph(folder, ["0,0", "10,5"])
    return BASE_SCENARIO + INFLOW.replace(f"{Y0 + 150.0}]]", f"{Y0 + 50.001}]]")


@case("inflows[0].line: point [9, 45] is outside the DEM extent", "longitude/latitude")
def inflow_line_in_lonlat(folder):
    write_hydrograph(folder, ["0,0", "10,5"])
    return (BASE_SCENARIO + "\n[[inflows]]\nline = [[9.0, 45.0], [9.0, 45.001]]\n"
            'hydrograph = "q.csv"\n')


@case("gauges.csv: gauge file needs the columns id, x, y; found one column 'id;x;y': the "
      "file is separated by semicolons; save it comma-separated")
def gauges_separated_by_semicolons(folder):
    (folder / "gauges.csv").write_text(f"id;x;y\nG1;{X0 + 50.0};{Y0 + 50.0}\n")
    return BASE_SCENARIO + GAUGES


@case("gauges.csv: gauge file needs the columns id, x, y; found the columns 'name', 'x', 'y'")
def gauges_without_an_id_column(folder):
    (folder / "gauges.csv").write_text(f"name,x,y\nG1,{X0 + 50.0},{Y0 + 50.0}\n")
    return BASE_SCENARIO + GAUGES


@case("gauges.csv, line 2: gauge 'G1'", "longitude/latitude")
def gauge_in_lonlat(folder):
    (folder / "gauges.csv").write_text("id,x,y\nG1,9.01,45.02\n")
    return BASE_SCENARIO + GAUGES


# -- no water ---------------------------------------------------------------------------------

@case("scenario.toml: initial_water[0].level_m: 90 m is below the bed everywhere inside the "
      "polygon (lowest bed there 98 m)", "no inflow")
def level_below_the_bed(folder):
    return replaced(("level_m = 100.0", "level_m = 90.0"))


@case("scenario.toml: the scenario holds no water")
def no_water_at_all(folder):
    return without_water()


@case("scenario.toml: inflows: the hydrographs bring no water before end_time_s = 20 s")
def inflow_after_the_end_time(folder):
    write_hydrograph(folder, ["100,0", "200,50"])
    return without_water() + INFLOW


@case("scenario.toml: inflows: the hydrographs bring no water before end_time_s = 20 s")
def hydrograph_of_zeros(folder):
    write_hydrograph(folder, ["0,0", "10,0", "100,0"])
    return without_water() + INFLOW


# -- the side an inflow enters on ---------------------------------------------------------------

@case("scenario.toml: inflows[0].direction: [0.0, 1.0] is parallel to the line")
def inflow_direction_along_its_line(folder):
    write_hydrograph(folder, ["0,10", "100,10"])
    return BASE_SCENARIO + INFLOW + "direction = [0.0, 1.0]\n"


@case("scenario.toml: inflows[0].direction: [1.0, 0.0] points off the DEM", "reverse it")
def inflow_direction_off_the_dem(folder):
    write_hydrograph(folder, ["0,10", "100,10"])
    east_edge = INFLOW.replace(f"{X0 + 150.0}", f"{X1 - 5.0}")
    return BASE_SCENARIO + east_edge + "direction = [1.0, 0.0]\n"


@case("initial_water[0].polygon: the polygon contains no DEM cell centre")
def polygon_without_a_cell_centre(folder):
    return with_polygon([(X0 + 1.0, Y0 + 1.0), (X0 + 3.0, Y0 + 1.0), (X0 + 1.0, Y0 + 3.0)])


@case("numerics.particle_spacing_m: the initial water seeds no particles at a spacing of 1000 m")
def spacing_wider_than_the_dem(folder):
    return replaced(("particle_spacing_m = 10.0", "particle_spacing_m = 1000.0"))


# -- Manning ----------------------------------------------------------------------------------

@case("terrain.manning: n = 30", "Strickler", "n = 1/K_st (K_st = 30 gives n = 0.0333)")
def manning_number_in_strickler(folder):
    return replaced(("manning = 0.03", "manning = 30"))


@case("manning raster", "n.tif: 800 DEM cells have n >= 1", "Strickler")
def manning_raster_in_strickler(folder):
    write_geotiff(folder / "n.tif", np.full((NY, NX), 35.0))
    return replaced(("manning = 0.03", 'manning = "n.tif"'))


@case("manning table", "classes.csv, line 2: n = 25", "Strickler")
def manning_table_in_strickler(folder):
    (folder / "classes.csv").write_text("class,manning_n\n10,25\n")
    return landcover_scenario(folder)


# -- impossible numbers (in the TOML: one shape, see IMPOSSIBLE_NUMBERS) ---------------------

@case("initial_water[0].polygon[1][0]: 1e+308 is beyond +-1e+12")
def coordinate_of_1e308(folder):
    return with_polygon([(X0, Y0), (1e308, Y0), (X1, Y1)])


@case("inflows[0].hydrograph", "q.csv, line 3: discharge_m3s = 1e308 is beyond +-1e+12")
def discharge_of_1e308(folder):
    write_hydrograph(folder, ["0,0", "10,1e308"])
    return BASE_SCENARIO + INFLOW


@case("inflows[0].hydrograph", "line 3: discharge_m3s = 5e+07 is above 1e+07 m3/s")
def discharge_above_the_physical_bound(folder):
    write_hydrograph(folder, ["0,0", "10,5e7"])
    return BASE_SCENARIO + INFLOW


@case("inflows[0].hydrograph", "line 3: time_s = inf is not finite")
def hydrograph_time_of_inf(folder):
    write_hydrograph(folder, ["0,0", "inf,5"])
    return BASE_SCENARIO + INFLOW


@case("inflows[0].breach.reservoir_volume_m3: 1e+308 is beyond +-1e+12")
def breach_volume_of_1e308(folder):
    return BASE_SCENARIO + INFLOW.replace(
        'hydrograph = "q.csv"',
        "[inflows.breach]\nbreach_height_m = 10.0\nreservoir_volume_m3 = 1e308")


IMPOSSIBLE_NUMBERS = [
    pytest.param(("end_time_s = 20.0", "end_time_s = 1e308"),
                 "scenario.end_time_s: 1e+308 is beyond +-1e+12", id="end-time-1e308"),
    pytest.param(("level_m = 100.0", "level_m = inf"),
                 "initial_water[0].level_m: expected a finite number, got inf", id="level-inf"),
    pytest.param(("level_m = 100.0", "level_m = 1e6"),
                 "initial_water[0].level_m: 1e+06 m is beyond +-10000 m", id="level-1e6"),
    pytest.param(("particle_spacing_m = 10.0", "particle_spacing_m = nan"),
                 "numerics.particle_spacing_m: expected a finite number, got nan",
                 id="spacing-nan"),
    pytest.param(("cfl = 0.3", "cfl = -inf"), "numerics.cfl: expected a finite number, got -inf",
                 id="cfl-minus-inf"),
    pytest.param(("cfl = 0.3", "cfl = 0.3\nthreads = 9223372036854775807"),
                 "numerics.threads: 9.22337e+18 is beyond +-1e+12", id="threads-2-to-the-63"),
    pytest.param(("manning = 0.03", "manning = 1e308"),
                 "terrain.manning: 1e+308 is beyond +-1e+12", id="manning-1e308"),
]


# -- too large for memory: refused before anything is allocated ------------------------------

@case("scenario.toml: the run needs an estimated", "particle_spacing_m",
      "at peak (seeding lattice 814.9 TB (while seeding: the peak), program and libraries ",
      " MB, map grids 75.0 kB, terrain grids 50.0 kB) but only")
def spacing_too_fine_for_memory(folder):
    return replaced(("particle_spacing_m = 10.0", "particle_spacing_m = 1e-4"))


@case("scenario.toml: the run needs an estimated", "seeding lattice")
def spacing_of_1e_minus_300(folder):
    return replaced(("particle_spacing_m = 10.0", "particle_spacing_m = 1e-300"))


@case("scenario.toml: the run needs an estimated", "map grids", "output.resolution_m")
def map_resolution_too_fine_for_memory(folder):
    return replaced(("resolution_m = 10.0", "resolution_m = 1e-5"))


@case("scenario.toml: the run needs an estimated", "terrain grids 596.0 GB")
def dem_too_large_to_read(folder):
    sparse_dem(folder, 100_000)
    return BASE_SCENARIO


@case("scenario.toml: the run needs an estimated", "terrain grids 74.5 GB")
def landcover_raster_too_large_to_read(folder):
    sparse_dem(folder, 100_000, name="lc.tif")  # 1e10 cells of 8 B once read
    (folder / "classes.csv").write_text("class,manning_n\n10,0.03\n")
    return replaced(("manning = 0.03", 'landcover = "lc.tif"\nmanning_table = "classes.csv"'))


# -- the scenario name and paths --------------------------------------------------------------

SCENARIO_NAMES = [
    pytest.param('""', "scenario.name: must be a non-empty folder name", id="empty"),
    pytest.param('"val\\u0000ley"', "scenario.name: contains a NUL character", id="nul"),
    pytest.param('"val\\nley"', "scenario.name: must be a non-empty folder name without / \\ : "
                 "or control characters", id="newline"),
    pytest.param(f'"{"v" * 300}"', "scenario.name: is 300 bytes long in UTF-8, but it names "
                 "the default output folder and a folder name holds at most 255",
                 id="300-bytes"),
    pytest.param(f'"{"é" * 200}"', "scenario.name: is 400 bytes long in UTF-8",
                 id="200-letters-of-2-bytes"),
]


@case("output.directory: contains a NUL character")
def output_directory_with_nul(folder):
    return replaced(("[output]", '[output]\ndirectory = "runs\\u0000a"'))


# -- CSV files in a legacy encoding ------------------------------------------------------------

@case("gauge file", "gauges.csv, line 2: not UTF-8 text (byte 0xe9", "save the file as UTF-8")
def gauges_in_cp1252(folder):
    (folder / "gauges.csv").write_bytes(f"id,x,y\nécluse,{X0 + 50},{Y0 + 50}\n".encode("cp1252"))
    return BASE_SCENARIO + GAUGES


@case("manning table", "classes.csv, line 2: not UTF-8 text")
def manning_table_in_cp1252(folder):
    (folder / "classes.csv").write_bytes("class,name,manning_n\n10,forêt,0.1\n".encode("cp1252"))
    return landcover_scenario(folder)


@case("inflows[0].hydrograph", "q.csv, line 2: not UTF-8 text")
def hydrograph_in_cp1252(folder):
    write_hydrograph(folder, ["0,0,début", "10,5,crête"], encoding="cp1252",
                     extra_header=",remarque")
    return BASE_SCENARIO + INFLOW


@case("inflows[0].hydrograph", "q.csv, line 1: not UTF-8 text (byte 0xff, a UTF-16 file)")
def hydrograph_in_utf16(folder):
    write_hydrograph(folder, ["0,0", "10,5"], encoding="utf-16")
    return BASE_SCENARIO + INFLOW


def invoke(*args, env=None):
    return CliRunner().invoke(cli, [str(a) for a in args], env=env)


def completed_runs(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("run.json")
            if json.loads(p.read_text()).get("status") == "completed"]


def assert_refused(folder: Path, command: str, text: str, fragments) -> None:
    """``command`` on the scenario ``text`` exits 2 with one ``Error:`` line holding every
    fragment, no traceback, and leaves no completed run."""
    scenario = folder / "scenario.toml"
    scenario.write_text(text, encoding="utf-8")
    extra = ["--max-steps", "1"] if command == "run" else []
    env = {"FLOODSPH_MEMORY_LIMIT_BYTES": str(8 * 2**30)}  # 8 GB, whatever the machine has
    result = invoke(command, scenario, *extra, env=env)
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2, result.output
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.stderr
    assert "Traceback" not in result.output
    for fragment in fragments:
        assert fragment in lines[0]
    assert completed_runs(folder) == []


COMMANDS = pytest.mark.parametrize("command", ["check", "run"])


@COMMANDS
@pytest.mark.parametrize(("build", "fragments"), CASES)
def test_hostile_input_is_refused_in_one_line(valley_dem, tmp_path, command, build, fragments):
    assert_refused(tmp_path, command, build(tmp_path), fragments)


@COMMANDS
@pytest.mark.parametrize(("value", "dtype", "nodata", "fragments"), UNDECLARED_FILLS)
def test_undeclared_dem_fill_is_refused(valley_dem, tmp_path, command, value, dtype, nodata,
                                        fragments):
    dem_with(value, tmp_path, dtype=dtype, nodata=nodata)
    assert_refused(tmp_path, command, BASE_SCENARIO, [f"DEM {tmp_path / 'dem.tif'}: ",
                                                      *fragments])


@COMMANDS
@pytest.mark.parametrize(("change", "fragment"), IMPOSSIBLE_NUMBERS)
def test_impossible_number_is_refused(valley_dem, tmp_path, command, change, fragment):
    assert_refused(tmp_path, command, replaced(change), [fragment])


@COMMANDS
@pytest.mark.parametrize(("name", "fragment"), SCENARIO_NAMES)
def test_unusable_scenario_name_is_refused(valley_dem, tmp_path, command, name, fragment):
    assert_refused(tmp_path, command, replaced(('name = "valley"', f"name = {name}")),
                   [fragment])


# ---- inputs accepted, converted or warned of -------------------------------------------------


def prepared(scenario_path: Path):
    from floodsph.inputs.prepare import prepare_inputs
    from floodsph.scenario.reader import load_scenario

    return prepare_inputs(load_scenario(scenario_path))


def write_dem_in_units(path: Path, z, crs: str, units: str | None) -> None:
    with rasterio.open(path, "w", driver="GTiff", width=NX, height=NY, count=1,
                       dtype="float32", crs=crs, transform=from_origin(X0, Y1, CELL, CELL),
                       nodata=-9999.0) as dst:
        dst.write(np.asarray(z, dtype=np.float32), 1)
        if units is not None:
            dst.units = (units,)


US_FOOT = 1200.0 / 3937.0


@pytest.mark.parametrize(("crs", "units", "factor", "unit_name"), [
    pytest.param("EPSG:32632+8228", None, 0.3048, "foot", id="compound-crs-foot"),
    pytest.param("EPSG:32632+6360", None, US_FOOT, "US survey foot", id="compound-crs-us-foot"),
    pytest.param("EPSG:32632", "ft", 0.3048, "ft", id="band-unit-ft"),
    pytest.param("EPSG:32632", "US survey foot", US_FOOT, "US survey foot", id="band-unit-us-ft"),
])
def test_dem_in_feet_is_converted_to_metres(valley_dem, scenario_file, crs, units, factor,
                                            unit_name):
    z_ft = valley_elevation() / 0.3  # 333.3 ft floor, 326.7 ft basin: 100 m and 98 m / 1.016
    write_dem_in_units(valley_dem, z_ft, crs, units)
    inputs = prepared(scenario_file)
    stored = z_ft.astype(np.float32).astype(np.float64)
    np.testing.assert_allclose(inputs.terrain.elevation, stored[::-1] * factor, rtol=1e-15)
    assert rasterio.crs.CRS.from_wkt(inputs.terrain.crs_wkt).to_epsg() == 32632
    assert inputs.warnings == [f"DEM {valley_dem}: elevations are in {unit_name} "
                               f"({factor:.10g} m each); converted to metres"]

    result = invoke("check", scenario_file)
    assert result.exit_code == 0, result.output
    assert f"WARNING: DEM {valley_dem}: elevations are in {unit_name}" in result.stderr
    assert "Warnings:        1" in result.stdout


def test_dem_with_a_vertical_crs_in_metres_is_read_as_is(valley_dem, scenario_file):
    write_dem_in_units(valley_dem, valley_elevation(), "EPSG:32632+5773", None)  # EGM96 height
    inputs = prepared(scenario_file)
    np.testing.assert_array_equal(inputs.terrain.elevation, valley_elevation()[::-1])
    assert inputs.warnings == []


def test_bom_gauge_file_reads_the_same_points(valley_dem, tmp_path):
    from floodsph.inputs.dem import load_terrain
    from floodsph.output.gauges import read_gauge_file

    terrain = load_terrain(valley_dem)
    text = f"id,x,y\nécluse,{X0 + 50},{Y0 + 50}\nG2,{X0 + 250.5},{Y0 + 120}\n"
    (tmp_path / "plain.csv").write_text(text, encoding="utf-8")
    (tmp_path / "excel.csv").write_text(text, encoding="utf-8-sig")  # "CSV UTF-8": with a BOM
    assert (tmp_path / "excel.csv").read_bytes()[:3] == b"\xef\xbb\xbf"
    plain = read_gauge_file(tmp_path / "plain.csv", terrain)
    excel = read_gauge_file(tmp_path / "excel.csv", terrain)
    assert excel.ids == plain.ids == ("écluse", "G2")
    np.testing.assert_array_equal(excel.x, [50.0, 250.5])
    np.testing.assert_array_equal(excel.y, plain.y)


def test_bom_manning_table_and_hydrograph_read_the_same_values(tmp_path):
    from floodsph.io.hydrograph import read_hydrograph
    from floodsph.io.manning import read_manning_table

    table = "class,name,manning_n\n10,forêt,0.12\n30,prairie,0.035\n"
    (tmp_path / "excel.csv").write_text(table, encoding="utf-8-sig")
    assert read_manning_table(tmp_path / "excel.csv") == {10: 0.12, 30: 0.035}
    (tmp_path / "q.csv").write_text("time_s,discharge_m3s\n0,0\n60,250.5\n", encoding="utf-8-sig")
    hydrograph = read_hydrograph(tmp_path / "q.csv")
    np.testing.assert_array_equal(hydrograph.t, [0.0, 60.0])
    np.testing.assert_array_equal(hydrograph.Q, [0.0, 250.5])


@pytest.mark.parametrize(("form", "message"), [
    pytest.param("number", "terrain.manning: n = 0.5 is above 0.2", id="number"),
    pytest.param("raster", "manning raster {folder}/n.tif: 800 DEM cells have n > 0.2; the "
                 "largest, n = 0.5 is above 0.2", id="raster"),
    pytest.param("table", "landcover {folder}/lc.tif with manning table {folder}/classes.csv: "
                 "800 DEM cells have n > 0.2", id="land-cover-table"),
])
def test_high_manning_is_accepted_with_a_warning(valley_dem, tmp_path, form, message):
    text = replaced(("manning = 0.03", "manning = 0.5"))
    if form == "raster":
        write_geotiff(tmp_path / "n.tif", np.full((NY, NX), 0.5))
        text = replaced(("manning = 0.03", 'manning = "n.tif"'))
    elif form == "table":
        (tmp_path / "classes.csv").write_text("class,manning_n\n10,0.5\n")
        text = landcover_scenario(tmp_path)
    scenario = tmp_path / "scenario.toml"
    scenario.write_text(text)
    expected = message.format(folder=tmp_path)
    inputs = prepared(scenario)
    assert len(inputs.warnings) == 1 and inputs.warnings[0].startswith(expected)
    assert np.all(inputs.terrain.manning == 0.5)
    result = invoke("check", scenario)
    assert result.exit_code == 0 and f"WARNING: {expected}" in result.stderr


def test_dry_body_beside_other_water_is_warned_and_the_run_keeps_the_water(write_scenario):
    dry = f"""
[[initial_water]]
level_m = 90.0
polygon = [[{X0 + 200.0}, {Y0}], [{X1}, {Y0}], [{X1}, {Y1}]]
"""
    text = BASE_SCENARIO.replace("[numerics]", dry + "\n[numerics]")
    scenario = write_scenario(text)
    inputs = prepared(scenario)
    assert inputs.particles.n == 10 * NY  # the basin's seeds, as without the dry body
    assert inputs.warnings == [
        "scenario.toml: initial_water[1].level_m: 90 m is below the bed everywhere inside the "
        "polygon (lowest bed there 100 m), so this body holds no water (the run goes on with the "
        "other water)"]
    result = invoke("check", scenario)
    assert result.exit_code == 0 and "WARNING: scenario.toml: initial_water[1]" in result.stderr


@pytest.mark.parametrize(("direction", "warned"), [("[-1.0, 0.0]", True),
                                                   ("[1.0, 0.0]", False)])
def test_an_inflow_pointing_into_the_reservoir_is_warned(write_scenario, direction, warned):
    # The line runs along the reservoir basin's eastern shore (x = 100 m): west is the
    # reservoir (2 m of water), east the dry floor.
    write_hydrograph(write_scenario().parent, ["0,10", "100,10"])
    shore = INFLOW.replace(f"{X0 + 150.0}", f"{X0 + 100.0}")
    scenario = write_scenario(BASE_SCENARIO + shore + f"direction = {direction}\n")
    result = invoke("check", scenario)
    assert result.exit_code == 0, result.output
    expected = (f"WARNING: scenario.toml: inflows[0].direction: {direction} points into the "
                "initial water")
    assert (expected in result.stderr) == warned
    assert prepared(scenario).warnings == ([expected.removeprefix("WARNING: ") + " (a reservoir?)"
                                            " while the other side of the line is dry: the "
                                            "inflow adds to that water instead of flowing away "
                                            "from it"] if warned else [])


def test_memory_is_estimated_from_the_dem_header_before_reading(valley_dem, scenario_file):
    """A 100 000 x 100 000 cell DEM file (sparse, a few MB): the estimate of its grids, the
    seeding lattice and the map grids follows the documented formula from the header alone."""
    from floodsph.inputs.memory import BASE_BYTES, COMPILE_BYTES
    from floodsph.inputs.prepare import estimate_before_reading
    from floodsph.scenario.reader import load_scenario

    sparse_dem(valley_dem.parent, 100_000)
    assert valley_dem.stat().st_size < 50e6
    estimate = estimate_before_reading(load_scenario(scenario_file), volume_inflow_m3=0.0)
    cells = 100_000**2  # spacing = resolution = cell = 10 m: one lattice and one map cell each
    assert estimate.dem_bytes == cells * 8 * 8
    assert estimate.seeding_bytes == cells * 14 * 8
    assert estimate.output_bytes == cells * 12 * 8
    assert estimate.base_bytes in (BASE_BYTES, BASE_BYTES + COMPILE_BYTES)
    assert estimate.total == estimate.base_bytes + cells * 8 * 8 + max(cells * 14 * 8,
                                                              estimate.particle_bytes
                                                              + cells * 12 * 8)


def test_crossings_are_refused_and_touching_outlines_pass():
    from floodsph.checks.shapes import polygon_problem, polyline_problem, self_crossing

    bowtie = np.array([(0.0, 0.0), (10.0, 10.0), (10.0, 0.0), (0.0, 10.0)])
    assert self_crossing(bowtie, closed=True) == (5.0, 5.0)
    assert "crosses itself near [5, 5]" in polygon_problem(bowtie)
    # An L-shaped reservoir with a repeated vertex, given closed, and a closed footprint.
    ell = [(0, 0), (20, 0), (20, 5), (20, 5), (5, 5), (5, 20), (0, 20), (0, 0)]
    assert polygon_problem(ell) is None
    assert polyline_problem([(0, 0), (4, 0), (4, 4), (0, 4), (0, 0)]) is None
    # A square with a square hole as one keyhole ring (the bridge edge run twice): allowed,
    # and filled by the even-odd rule with the hole outside.
    keyhole = [(0, 0), (10, 0), (10, 10), (0, 10), (0, 0), (3, 3), (3, 7), (7, 7), (7, 3),
               (3, 3)]
    assert polygon_problem(keyhole) is None
    assert "encloses no area" in polygon_problem([(0, 0), (10, 0), (10, 10), (10, 0)])
    # A "6": the wall's end lands on its own first segment (touching, allowed); a figure-8
    # wall crosses itself; a wall running back along itself overlaps.
    assert polyline_problem([(0, 0), (10, 0), (10, 5), (5, 5), (5, 0)]) is None
    assert "near [5, 5]" in polyline_problem([(0, 0), (10, 10), (10, 0), (0, 10)])
    assert "runs back along itself" in polyline_problem([(0, 0), (10, 0), (4, 0)])


def test_reservoir_with_a_hole_as_one_keyhole_ring_is_accepted(write_scenario):
    """The outline runs round the DEM, in along a bridge edge, round a 60 m x 100 m island in
    the basin and back: no crossing, so it is accepted, and the island stays dry."""
    island = [(X0 + 20.0, Y0 + 50.0), (X0 + 20.0, Y0 + 150.0), (X0 + 80.0, Y0 + 150.0),
              (X0 + 80.0, Y0 + 50.0), (X0 + 20.0, Y0 + 50.0)]
    ring = [(X0, Y0), (X1, Y0), (X1, Y1), (X0, Y1), (X0, Y0), *island]
    scenario = write_scenario(with_polygon(ring))
    result = invoke("check", scenario)
    assert result.exit_code == 0, result.output
    island_cells = 6 * 10
    assert f"Particles:       {10 * NY - island_cells}\n" in result.output
