"""Walls, initial water, sinks and gauges from vector files in another CRS: placed on the
UTM valley DEM (conftest) where pyproj puts them, and bad files named in one message."""

from __future__ import annotations

import json
import math

import numpy as np
import pyproj
import pytest
from conftest import BASE_SCENARIO, CELL, CRS, NX, NY, RESERVOIR_VOLUME_M3, X0, Y0

from floodsph.errors import InputError
from floodsph.inputs.prepare import prepare_inputs
from floodsph.scenario.reader import load_scenario
from floodsph.scenario.writer import write_resolved

TO_LONLAT = pyproj.Transformer.from_crs(CRS, "EPSG:4326", always_xy=True)

# In the DEM's CRS (EPSG:32632): a wall across the valley floor, two gauges, the whole DEM.
WALL_UTM = [(X0 + 205.0, Y0 + 15.0), (X0 + 205.0, Y0 + 185.0)]
GAUGES_UTM = {"upstream": (X0 + 55.0, Y0 + 95.0), "downstream": (X0 + 305.0, Y0 + 105.0)}
DEM_RING_UTM = [(X0, Y0), (X0 + NX * CELL, Y0), (X0 + NX * CELL, Y0 + NY * CELL),
                (X0, Y0 + NY * CELL), (X0, Y0)]
SINK_UTM = [(X0 + 350.0, Y0), (X0 + 400.0, Y0), (X0 + 400.0, Y0 + 200.0),
            (X0 + 350.0, Y0 + 200.0), (X0 + 350.0, Y0)]


def lonlat(points) -> list[list[float]]:
    return [list(TO_LONLAT.transform(x, y)) for x, y in points]


def feature(kind: str, coordinates, **properties) -> dict:
    return {"type": "Feature", "properties": properties,
            "geometry": {"type": kind, "coordinates": coordinates}}


def write_geojson(path, *features):
    path.write_text(json.dumps({"type": "FeatureCollection", "features": list(features)}),
                    encoding="utf-8")
    return path


def local(points) -> np.ndarray:
    return np.asarray(points, dtype=np.float64) - (X0, Y0)


def vector_scenario(tmp_path) -> str:
    """The base scenario with its reservoir, a wall, a sink and the gauges in GeoJSON files
    (RFC 7946: longitude, latitude on WGS 84)."""
    write_geojson(tmp_path / "reservoir.geojson", feature("Polygon", [lonlat(DEM_RING_UTM)]))
    write_geojson(tmp_path / "walls.geojson", feature("LineString", lonlat(WALL_UTM)))
    write_geojson(tmp_path / "sea.geojson", feature("Polygon", [lonlat(SINK_UTM)]))
    write_geojson(tmp_path / "gauges.geojson",
                  *(feature("Point", lonlat([p])[0], name=n) for n, p in GAUGES_UTM.items()))
    head, _, rest = BASE_SCENARIO.partition("[[initial_water]]")
    rest = rest[rest.index("[numerics]"):]
    return (head + '[[initial_water]]\nlevel_m = 100.0\nfile = "reservoir.geojson"\n\n'
            '[[walls]]\nfile = "walls.geojson"\n\n[[sinks]]\nfile = "sea.geojson"\n\n'
            '[gauges]\nfile = "gauges.geojson"\nid_field = "name"\ninterval_s = 5.0\n\n' + rest)


def test_geojson_in_lonlat_placed_on_the_utm_dem(write_scenario, tmp_path):
    sc = load_scenario(write_scenario(vector_scenario(tmp_path)))
    assert sc.walls[0].polyline is None and sc.walls[0].file.name == "walls.geojson"
    inputs = prepare_inputs(sc)
    # Where pyproj puts the lon/lat points back in UTM: within a millimetre.
    assert len(inputs.walls) == 1
    assert np.allclose(inputs.walls[0], local(WALL_UTM), atol=1e-3)
    assert inputs.gauges.ids == tuple(GAUGES_UTM)
    gauges = np.column_stack([inputs.gauges.x, inputs.gauges.y])
    assert np.allclose(gauges, local(list(GAUGES_UTM.values())), atol=1e-3)
    assert np.allclose(inputs.gauges.bed, [98.0, 100.0])  # basin floor, valley floor
    assert np.allclose(inputs.sinks[0], local(SINK_UTM), atol=1e-3)
    # The reservoir polygon (the whole DEM) holds the basin's water: 100 m x 200 m x 2 m.
    assert math.isclose(inputs.volume_initial_m3, RESERVOIR_VOLUME_M3, rel_tol=1e-9)
    # The resolved copy keeps the file keys and reloads into the same scenario.
    write_resolved(sc, tmp_path / "resolved.toml")
    assert load_scenario(tmp_path / "resolved.toml").to_dict() == sc.to_dict()


