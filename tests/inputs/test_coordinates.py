"""One bowl, the DEM as engineers bring it: projected, geographic with lon/lat coordinates, Web
Mercator; inline coordinates follow the DEM file, and messages name the CRS they are in."""

from __future__ import annotations

import math

import numpy as np
import pytest
import rasterio
from rasterio.crs import CRS
from rasterio.enums import Resampling
from rasterio.transform import from_origin
from rasterio.warp import calculate_default_transform, reproject
from rasterio.warp import transform as warp_transform

from floodsph.errors import InputError
from floodsph.inputs.prepare import prepare_inputs, summary_lines
from floodsph.scenario.reader import load_scenario

UTM = CRS.from_epsg(32616)
LONLAT = CRS.from_epsg(4326)
MERCATOR = CRS.from_epsg(3857)
CELL = 20.0
N = 100  # 2 km x 2 km
XC, YC = 500_000.0, 4_062_000.0  # the bowl's centre, -87.0 E, 36.70 N
CURVATURE = 40_000.0  # z = 100 + r^2 / CURVATURE [m]
LEVEL = 115.0
BOWL_VOLUME_M3 = math.pi * CURVATURE * (LEVEL - 100.0) ** 2 / 2.0  # 14.14e6 m3
HALF = 900.0  # the reservoir polygon: a square of +-900 m around the centre


def bowl() -> tuple[np.ndarray, object]:
    """North-up bowl elevations in UTM and their transform."""
    x0, y1 = XC - N * CELL / 2, YC + N * CELL / 2
    x = x0 + (np.arange(N) + 0.5) * CELL
    y = y1 - (np.arange(N) + 0.5) * CELL
    z = 100.0 + ((x[None, :] - XC) ** 2 + (y[:, None] - YC) ** 2) / CURVATURE
    return z, from_origin(x0, y1, CELL, CELL)


def write(path, z, transform, crs):
    with rasterio.open(path, "w", driver="GTiff", width=z.shape[1], height=z.shape[0],
                       count=1, dtype="float64", crs=crs, transform=transform,
                       nodata=-9999.0) as dst:
        dst.write(z, 1)
    return path


def warped(path, crs, resolution):
    """The bowl reprojected to ``crs`` (bilinear), as a file in ``crs``."""
    z, t = bowl()
    left, top = t.c, t.f
    dst_t, w, h = calculate_default_transform(UTM, crs, N, N, left, top - N * CELL,
                                              left + N * CELL, top, resolution=resolution)
    out = np.full((h, w), -9999.0)
    reproject(z, out, src_transform=t, src_crs=UTM, dst_transform=dst_t, dst_crs=crs,
              dst_nodata=-9999.0, resampling=Resampling.bilinear)
    return write(path, out, dst_t, crs)


def square_in(crs) -> list[list[float]]:
    """The reservoir square's corners, written in ``crs``."""
    xs = [XC - HALF, XC + HALF, XC + HALF, XC - HALF]
    ys = [YC - HALF, YC - HALF, YC + HALF, YC + HALF]
    if crs != UTM:
        xs, ys = warp_transform(UTM, crs, xs, ys)
    return [[float(x), float(y)] for x, y in zip(xs, ys, strict=True)]


def scenario(tmp_path, dem, polygon, extra="", gauge=None):
    text = f"""[scenario]
name = "bowl"
end_time_s = 10.0
{extra}
[terrain]
dem = "{dem.name}"

[[initial_water]]
level_m = {LEVEL}
polygon = {polygon}

[numerics]
particle_spacing_m = {CELL}
"""
    if gauge is not None:
        (tmp_path / "gauges.csv").write_text(f"id,x,y\ng1,{gauge[0]!r},{gauge[1]!r}\n")
        text += '\n[gauges]\nfile = "gauges.csv"\n'
    path = tmp_path / "bowl.toml"
    path.write_text(text)
    return load_scenario(path)


@pytest.fixture
def forms(tmp_path):
    """The bowl as a projected DEM, a geographic one and a Web Mercator one."""
    z, t = bowl()
    return {
        "projected": write(tmp_path / "utm.tif", z, t, UTM),
        "geographic": warped(tmp_path / "lonlat.tif", LONLAT, 0.0002),
        "mercator": warped(tmp_path / "merc.tif", MERCATOR, CELL * 1.247),
    }


