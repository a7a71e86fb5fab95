"""Workflows ``benchmarks/ea_test4`` (EA benchmark Test 4) and ``benchmarks/versus_grid_code.py``.

Without ANUGA or the benchmark data the parts that need them skip; the conversion of ANUGA's
triangle values to the DEM grid is tested on a synthetic cross mesh: ``rectangular_cross``
splits each cell (centre (xc, yc), size dx x dy) into four triangles, each made of one cell
side and the centre, whose centroids are (xc -+ dx/3, yc) and (xc, yc -+ dy/3).

EA Test 4 hydrograph (Néelz & Pender 2013; the benchmark's SOURCE.md): 0 -> 20 m3/s from 300 s
to 3600 s, 20 m3/s to 14400 s, -> 0 at 18000 s, so the volume is
20 (3600 - 300)/2 + 20 (14400 - 3600) + 20 (18000 - 14400)/2 = 285 000 m3, and up to
t in [300, 3600] s it is 20/3300 (t - 300)^2 / 2.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import BASE_SCENARIO, X0, Y0, load_script, write_geotiff

pytestmark = pytest.mark.benchmark

REPO = Path(__file__).resolve().parents[2]


vgc = load_script("versus_grid_code", REPO / "benchmarks" / "versus_grid_code.py")
ea4 = load_script("run_ea_test4", REPO / "benchmarks" / "ea_test4" / "run_ea_test4.py")

needs_anuga = pytest.mark.skipif(not vgc.anuga_available(), reason="ANUGA is not installed")
EA4_DATA = ea4.data_folder()
needs_ea4 = pytest.mark.skipif(EA4_DATA is None, reason="EA test 4 benchmark data not found")

EA4_VOLUME_M3 = 20 * (3600 - 300) / 2 + 20 * (14400 - 3600) + 20 * (18000 - 14400) / 2


def _ramp_volume(t: float) -> float:
    """EA Test 4 inflow volume [m3] up to t in [300, 3600] s."""
    return 20.0 / 3300.0 * (t - 300.0) ** 2 / 2.0


def cross_mesh_centroids(nx: int, ny: int, dx: float, dy: float):
    """Centroids of the 4 triangles of every cell, and the flat index of their cell."""
    i, j = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    xc, yc = (j.ravel() + 0.5) * dx, (i.ravel() + 0.5) * dy
    offsets = [(-dx / 3, 0.0), (dx / 3, 0.0), (0.0, -dy / 3), (0.0, dy / 3)]
    x = np.concatenate([xc + ox for ox, _ in offsets])
    y = np.concatenate([yc + oy for _, oy in offsets])
    cell = np.tile(i.ravel() * nx + j.ravel(), 4)
    return x, y, cell


# -- versus_grid_code: grid <-> triangles, no ANUGA --------------------------------------------
def test_cross_mesh_centroids_fall_in_their_own_cell():
    x, y, cell = cross_mesh_centroids(5, 3, 10.0, 4.0)
    assert np.array_equal(vgc.cell_index(x, y, 10.0, 4.0, (3, 5)), cell)


def test_grid_to_triangles_and_back_is_the_identity():
    rng = np.random.default_rng(1)
    grid = rng.normal(size=(3, 5))
    x, y, _ = cross_mesh_centroids(5, 3, 10.0, 4.0)
    cells = vgc.cell_index(x, y, 10.0, 4.0, grid.shape)
    back = vgc.centroids_to_grid(vgc.grid_to_centroids(grid, cells), cells, grid.shape)
    assert np.array_equal(back, grid)


def test_a_cell_takes_the_mean_of_its_four_triangles():
    x, y, _ = cross_mesh_centroids(2, 2, 5.0, 5.0)
    cells = vgc.cell_index(x, y, 5.0, 5.0, (2, 2))
    values = np.zeros(x.size)
    in_cell_3 = np.flatnonzero(cells == 3)  # row 1 (north), column 1 (east)
    values[in_cell_3] = [1.0, 2.0, 3.0, 6.0]
    grid = vgc.centroids_to_grid(values, cells, (2, 2))
    assert grid[1, 1] == pytest.approx(3.0)
    assert np.all(grid.ravel()[:3] == 0.0)


def test_cells_without_triangles_are_nan_and_points_off_the_grid_are_ignored():
    x = np.array([2.5, -1.0, 12.5, 7.5])
    y = np.array([2.5, 2.5, 2.5, 30.0])
    cells = vgc.cell_index(x, y, 5.0, 5.0, (2, 2))
    assert cells.tolist() == [0, -1, -1, -1]
    grid = vgc.centroids_to_grid(np.array([4.0, 100.0, 100.0, 100.0]), cells, (2, 2))
    assert grid[0, 0] == 4.0
    assert np.isnan(grid.ravel()[1:]).all()
    with pytest.raises(ValueError, match="outside the grid"):
        vgc.grid_to_centroids(np.zeros((2, 2)), cells)


def test_anuga_map_is_written_on_the_dem_grid_north_up(tmp_path):
    import rasterio
    from rasterio.crs import CRS

    from floodsph.model.terrain import Terrain

    crs = CRS.from_epsg(32632)
    terrain = Terrain(elevation=np.zeros((3, 4)), dx=10.0, dy=5.0, x0=500000.0, y0=4000000.0,
                      crs_wkt=crs.to_wkt())
    grid = np.arange(12.0).reshape(3, 4)  # row 0 = south
    path = vgc.write_grid_geotiff(tmp_path / "a.tif", grid, terrain, "ANUGA maximum depth")
    with rasterio.open(path) as src:
        assert src.crs == crs
        assert src.transform == rasterio.transform.from_origin(500000.0, 4000015.0, 10.0, 5.0)
        data = src.read(1)
        # The south-west cell (grid[0, 0] = 0) is the last row of the north-up file.
        assert data[-1, 0] == 0.0 and data[0, 0] == grid[2, 0]
        assert list(src.sample([(500035.0, 4000012.5)]))[0][0] == grid[2, 3]


def test_an_inflow_line_on_the_border_is_moved_a_quarter_cell_inside():
    line = np.array([[0.0, 990.0], [0.0, 1010.0]])
    assert vgc.inlet_line(line, 5.0, 5.0, 1000.0, 2000.0) == [[1.25, 990.0], [1.25, 1010.0]]
    inside = np.array([[300.0, 10.0], [320.0, 10.0]])
    assert vgc.inlet_line(inside, 5.0, 5.0, 1000.0, 2000.0) == inside.tolist()


def test_without_anuga_the_comparison_is_skipped_with_a_message(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(vgc, "anuga_available", lambda: False)
    assert vgc.main(["--out", str(tmp_path / "out")]) == 0
    assert "ANUGA is not installed" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_walls_along_a_whole_side_around_an_inflow_make_it_reflective():
    walls = [np.array([[0.0, 0.0], [0.0, 990.0]]), np.array([[0.0, 1010.0], [0.0, 2000.0]])]
    inlet = [np.array([[0.0, 990.0], [0.0, 1010.0]])]
    assert vgc.walled_sides(walls, inlet, 1000.0, 2000.0, 1e-6) == {"left"}
    box = [np.array([[0.0, 0.0], [1000.0, 0.0], [1000.0, 2000.0], [0.0, 2000.0], [0.0, 0.0]])]
    assert vgc.walled_sides(box, [], 1000.0, 2000.0, 1e-6) == {"left", "right", "bottom", "top"}
    with pytest.raises(ValueError, match="only part of the left side"):
        vgc.walled_sides(walls, [], 1000.0, 2000.0, 1e-6)


def test_walls_off_the_border_are_refused_naming_the_table(write_scenario):
    from floodsph.inputs.prepare import prepare_inputs
    from floodsph.scenario.reader import load_scenario

    text = BASE_SCENARIO + f"\n[[walls]]\npolyline = [[{X0 + 50}, {Y0}], [{X0 + 50}, {Y0 + 90}]]\n"
    scenario = load_scenario(write_scenario(text))
    with pytest.raises(SystemExit, match=r"\[\[walls\]\]: wall segment \[50\.0, 0\.0\] - "
                       r"\[50\.0, 90\.0\] \(local m\) is not on the DEM border"):
        vgc.translate_walls(scenario, prepare_inputs(scenario).terrain)


# -- versus_grid_code with ANUGA: a small dam break ------------------------------------------
DAM_BREAK = """\
[scenario]
name = "tiny-dam-break"
end_time_s = 10.0