def test_geojson_crs_member_and_crs_key(write_scenario, tmp_path):
    # A file in the DEM's own CRS, named by the 2008 GeoJSON "crs" member, and one without
    # CRS information whose coordinates the scenario's crs key declares.
    named = {"type": "FeatureCollection",
             "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32632"}},
             "features": [feature("LineString", [list(p) for p in WALL_UTM])]}
    (tmp_path / "named.geojson").write_text(json.dumps(named), encoding="utf-8")
    mercator = pyproj.Transformer.from_crs(CRS, "EPSG:3857", always_xy=True)
    write_geojson(tmp_path / "mercator.geojson",
                  feature("LineString", [list(mercator.transform(*p)) for p in WALL_UTM]))
    text = BASE_SCENARIO + ('\n[[walls]]\nfile = "named.geojson"\n\n'
                            '[[walls]]\nfile = "mercator.geojson"\ncrs = "EPSG:3857"\n')
    inputs = prepare_inputs(load_scenario(write_scenario(text)))
    assert len(inputs.walls) == 2
    for wall in inputs.walls:
        assert np.allclose(wall, local(WALL_UTM), atol=1e-3)


def test_wrong_geometry_type_names_the_file_and_key(write_scenario, tmp_path):
    write_geojson(tmp_path / "walls.geojson", feature("LineString", lonlat(WALL_UTM)),
                  feature("Point", lonlat(WALL_UTM[:1])[0]))
    sc = load_scenario(write_scenario(BASE_SCENARIO + '\n[[walls]]\nfile = "walls.geojson"\n'))
    with pytest.raises(InputError, match=r"^scenario\.toml: walls\[0\]\.file walls\.geojson: "
                                         r"feature 2 is Point; expected LineString"):
        prepare_inputs(sc)


def test_vector_polygon_off_the_dem_named_by_feature(write_scenario, tmp_path):
    far = [(x + 10_000.0, y) for x, y in SINK_UTM]
    write_geojson(tmp_path / "sea.geojson", feature("Polygon", [lonlat(SINK_UTM)]),
                  feature("Polygon", [lonlat(far)]))
    sc = load_scenario(write_scenario(BASE_SCENARIO + '\n[[sinks]]\nfile = "sea.geojson"\n'))
    with pytest.raises(InputError, match=r"sinks\[0\]\.file sea\.geojson, feature 2: the "
                                         r"polygon lies wholly outside the DEM"):
        prepare_inputs(sc)


@pytest.mark.parametrize(("entry", "message"), [
    ('[[walls]]\nfile = "walls.geojson"\npolyline = [[0, 0], [1, 1]]',
     r"walls\[0\]: give either polyline or file, not both"),
    ('[[walls]]\nfile = "walls.csv"', r"walls\[0\]\.file: walls\.csv: not a vector file"),
    ('[[sinks]]\nlayer = "sea"\npolygon = [[0, 0], [1, 0], [1, 1]]',
     r"sinks\[0\]\.layer: applies only with file"),
    ('[[walls]]\nfile = "walls.geojson"\ncrs = "EPSG:999999"',
     r"walls\[0\]\.crs: 'EPSG:999999' is not a coordinate reference system"),
])
def test_vector_keys_checked_when_loading(write_scenario, tmp_path, entry, message):
    write_geojson(tmp_path / "walls.geojson", feature("LineString", lonlat(WALL_UTM)))
    (tmp_path / "walls.csv").write_text("x,y\n", encoding="utf-8")
    with pytest.raises(InputError, match=message):
        load_scenario(write_scenario(BASE_SCENARIO + "\n" + entry + "\n"))


def test_geopackage_layer_in_web_mercator(write_scenario, tmp_path):
    pytest.importorskip("pyogrio", reason="GeoPackage needs the gis extra (pyogrio)")
    import shapely

    mercator = pyproj.Transformer.from_crs(CRS, "EPSG:3857", always_xy=True)
    line = shapely.LineString([mercator.transform(*p) for p in WALL_UTM])
    points = [shapely.Point(mercator.transform(*p)) for p in GAUGES_UTM.values()]
    path = tmp_path / "layers.gpkg"
    from pyogrio.raw import write

    write(path, np.array([shapely.to_wkb(line)], dtype=object), [], [], layer="dams",
          driver="GPKG", geometry_type="LineString", crs="EPSG:3857")
    write(path, np.array([shapely.to_wkb(p) for p in points], dtype=object),
          [np.array(list(GAUGES_UTM), dtype=object)], ["id"], layer="gauges",
          driver="GPKG", geometry_type="Point", crs="EPSG:3857", append=True)
    text = BASE_SCENARIO + ('\n[[walls]]\nfile = "layers.gpkg"\nlayer = "dams"\n\n'
                            '[gauges]\nfile = "layers.gpkg"\nlayer = "gauges"\n')
    inputs = prepare_inputs(load_scenario(write_scenario(text)))
    assert np.allclose(inputs.walls[0], local(WALL_UTM), atol=1e-3)
    assert inputs.gauges.ids == tuple(GAUGES_UTM)
    assert np.allclose(np.column_stack([inputs.gauges.x, inputs.gauges.y]),
                       local(list(GAUGES_UTM.values())), atol=1e-3)
    # Without layer, or with one the file lacks: one message naming the file and its layers.
    for extra, message in (("", r"the file holds several layers \['dams', 'gauges'\]; name one"),
                           ('layer = "dam"', r"no layer 'dam'; the file holds \['dams', ")):
        text = BASE_SCENARIO + f'\n[[walls]]\nfile = "layers.gpkg"\n{extra}\n'
        with pytest.raises(InputError, match=r"walls\[0\]\.file layers\.gpkg: " + message):
            prepare_inputs(load_scenario(write_scenario(text)))