def test_every_form_of_the_bowl_holds_the_same_water(forms, tmp_path):
    volumes = {}
    for name, dem in forms.items():
        crs = {"projected": UTM, "geographic": LONLAT, "mercator": MERCATOR}[name]
        inputs = prepare_inputs(scenario(tmp_path, dem, square_in(crs)))
        assert CRS.from_wkt(inputs.terrain.crs_wkt) == UTM, name
        volumes[name] = inputs.volume_initial_m3
    assert volumes["projected"] == pytest.approx(BOWL_VOLUME_M3, rel=0.01)
    for name in ("geographic", "mercator"):
        assert volumes[name] == pytest.approx(volumes["projected"], rel=0.005), volumes


def test_lonlat_inline_coordinates_follow_a_geographic_dem(forms, tmp_path):
    lon, lat = warp_transform(UTM, LONLAT, [XC + 300.0], [YC - 200.0])
    sc = scenario(tmp_path, forms["geographic"], square_in(LONLAT), gauge=(lon[0], lat[0]))
    inputs = prepare_inputs(sc)
    t = inputs.terrain
    # The gauge, given in lon/lat, sits 300 m east and 200 m south of the centre in UTM.
    assert inputs.gauges.x[0] + t.x0 == pytest.approx(XC + 300.0, abs=1e-3)
    assert inputs.gauges.y[0] + t.y0 == pytest.approx(YC - 200.0, abs=1e-3)
    lines = summary_lines(sc, inputs, None)
    assert "CRS:             EPSG:32616 (WGS 84 / UTM zone 16N) (the model and the maps)" \
        in "\n".join(lines)
    assert "Coordinates:     EPSG:4326 (WGS 84), the DEM file's CRS (inline coordinates)" \
        in lines
    assert [line for line in lines if line.startswith("DEM file CRS:    EPSG:4326")]


def test_mercator_dem_check_reports_its_scale_factor(forms, tmp_path):
    sc = scenario(tmp_path, forms["mercator"], square_in(MERCATOR))
    inputs = prepare_inputs(sc)
    line = [s for s in summary_lines(sc, inputs, None) if s.startswith("DEM file CRS:")][0]
    lo, hi = (float(v) for v in line.split("scale factor ")[1].split(")")[0].split(" to "))
    assert 1.2460 < lo < hi < 1.2485  # 1 / cos(36.7 deg) = 1.2472 at the centre
    assert "EPSG:3857" in line
    assert [w for w in inputs.warnings if "merc.tif" in w and "EPSG:32616" in w]


def test_scenario_crs_gives_inline_coordinates_in_another_crs(forms, tmp_path):
    sc = scenario(tmp_path, forms["projected"], square_in(LONLAT),
                  extra='crs = "EPSG:4326"\n')
    assert sc.scenario.crs == "EPSG:4326"
    inputs = prepare_inputs(sc)
    assert inputs.volume_initial_m3 == pytest.approx(BOWL_VOLUME_M3, rel=0.01)
    assert "Coordinates:     EPSG:4326 (WGS 84), scenario.crs (inline coordinates)" in \
        summary_lines(sc, inputs, None)


def test_lonlat_polygon_over_a_projected_dem_names_the_file_crs_and_the_way_out(forms,
                                                                               tmp_path):
    sc = scenario(tmp_path, forms["projected"], square_in(LONLAT))
    with pytest.raises(InputError) as err:
        prepare_inputs(sc)
    message = str(err.value)
    assert message.startswith("bowl.toml: initial_water[0].polygon: the polygon lies wholly "
                              "outside the DEM extent [499000, 4061000, 501000, 4063000] in "
                              "EPSG:32616 (WGS 84 / UTM zone 16N), the DEM file's CRS")
    assert message.endswith('; for longitude/latitude give [scenario] crs = "EPSG:4326"')


def test_projected_polygon_over_a_geographic_dem_names_the_crs_it_is_read_in(forms, tmp_path):
    # Metres where the DEM file (EPSG:4326) says degrees: one message naming both CRSs.
    sc = scenario(tmp_path, forms["geographic"], square_in(UTM))
    with pytest.raises(InputError) as err:
        prepare_inputs(sc)
    message = str(err.value)
    assert "initial_water[0].polygon" in message
    assert "EPSG:4326 (WGS 84), the DEM file's CRS" in message
    assert "[scenario] crs" in message and "EPSG:32616" in message