[terrain]
dem = "dem.tif"
manning = 0.03
edges = "closed"

[[initial_water]]
level_m = 102.0
polygon = [[{x0}, {y0}], [{xd}, {y0}], [{xd}, {y1}], [{x0}, {y1}]]

[numerics]
particle_spacing_m = 10.0
refinement = "none"

[output]
resolution_m = 10.0
"""


@needs_anuga
def test_anuga_and_floodsph_on_a_small_dam_break(tmp_path):
    """Flat bed at 100 m, 30 x 10 cells of 10 m, 2 m of water in the western 100 m, walls.

    At 10 s the Ritter front is at 100 + 2 sqrt(g 2 m) 10 s = 189 m: both codes flood the
    reservoir and the next few cells only, and keep the 20 000 m3 in the closed box.
    """
    import rasterio

    write_geotiff(tmp_path / "dem.tif", np.full((10, 30), 100.0))
    scenario = tmp_path / "scenario.toml"
    scenario.write_text(DAM_BREAK.format(x0=X0, y0=Y0, xd=X0 + 100.0, y1=Y0 + 100.0))
    out = tmp_path / "out"
    assert vgc.main([str(scenario), "--out", str(out), "--quiet"]) == 0
    with open(out / "versus_grid_code.csv", newline="") as f:
        (row,) = list(csv.DictReader(f))
    assert row["scenario"] == "tiny-dam-break" and int(row["triangles"]) == 4 * 300
    for key in ("floodsph_volume_initial_m3", "anuga_volume_initial_m3",
                "anuga_volume_final_m3"):
        assert float(row[key]) == pytest.approx(20000.0, rel=1e-5), key
    assert float(row["csi"]) > 0.8
    assert float(row["wall_ratio_floodsph_to_anuga"]) == pytest.approx(
        float(row["floodsph_wall_s"]) / float(row["anuga_wall_s"]), rel=1e-4)
    with rasterio.open(out / "tiny-dam-break" / "anuga_max_depth.tif") as src:
        depth = src.read(1)[::-1]  # row 0 = south
    assert np.all(depth[:, :10] >= 2.0)  # the reservoir, initial depth included
    assert np.isnan(depth[:, 25:]).all()  # beyond x = 250 m: never wet
    assert (out / "tiny-dam-break" / "max_depth_side_by_side.png").is_file()


# -- EA test 4 ----------------------------------------------------------------------------------
def test_arrival_is_the_first_sample_above_the_threshold_and_peak_its_maximum():
    t = np.array([0.0, 10.0, 20.0, 30.0, 40.0])
    assert ea4.arrival_and_peak(t, np.array([0, 0.005, 0.02, 0.5, 0.3]), 0.01) == (
        20.0, 0.5, 30.0)
    arrival, peak, t_peak = ea4.arrival_and_peak(t, np.array([0, 0, 0.01, 0.004, 0]), 0.01)
    assert math.isnan(arrival) and peak == 0.01 and math.isnan(t_peak)


def test_dry_gauge_samples_count_as_zero_depth(tmp_path):
    path = tmp_path / "gauges.csv"
    path.write_text("time_s,id,depth_m,level_m,speed_ms\n0,P1,nan,nan,nan\n0,P2,0.2,0.2,0.1\n"
                    "10,P1,0.3,0.3,0.2\n10,P2,nan,nan,nan\n")
    series = ea4.gauge_series(path)
    assert series["P1"][1].tolist() == [0.0, 0.3]
    assert series["P2"][0].tolist() == [0.0, 10.0] and series["P2"][1].tolist() == [0.2, 0.0]


@needs_ea4
def test_ea4_scenario_and_hydrograph_written_to_the_contract(tmp_path):
    from floodsph.cli.main import cli
    from floodsph.io.hydrograph import read_hydrograph
    from floodsph.scenario.reader import load_scenario

    path = ea4.write_inputs(EA4_DATA, tmp_path, 18000.0, 10, 10.0)
    hydrograph = read_hydrograph(tmp_path / "ea4_hydrograph.csv")
    assert hydrograph.total_volume() == pytest.approx(EA4_VOLUME_M3, rel=1e-12)
    assert float(hydrograph.discharge(9000.0)) == 20.0
    sc = load_scenario(path)
    assert sc.terrain.crs == "EPSG:27700" and sc.terrain.manning == 0.05
    assert [list(p) for p in sc.inflows[0].line] == [[0.0, 990.0], [0.0, 1010.0]]
    assert sc.terrain.dem.parent == EA4_DATA  # read in place, never copied
    with open(tmp_path / "ea4_gauges.csv", newline="") as f:
        gauges = {r["id"]: (float(r["x"]), float(r["y"])) for r in csv.DictReader(f)}
    assert gauges == {"P1": (50, 1000), "P2": (100, 1000), "P3": (200, 1000),
                      "P4": (300, 1000), "P5": (400, 1000), "P6": (300, 1300)}
    result = CliRunner().invoke(cli, ["check", str(path)])
    assert result.exit_code == 0, result.output
    assert "Inflow volume:   285000 m3" in result.output
    assert "100 x 200 cells of 10 m" in result.output


@needs_ea4
@pytest.mark.parametrize("time_stepping, refinement", [("global", "split+coalesce"),
                                                        ("local", "split+coalesce"),
                                                        ("local", "none")])
def test_ea4_short_run_injects_the_hydrograph_volume(tmp_path, time_stepping, refinement):
    """700 s on the 10 m DEM: 400 s of inflow, 485 m3, nowhere near the points 400 m away.

    The inflow injects whole rows of particles: the injected volume follows the hydrograph
    integral within half a row, d_B L dx / 2 (floodsph.boundaries.inflow), about 15 m3 here
    (boundary depth d_B ~ 0.15 m, L = 20 m, dx = 10 m). With local time stepping the rows enter
    within big steps, and water leaves through the open edges between a particle's updates.
    """
    out = tmp_path / "ea4"
    argv = ["--end-time", "700", "--dem-cell", "10", "--threads", "1", "--out", str(out),
            "--time-stepping", time_stepping, "--refinement", refinement]
    assert ea4.main(argv) == 0
    with open(out / "run" / "run.json") as f:
        manifest = json.load(f)
    assert manifest["scenario"]["numerics"]["time_stepping"] == time_stepping
    assert manifest["scenario"]["numerics"]["refinement"] == refinement
    if refinement == "none":
        assert manifest["splits"] == 0 and manifest["merges"] == 0
    with open(out / "ea4_volume.csv", newline="") as f:
        (balance,) = list(csv.DictReader(f))
    assert float(balance["hydrograph_volume_m3"]) == pytest.approx(_ramp_volume(700.0), rel=1e-5)
    assert float(balance["volume_in_m3"]) == pytest.approx(_ramp_volume(700.0), abs=25.0)
    assert float(balance["volume_domain_m3"]) == pytest.approx(float(balance["volume_in_m3"]),
                                                               rel=1e-9)
    assert abs(float(balance["mass_error_rel"])) < 1e-9
    with open(out / "ea4_points.csv", newline="") as f:
        points = {r["point"]: r for r in csv.DictReader(f)}
    assert sorted(points) == ["P1", "P2", "P3", "P4", "P5", "P6"]
    for far in ("P5", "P6"):
        assert points[far]["arrival_s"] == "nan" and float(points[far]["peak_depth_m"]) == 0.0
    assert (out / "ea4_depths.png").is_file() and (out / "ea4_volume.png").is_file()