def write_layer(path, geometries, crs, driver, **fields):
    import shapely
    from pyogrio.raw import write

    write(path, np.array([shapely.to_wkb(g) for g in geometries], dtype=object),
          [np.array(v, dtype=object) for v in fields.values()], list(fields), driver=driver,
          geometry_type=geometries[0].geom_type, crs=crs)
    return path


def zipped_shapefile(tmp_path, geometries, crs):
    import zipfile

    folder = tmp_path / "shp"
    folder.mkdir()
    write_layer(folder / "dams.shp", geometries, crs, "ESRI Shapefile")
    with zipfile.ZipFile(tmp_path / "dams.zip", "w") as archive:
        for part in sorted(folder.iterdir()):  # .shp, .shx, .dbf and the .prj with the CRS
            archive.write(part, part.name)
    return tmp_path / "dams.zip"


@pytest.mark.parametrize(("name", "crs", "driver"), [
    ("dams.kml", "EPSG:4326", "KML"),
    ("dams.gml", "EPSG:3857", "GML"),
    ("dams.fgb", "EPSG:3857", "FlatGeobuf"),
    ("dams.zip", "EPSG:3857", None),
])
def test_walls_from_each_gdal_format_land_where_pyproj_puts_them(write_scenario, tmp_path,
                                                                 name, crs, driver):
    import shapely

    move = pyproj.Transformer.from_crs(CRS, crs, always_xy=True)
    line = [shapely.LineString([move.transform(*p) for p in WALL_UTM])]
    if driver is None:
        zipped_shapefile(tmp_path, line, crs)
    else:
        write_layer(tmp_path / name, line, crs, driver)
    text = BASE_SCENARIO + f'\n[[walls]]\nfile = "{name}"\n'
    inputs = prepare_inputs(load_scenario(write_scenario(text)))
    assert np.allclose(inputs.walls[0], local(WALL_UTM), atol=1e-3)


def test_a_reservoir_with_an_island_keeps_the_island_dry(write_scenario, tmp_path):
    """A GeoJSON polygon with a hole: a 60 m x 100 m island in the 2 m deep basin."""
    island = [(X0 + 20.0, Y0 + 50.0), (X0 + 80.0, Y0 + 50.0), (X0 + 80.0, Y0 + 150.0),
              (X0 + 20.0, Y0 + 150.0), (X0 + 20.0, Y0 + 50.0)]
    write_geojson(tmp_path / "reservoir.geojson",
                  feature("Polygon", [lonlat(DEM_RING_UTM), lonlat(island)]))
    head, _, rest = BASE_SCENARIO.partition("[[initial_water]]")
    text = (head + '[[initial_water]]\nlevel_m = 100.0\nfile = "reservoir.geojson"\n\n'
            + rest[rest.index("[numerics]"):])
    inputs = prepare_inputs(load_scenario(write_scenario(text)))
    island_cells = 6 * 10
    assert inputs.particles.n == 10 * NY - island_cells
    assert inputs.volume_initial_m3 == pytest.approx(RESERVOIR_VOLUME_M3 * (1 - 60 / 200),
                                                     rel=1e-6)


def test_a_building_with_a_courtyard_is_two_closed_walls(write_scenario, tmp_path):
    outline = [(X0 + 200.0, Y0 + 40.0), (X0 + 300.0, Y0 + 40.0), (X0 + 300.0, Y0 + 160.0),
               (X0 + 200.0, Y0 + 160.0), (X0 + 200.0, Y0 + 40.0)]
    yard = [(X0 + 230.0, Y0 + 70.0), (X0 + 270.0, Y0 + 70.0), (X0 + 270.0, Y0 + 130.0),
            (X0 + 230.0, Y0 + 130.0), (X0 + 230.0, Y0 + 70.0)]
    write_geojson(tmp_path / "b.geojson", feature("Polygon", [lonlat(outline), lonlat(yard)]))
    inputs = prepare_inputs(load_scenario(write_scenario(
        BASE_SCENARIO + '\n[[walls]]\nfile = "b.geojson"\n')))
    assert len(inputs.walls) == 2
    assert np.allclose(inputs.walls[0], local(outline), atol=1e-3)
    assert np.allclose(inputs.walls[1], local(yard), atol=1e-3)