def tiles(tmp_path, east_crs=UTM):
    """The bowl split in a west and an east tile that overlap by 10 columns, with different
    nodata values (-9999 and -32768); the east tile in ``east_crs``."""
    z, t = bowl()
    west = write(tmp_path / "bowl_w.tif", z[:, :55], t, UTM)
    east_t = from_origin(t.c + 45 * CELL, t.f, CELL, CELL)
    with rasterio.open(tmp_path / "bowl_e.tif", "w", driver="GTiff", width=55, height=N,
                       count=1, dtype="float32", crs=UTM, transform=east_t,
                       nodata=-32768.0) as dst:
        dst.write(z[:, 45:].astype(np.float32), 1)
    east = tmp_path / "bowl_e.tif"
    if east_crs != UTM:
        with rasterio.open(east) as src:
            data, src_t = src.read(1).astype(np.float64), src.transform
        dst_t, w, h = calculate_default_transform(UTM, east_crs, 55, N,
                                                  *rasterio.transform.array_bounds(N, 55, src_t))
        out = np.full((h, w), -9999.0)
        reproject(data, out, src_transform=src_t, src_crs=UTM, dst_transform=dst_t,
                  dst_crs=east_crs, dst_nodata=-9999.0, resampling=Resampling.bilinear)
        east = write(tmp_path / "bowl_e_lonlat.tif", out, dst_t, east_crs)
    return west, east


def test_two_tiles_make_the_dem_they_were_cut_from(forms, tmp_path):
    whole = prepare_inputs(scenario(tmp_path, forms["projected"], square_in(UTM)))
    tiles(tmp_path)
    text = (tmp_path / "bowl.toml").read_text().replace('dem = "utm.tif"', 'dem = "bowl_?.tif"')
    (tmp_path / "bowl.toml").write_text(text)
    sc = load_scenario(tmp_path / "bowl.toml")
    assert sc.terrain.dem == (tmp_path / "bowl_e.tif", tmp_path / "bowl_w.tif")
    mosaic = prepare_inputs(sc)
    t = mosaic.terrain
    assert (t.x0, t.y0, t.shape) == (whole.terrain.x0, whole.terrain.y0, (N, N))
    assert t.valid.all()
    # float32 east tile: elevations to float32 round-off, the same water to 1e-6.
    np.testing.assert_allclose(t.elevation, whole.terrain.elevation, rtol=0, atol=2e-5)
    assert mosaic.volume_initial_m3 == pytest.approx(whole.volume_initial_m3, rel=1e-6)


def test_a_tile_in_another_crs_is_reprojected_to_the_first_ones(forms, tmp_path):
    whole = prepare_inputs(scenario(tmp_path, forms["projected"], square_in(UTM)))
    west, east = tiles(tmp_path, east_crs=LONLAT)
    text = (tmp_path / "bowl.toml").read_text().replace(
        'dem = "utm.tif"', f'dem = ["{west.name}", "{east.name}"]')
    (tmp_path / "bowl.toml").write_text(text)
    inputs = prepare_inputs(load_scenario(tmp_path / "bowl.toml"))
    assert [w for w in inputs.warnings if "bowl_e_lonlat.tif is in EPSG:4326" in w]
    assert CRS.from_wkt(inputs.terrain.crs_wkt) == UTM
    assert inputs.volume_initial_m3 == pytest.approx(whole.volume_initial_m3, rel=0.005)


def test_a_glob_that_matches_nothing_names_the_key(forms, tmp_path):
    sc = tmp_path / "bowl.toml"
    scenario(tmp_path, forms["projected"], square_in(UTM))
    sc.write_text(sc.read_text().replace('dem = "utm.tif"', 'dem = "N36W08*.tif"'))
    with pytest.raises(InputError, match=r"bowl.toml: terrain.dem: no file matches .*N36W08\*"):
        load_scenario(sc)


