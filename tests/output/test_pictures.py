"""Quick-look pictures: labels that do not run into each other or into the maps, scale bars
of a round length, and the new speed, d·v and time-wet maps drawn from the right values."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from rasterio.crs import CRS
from rasterio.transform import from_origin

pytest.importorskip("matplotlib", reason="matplotlib (floodsph[plot]) not installed")

from floodsph.model.terrain import Terrain  # noqa: E402
from floodsph.output.envelopes import Envelopes  # noqa: E402
from floodsph.output.grid import OutputGrid  # noqa: E402
from floodsph.output.pictures import (  # noqa: E402
    comparison_figure,
    map_figure,
    scale_length,
    time_unit,
)

X0, Y0, CELL = 431000.0, 5012000.0, 5.0


@pytest.fixture(scope="module")
def envelopes():
    """300 m x 200 m; three bands of water reaching Australian classes H1, H5 and H6."""
    t = Terrain.from_function(lambda x, y: 0.01 * (x - X0), (X0, X0 + 300.0), (Y0, Y0 + 200.0),
                              CELL)
    t.crs_wkt = CRS.from_epsg(32632).to_wkt()
    env = Envelopes(OutputGrid.from_terrain(t), wet_threshold=0.05)
    d = np.full(env.grid.shape, np.nan)
    u = np.zeros(env.grid.shape)
    d[:, :10], u[:, :10] = 0.2, 0.5      # H1
    d[:, 10:20], u[:, 10:20] = 1.0, 3.0  # d v = 3 m2/s, v <= 4 m/s: H5
    d[:, 20:30], u[:, 20:30] = 2.0, 5.0  # v > 4 m/s: H6
    env.fold(0.0, 0.0, d, u, np.zeros_like(u))
    env.fold(600.0, 600.0, d, u, np.zeros_like(u))
    return env


def drawn(fig):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def test_hazard_class_names_do_not_overlap_each_other_or_the_map(envelopes):
    fig = map_figure(envelopes, "hazard_arr", "valley")
    renderer = drawn(fig)
    ax = fig.axes[0]
    legend = ax.get_legend()
    boxes = [t.get_window_extent(renderer) for t in legend.get_texts()]
    assert [t.get_text()[:2] for t in legend.get_texts()] == ["H1", "H2", "H3", "H4", "H5",
                                                               "H6"]
    assert "\n" in legend.get_texts()[4].get_text()      # the long H5 name is wrapped ...
    for a, b in itertools.combinations(boxes, 2):        # ... and no two names overlap
        assert not a.overlaps(b)
    assert not legend.get_window_extent(renderer).overlaps(ax.get_window_extent(renderer))
    assert fig.bbox.contains(*legend.get_window_extent(renderer).p1)   # inside the figure


def test_comparison_legend_stays_clear_of_both_panels():
    from floodsph.output.compare import Comparison
    from floodsph.output.map_source import Raster
    from floodsph.output.quantities import BY_NAME

    categories = np.zeros((40, 60), dtype=np.uint8)
    categories[:, :] = 1
    categories[10:20, 10:30] = 2
    categories[10:20, 30:35] = 3
    categories[20:25, 10:30] = 4
    model = Raster("m.tif", np.zeros((40, 60)), from_origin(500000.0, 4200000.0, 10.0, 10.0),
                   CRS.from_epsg(32633), BY_NAME["depth"])
    summary = {"csi": 0.6, "hit_rate": 0.667, "kind": "depth"}
    fig = comparison_figure(Comparison(summary, np.zeros((40, 60)), categories, model))
    renderer = drawn(fig)
    ax1, ax2 = fig.axes[:2]
    legend = ax1.get_legend().get_window_extent(renderer)
    assert [t.get_text() for t in ax1.get_legend().get_texts()][:2] == ["dry in both",
                                                                        "hit (wet in both)"]
    assert not legend.overlaps(ax1.get_window_extent(renderer))
    assert not legend.overlaps(ax1.xaxis.label.get_window_extent(renderer))
    assert not legend.overlaps(ax2.get_tightbbox(renderer))


def test_scale_bar_is_a_round_fifth_of_the_width_at_most(envelopes):
    assert scale_length(300.0) == 50.0          # a fifth is 60 m: 50 m
    assert scale_length(12_000.0) == 2000.0     # 2400 m: 2 km
    assert scale_length(1000.0) == 200.0
    fig = map_figure(envelopes, "max_depth")
    texts = [t.get_text() for t in fig.axes[0].findobj(lambda a: hasattr(a, "get_text"))]
    assert "50 m" in texts


def test_speed_dv_and_time_wet_pictures_show_the_mapped_values(envelopes):
    """The image of each picture holds the map's values (time wet in min: 600 s = 10 min)."""
    expected = {"max_speed": (0.5, 5.0), "max_unit_discharge": (0.1, 10.0),
                "duration": (10.0, 10.0)}
    for name, (low, high) in expected.items():
        fig = map_figure(envelopes, name)
        image = fig.axes[0].get_images()[-1].get_array()
        assert (float(image.min()), float(image.max())) == pytest.approx((low, high)), name
        assert image.mask[:, 30:].all()       # dry cells stay clear of colour
        label = fig.axes[-1].get_ylabel()     # the colour bar
        assert label.endswith({"max_speed": "[m/s]", "max_unit_discharge": "[m²/s]",
                               "duration": "[min]"}[name])