def test_every_form_of_the_bowl_maps_the_same_flood(forms, tmp_path):
    """Thirty steps of the bowl at rest from each form: the maximum-depth maps, resampled onto
    the projected run's grid, are wet on the same cells but for a band of one cell at the
    shore, and agree inside it within 0.1 m (measured: 4e-5 m for the tiles, 0.005 m for Web
    Mercator, 0.048 m for the geographic DEM)."""
    from scipy import ndimage

    from floodsph.api import run_scenario

    z, t = bowl()
    forms["tiles"] = tuple(tiles(tmp_path))
    maps = {}
    for name, dem in forms.items():
        crs = {"geographic": LONLAT, "mercator": MERCATOR}.get(name, UTM)
        folder = tmp_path / name
        folder.mkdir()
        if isinstance(dem, tuple):
            dem_key = "[" + ", ".join(f'"{p}"' for p in dem) + "]"
        else:
            dem_key = f'"{dem}"'
        (folder / "bowl.toml").write_text(f"""[scenario]
name = "{name}"
end_time_s = 5.0

[terrain]
dem = {dem_key}

[[initial_water]]
level_m = {LEVEL}
polygon = {square_in(crs)}

[numerics]
particle_spacing_m = {CELL}

[output]
formats = ["geotiff"]
""")
        result = run_scenario(folder / "bowl.toml", max_steps=30, progress=False, threads=1)
        with rasterio.open(result.folder / "max_depth.tif") as src:
            maps[name] = {}
            for how in (Resampling.nearest, Resampling.bilinear):
                depth = np.full((N, N), np.nan)
                reproject(rasterio.band(src, 1), depth, dst_transform=t, dst_crs=UTM,
                          dst_nodata=np.nan, resampling=how)
                maps[name][how] = np.nan_to_num(depth)
    wet = maps["projected"][Resampling.nearest] > 0.0
    shore = ndimage.binary_dilation(wet) & ~ndimage.binary_erosion(wet)
    inner = ndimage.binary_erosion(wet, iterations=3)
    assert wet.sum() > 4000  # the bowl holds water over a disc of about 4,700 cells
    reference = maps["projected"][Resampling.bilinear]
    for name in ("tiles", "mercator", "geographic"):
        other = maps[name][Resampling.nearest] > 0.0
        assert not np.any((other != wet) & ~shore), name
        # Bilinear: a nearest pick of cells 19.9 m wide onto 20 m ones would shift the bowl's
        # slope by up to half a cell (0.35 m of depth at 700 m from the centre).
        depth = maps[name][Resampling.bilinear]
        np.testing.assert_allclose(depth[inner], reference[inner], atol=0.1, err_msg=name)
        assert depth.sum() == pytest.approx(reference.sum(), rel=0.005), name


def test_extent_inflow_line_and_direction_in_lonlat_follow_the_geographic_dem(forms, tmp_path):
    sc = scenario(tmp_path, forms["geographic"], square_in(LONLAT))
    (tmp_path / "q.csv").write_text("time_s,discharge_m3s\n0,1\n10,1\n")
    (lon0, lon1), (lat0, lat1) = warp_transform(UTM, LONLAT, [XC - 600.0, XC + 600.0],
                                                [YC - 500.0, YC + 500.0])
    (a_lon, b_lon), (a_lat, b_lat) = warp_transform(UTM, LONLAT, [XC - 400.0, XC - 400.0],
                                                    [YC - 100.0, YC + 100.0])
    text = sc.path.read_text().replace(
        "[terrain]\n", f"[terrain]\nextent = [{lon0!r}, {lat0!r}, {lon1!r}, {lat1!r}]\n")
    text += (f"\n[[inflows]]\nline = [[{a_lon!r}, {a_lat!r}], [{b_lon!r}, {b_lat!r}]]\n"
             'hydrograph = "q.csv"\ndirection = [1.0, 0.0]\n')
    sc.path.write_text(text)
    inputs = prepare_inputs(load_scenario(sc.path))
    t = inputs.terrain
    # The crop: 1200 m x 1000 m of whole ~19.9 m cells around the centre.
    assert t.width == pytest.approx(1200.0, abs=2 * t.dx)
    assert t.height == pytest.approx(1000.0, abs=2 * t.dy)
    assert t.x0 == pytest.approx(XC - 600.0, abs=t.dx)
    np.testing.assert_allclose(inputs.inflows[0].line, [(XC - 400.0, YC - 100.0),
                                                        (XC - 400.0, YC + 100.0)], atol=1e-3)
    dx, dy = inputs.inflows[0].direction
    assert dx > 0 and abs(dy / dx) < 1e-3  # east in lon/lat is east in UTM on its meridian


def test_a_scenario_crs_that_is_no_crs_names_the_key(forms, tmp_path):
    with pytest.raises(InputError, match=r"bowl.toml: scenario.crs: 'EPSG:99999' is not a "):
        scenario(tmp_path, forms["projected"], square_in(UTM), extra='crs = "EPSG:99999"\n')