def test_time_unit_follows_the_range():
    assert time_unit(90.0) == (1.0, "s")
    assert time_unit(600.0) == (60.0, "min")
    assert time_unit(5 * 3600.0) == (3600.0, "h")


def test_depth_quick_look_is_drawn_in_the_depth_bands(envelopes):
    """Depths take the colour of their band, the same colours as the report's area table
    (a linear ramp from 0 to the deepest 2 m gave 0.2 m a near-white colour); a depth on a
    limit (1 m) is in the deeper band, in the picture as in the table."""
    from matplotlib.colors import to_hex

    from floodsph.output.areas import area_by_depth, depth_bands

    fig = map_figure(envelopes, "max_depth")
    image = fig.axes[0].get_images()[-1]
    bands = {b.label: b.colour for b in depth_bands(envelopes.wet_threshold)}
    for depth, label in ((0.2, "0.15 to 0.3 m"), (0.7, "0.5 to 1 m"), (1.0, "1 to 2 m"),
                         (1.5, "1 to 2 m"), (2.0, "2 to 5 m"), (7.0, "more than 5 m")):
        assert to_hex(image.to_rgba(depth)) == bands[label], depth
        rows = area_by_depth(np.array([depth]), 1.0, envelopes.wet_threshold)
        assert [r.label for r in rows if r.cells] == [label]
    assert to_hex(image.to_rgba(0.2)) != to_hex(image.to_rgba(0.3))


def test_walls_sinks_gauges_and_the_caption_are_drawn(envelopes):
    from floodsph.output.pictures import MapFeatures, map_caption

    caption = map_caption(envelopes.grid.crs_wkt, 600.0, None)
    assert caption == ("CRS: WGS 84 / UTM zone 32N (EPSG:32632); maxima over t = 0 to 600 s "
                       "(no calendar start)")
    wall = np.array([[X0 + 100.0, Y0 + 20.0], [X0 + 100.0, Y0 + 180.0]])
    sink = np.array([[X0 + 250.0, Y0], [X0 + 300.0, Y0], [X0 + 300.0, Y0 + 50.0]])
    features = MapFeatures(walls=(wall,), sinks=(sink,), gauges=(("G7", X0 + 40.0, Y0 + 60.0),),
                           caption=caption)
    for name in ("max_depth", "hazard_uk", "arrival_time"):
        fig = map_figure(envelopes, name, features=features)
        ax = fig.axes[0]
        lines = [line.get_xydata() for line in ax.get_lines()]
        assert any(np.allclose(xy, wall / 1e3) for xy in lines), name
        assert any(len(xy) == 4 and np.allclose(xy[:3], sink / 1e3) for xy in lines), name
        assert "G7" in [t.get_text() for t in ax.texts], name
        assert fig.get_supxlabel() == caption


def test_gauge_plot_spans_the_run_and_says_when_every_gauge_stayed_dry():
    from floodsph.output.pictures import gauge_figure

    nan = float("nan")
    rows = [(t, "G1", nan, nan, nan) for t in (0.0, 30.0, 60.0)]
    depth_ax, level_ax = gauge_figure(rows).axes[:2]
    assert level_ax.get_xlim() == (0.0, 60.0)
    assert [t.get_text() for t in depth_ax.texts] == ["every gauge stayed dry"]
    wet = [(0.0, "G1", nan, nan, nan), (30.0, "G1", 0.4, 100.4, 1.0), (60.0, "G1", 0.9, 100.9,
                                                                           1.2)]
    depth_ax, _ = gauge_figure(wet).axes[:2]
    assert not depth_ax.texts
    assert np.allclose(depth_ax.get_lines()[0].get_xydata()[1:], [[30.0, 0.4], [60.0, 0.9]])
