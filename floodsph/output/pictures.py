"""Quick-look PNGs of a run's maps (depth, speed, d·v, duration, hazard, arrival), of its
gauges and mass balance over time, and of an ensemble's probability map.

matplotlib is optional (``floodsph[plot]``): without it every function returns the message
``"pictures skipped: matplotlib not installed"`` instead of paths. Figures are drawn with
``matplotlib.figure.Figure`` (no pyplot state, no GUI backend), north up, axes in km of the
map CRS, over a hillshade of the bed, with a title, a colour bar or legend with units, a
north arrow and a scale bar. The maximum depth is drawn in the depth bands of
:mod:`floodsph.output.areas` (a continuous ramp from 0 to the deepest cell leaves metre-deep
floodplains almost white beside a 30 m deep gorge). :class:`MapFeatures` adds the walls,
sinks and gauges and a caption with the CRS and the period the maps cover. The figure
builders (``*_figure``) return the Figure, so that its layout can be checked without
writing a file.
"""

from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import numpy as np

SKIPPED = "pictures skipped: matplotlib not installed"
SERIES_PICTURES = ("gauges.png", "mass_balance.png")
"""The time-series pictures of :func:`write_series_pictures`."""


@dataclass(frozen=True)
class MapFeatures:
    """What is drawn over every map, in world coordinates [m] of the map CRS: walls
    (polylines, black on a white halo), sinks (polygons, dashed purple outline), gauges
    (id, x, y: red triangles with their ids); and a caption under the map
    (:func:`map_caption`)."""

    walls: tuple = ()
    sinks: tuple = ()
    gauges: tuple = ()
    caption: str = ""


def map_caption(crs_wkt: str | None, period_s: float | None, start: datetime | None) -> str:
    """``CRS: WGS 84 / UTM zone 32N (EPSG:32632); maxima over t = 0 to 600 s from 2024-01-15
    06:00 UTC``: what every map of a run states about where and when it is."""
    from floodsph.output.gauges import utc_text

    if crs_wkt:
        import pyproj

        crs = pyproj.CRS.from_wkt(crs_wkt)
        code = crs.to_epsg()
        where = f"CRS: {crs.name}" + (f" (EPSG:{code})" if code else "")
    else:
        where = "no CRS (local coordinates)"
    if period_s is None:
        return where
    when = (f"from {utc_text(start)[:16].replace('T', ' ')} UTC" if start is not None
            else "(no calendar start)")
    return f"{where}; maxima over t = 0 to {period_s:g} s {when}"

CONTINUOUS = {
    "max_depth": ("maximum depth", "Blues", "m"),
    "max_speed": ("maximum speed", "YlOrRd", "m/s"),
    "max_unit_discharge": ("maximum depth x speed (d·v)", "magma_r", "m²/s"),
    "duration": ("time wet", "viridis", None),
}
"""Picture name -> (title, colour map, units; None: a time, in s, min or h by its range)."""

CLASSES = {"hazard_uk": "UK hazard rating class", "hazard_arr": "Australian hazard class"}
"""Class-map picture name -> legend title."""

PICTURES = (*CONTINUOUS, *CLASSES, "arrival_time")
"""The maps :func:`write_pictures` draws, one ``<name>.png`` each."""


def have_matplotlib() -> bool:
    """True when matplotlib can be imported."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


def _axes(grid, title, features: MapFeatures | None = None):
    """Figure and axes sized to the map aspect, axes in km, north arrow and scale bar; the
    caption of ``features`` under the map."""
    from matplotlib.figure import Figure

    aspect = (grid.ny * grid.dy) / (grid.nx * grid.dx)
    fig = Figure(figsize=(8.0, min(max(8.0 * aspect, 3.5), 11.0)), dpi=120,
                 layout="constrained")
    ax = fig.add_subplot()
    _frame(ax, title)
    _hillshade(ax, grid)
    ax.annotate("N", xy=(0.95, 0.95), xytext=(0.95, 0.83), xycoords="axes fraction",
                ha="center", va="center", fontsize=12, fontweight="bold",
                arrowprops={"arrowstyle": "-|>", "color": "k"})
    _scale_bar(ax, grid.nx * grid.dx)
    if features is not None and features.caption:
        fig.supxlabel(textwrap.fill(features.caption, 110), fontsize=8)
    return fig, ax


def _draw_features(ax, features: MapFeatures | None) -> None:
    """Walls, sinks and gauges over the map (axes in km), above every layer."""
    from matplotlib import patheffects

    if features is None:
        return
    halo = [patheffects.withStroke(linewidth=3.5, foreground="white")]
    for line in features.walls:
        xy = np.asarray(line) / 1e3
        ax.plot(xy[:, 0], xy[:, 1], color="k", linewidth=1.6, zorder=5, path_effects=halo)
    for polygon in features.sinks:
        xy = np.asarray(polygon) / 1e3
        xy = np.vstack([xy, xy[:1]])
        ax.plot(xy[:, 0], xy[:, 1], color="#7b3294", linewidth=1.2, linestyle="--", zorder=5)
    for gid, x, y in features.gauges:
        ax.plot(x / 1e3, y / 1e3, marker="^", color="#d7191c", markeredgecolor="k",
                markersize=7, linestyle="none", zorder=6)
        ax.annotate(gid, (x / 1e3, y / 1e3), xytext=(4, 4), textcoords="offset points",
                    fontsize=7, zorder=6)


def _frame(ax, title):
    ax.set_title(title)
    ax.set_xlabel("Easting [km]")
    ax.set_ylabel("Northing [km]")
    ax.ticklabel_format(useOffset=False, style="plain")


def scale_length(width_m: float) -> float:
    """A round length (1, 2 or 5 x 10^n m) of at most a fifth of the map width [m]."""
    target = width_m / 5.0
    power = 10.0 ** math.floor(math.log10(target))
    return max(s * power for s in (1, 2, 5) if s * power <= target)


def _scale_bar(ax, width_m):
    """A scale bar in the lower left corner (axes are in km)."""
    from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

    length = scale_length(width_m)
    label = f"{length / 1e3:g} km" if length >= 1e3 else f"{length:g} m"
    ax.add_artist(AnchoredSizeBar(ax.transData, length / 1e3, label, "lower left", pad=0.4,
                                  sep=3, frameon=True, size_vertical=0, fontproperties={
                                      "size": 8}))


def _extent(grid):
    """imshow extent in km of the world coordinates (for south-up arrays, origin='lower')."""
    return (grid.x0 / 1e3, (grid.x0 + grid.nx * grid.dx) / 1e3, grid.y0 / 1e3,
            (grid.y0 + grid.ny * grid.dy) / 1e3)


def _hillshade(ax, grid):
    from matplotlib.colors import LightSource

    shade = LightSource(azdeg=315, altdeg=45).hillshade(grid.bed[::-1], vert_exag=2.0,
                                                        dx=grid.dx, dy=grid.dy)
    ax.imshow(shade[::-1], cmap="gray", origin="lower", extent=_extent(grid), vmin=0, vmax=1,
              interpolation="nearest")


def _save(fig, path) -> Path:
    fig.savefig(path, bbox_inches="tight")
    return Path(path)


def time_unit(top_s: float) -> tuple[float, str]:
    """(seconds per unit, unit) for times up to ``top_s`` [s]: s below 2 min, min below 3 h,
    else h."""
    if top_s < 120.0:
        return 1.0, "s"
    if top_s < 3 * 3600.0:
        return 60.0, "min"
    return 3600.0, "h"


def write_pictures(envelopes, out_dir, title: str = "",
                   features: MapFeatures | None = None) -> list[Path] | str:
    """Write one PNG per map of :data:`PICTURES` (``<name>.png``) into ``out_dir``, with the
    walls, sinks, gauges and caption of ``features``."""
    if not have_matplotlib():
        return SKIPPED
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for name in PICTURES:
        fig = map_figure(envelopes, name, title, features)
        written.append(_save(fig, out_dir / f"{name}.png"))
    return written


def map_figure(envelopes, name: str, title: str = "", features: MapFeatures | None = None):
    """The Figure of the map ``name`` (one of :data:`PICTURES`) of the envelopes."""
    grid = envelopes.grid
    maps = envelopes.maps()
    prefix = f"{title}: " if title else ""
    if name in CLASSES:
        fig = _class_figure(grid, maps[name], envelopes.tables, name, prefix, features)
    elif name == "arrival_time":
        fig = _arrival_figure(grid, maps[name], prefix, features)
    elif name == "max_depth":
        fig = _depth_figure(grid, maps[name], envelopes.wet_threshold, prefix, features)
    else:
        fig = _continuous_figure(grid, maps, name, envelopes.wet_threshold, prefix, features)
    _draw_features(fig.axes[0], features)
    return fig


def _depth_figure(grid, max_depth, wet_threshold, prefix, features):
    """The maximum depth in the bands of :func:`floodsph.output.areas.depth_bands`, one
    colour each, the colour bar's bands of equal size whatever their depth range."""
    from matplotlib import colors

    from floodsph.output.areas import depth_bands

    bands = depth_bands(wet_threshold)
    top = bands[-1].lower * 2.0
    edges = [b.lower for b in bands] + [max(top, float(np.nanmax(max_depth, initial=0.0)))]
    cmap = colors.ListedColormap([b.colour for b in bands])
    fig, ax = _axes(grid, f"{prefix}{CONTINUOUS['max_depth'][0]}", features)
    wet = np.where(np.nan_to_num(max_depth) > wet_threshold, max_depth, np.nan)
    im = ax.imshow(np.ma.masked_invalid(wet), cmap=cmap, norm=colors.BoundaryNorm(edges, cmap.N),
                   origin="lower", extent=_extent(grid), alpha=0.9, interpolation="nearest")
    bar = fig.colorbar(im, ax=ax, label="maximum depth [m]", shrink=0.8, spacing="uniform",
                       ticks=edges[:-1])
    bar.ax.set_yticklabels([f"{e:g}" for e in edges[:-1]])
    return fig


def _continuous_figure(grid, maps, name, wet_threshold, prefix, features):
    label, cmap, units = CONTINUOUS[name]
    wet = np.nan_to_num(maps["max_depth"]) > wet_threshold
    values = np.where(wet, maps[name], np.nan)
    scale = 1.0
    if units is None:
        scale, units = time_unit(float(np.nanmax(values)) if wet.any() else 0.0)
    fig, ax = _axes(grid, f"{prefix}{label}", features)
    im = ax.imshow(np.ma.masked_invalid(values / scale), cmap=cmap, origin="lower",
                   extent=_extent(grid), alpha=0.85, interpolation="nearest", vmin=0.0)
    fig.colorbar(im, ax=ax, label=f"{label} [{units}]", shrink=0.8)
    return fig


def _class_figure(grid, classes, tables, name, prefix, features=None):
    """Class map with a legend of every class (wrapped names) beside the map."""
    from matplotlib import colors
    from matplotlib.patches import Patch

    from floodsph.output.hazard import ARR_COLOURS, UK_COLOURS

    names = tables.uk_names if name == "hazard_uk" else tables.arr_names
    rgb = [np.array(c) / 255.0 for c in (UK_COLOURS if name == "hazard_uk" else ARR_COLOURS)]
    k = len(names)
    fig, ax = _axes(grid, f"{prefix}{CLASSES[name]} (maximum)", features)
    cmap = colors.ListedColormap(rgb[1:k])
    ax.imshow(np.ma.masked_equal(classes, 0), cmap=cmap,
              norm=colors.BoundaryNorm(np.arange(0.5, k), cmap.N), origin="lower",
              extent=_extent(grid), interpolation="nearest")
    handles = [Patch(facecolor=rgb[c], edgecolor="0.3", label=textwrap.fill(names[c], 34))
               for c in range(1, k)]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8,
              title=f"{CLASSES[name]}\n(dry cells not shown)", title_fontsize=8,
              labelspacing=0.9, frameon=False)
    return fig


def _arrival_figure(grid, arrival_s, prefix, features=None):
    fig, ax = _axes(grid, f"{prefix}arrival time", features)
    if not np.isfinite(arrival_s).any():
        return fig
    top = float(np.nanmax(arrival_s))
    scale, units = time_unit(top)
    values = np.ma.masked_invalid(arrival_s / scale)
    im = ax.imshow(values, cmap="viridis_r", origin="lower", extent=_extent(grid), alpha=0.6,
                   interpolation="nearest")
    fig.colorbar(im, ax=ax, label=f"arrival time [{units}]", shrink=0.8)
    if top > 0:
        xc, yc = grid.world_centres()
        cs = ax.contour(xc / 1e3, yc[::-1] / 1e3, values, levels=nice_levels(top / scale),
                        colors="k", linewidths=0.8)
        ax.clabel(cs, fmt=f"%g {units}", fontsize=7)
    return fig


def write_probability_picture(grid, probability, path, title: str,
                              label: str = "probability") -> Path | str:
    """One PNG of a probability map (0..1, south-up) over the hillshade, cells of zero
    probability left clear, with the p = 0.5 contour; or the ``SKIPPED`` message."""
    if not have_matplotlib():
        return SKIPPED
    fig, ax = _axes(grid, title)
    p = np.ma.masked_where(~(np.nan_to_num(probability) > 0.0), probability)
    im = ax.imshow(p, cmap="YlOrRd", origin="lower", extent=_extent(grid), vmin=0.0, vmax=1.0,
                   alpha=0.85, interpolation="nearest")
    fig.colorbar(im, ax=ax, label=label, shrink=0.8)
    filled = np.nan_to_num(probability)
    if filled.min() < 0.5 < filled.max():
        xc, yc = grid.world_centres()
        ax.contour(xc / 1e3, yc[::-1] / 1e3, filled, levels=[0.5], colors="k",
                   linewidths=0.8, linestyles="--")
    return _save(fig, path)


def nice_levels(top: float) -> np.ndarray:
    """About 6 round contour levels between 0 and top."""
    raw = top / 6.0
    mag = 10.0 ** np.floor(np.log10(raw))
    step = min((s * mag for s in (1, 2, 5, 10) if s * mag >= raw), default=raw)
    return np.arange(step, top + 1e-9, step)


CATEGORIES = ("dry in both", "hit (wet in both)", "false alarm (model only)",
              "miss (reference only)")
CATEGORY_COLOURS = ("#f0f0f0", "#2b8cbe", "#e34a33", "#fdbb84")
"""Agreement categories 1-4 of :class:`floodsph.output.compare.Comparison` and their colours."""


def comparison_figure(result):
    """Two panels: agreement categories (legend below the panel) and the difference map."""
    from matplotlib import colors
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    m = result.model
    ny, nx = m.data.shape
    t = m.transform
    extent = (t.c / 1e3, (t.c + nx * t.a) / 1e3, (t.f + ny * t.e) / 1e3, t.f / 1e3)
    fig = Figure(figsize=(13.0, 6.0), dpi=110, layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    cmap = colors.ListedColormap(CATEGORY_COLOURS)
    ax1.imshow(np.ma.masked_equal(result.categories, 0), cmap=cmap,
               norm=colors.BoundaryNorm(np.arange(0.5, 5), cmap.N), extent=extent,
               interpolation="nearest")
    ax1.legend(handles=[Patch(facecolor=c, edgecolor="0.3", label=n)
                        for c, n in zip(CATEGORY_COLOURS, CATEGORIES, strict=True)],
               loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize=8,
               frameon=False)
    s = result.summary
    diff = result.difference
    lim = float(np.nanmax(np.abs(diff))) if np.isfinite(diff).any() else 1.0
    quantity = result.model.quantity
    units = "class" if quantity.classes else quantity.units
    im = ax2.imshow(diff, cmap="RdBu_r", vmin=-lim, vmax=lim, extent=extent,
                    interpolation="nearest")
    fig.colorbar(im, ax=ax2, label=f"model - reference [{units}]", shrink=0.8)
    _frame(ax1, f"wet/dry agreement: CSI = {s['csi']:.3f}, H = {s['hit_rate']:.3f}")
    _frame(ax2, f"{quantity.name} difference")
    for ax in (ax1, ax2):
        _scale_bar(ax, nx * abs(t.a))
    return fig


def plot_comparison(result, path) -> Path | str:
    """Write :func:`comparison_figure` to ``path``, or return the ``SKIPPED`` message."""
    if not have_matplotlib():
        return SKIPPED
    return _save(comparison_figure(result), path)


def write_series_pictures(gauge_rows, mass_rows, out_dir,
                          start: datetime | None = None) -> list[Path] | str:
    """``gauges.png`` (:func:`gauge_figure`, when there are gauge rows) and
    ``mass_balance.png`` (:func:`mass_balance_figure`) into ``out_dir``; or the ``SKIPPED``
    message."""
    if not have_matplotlib():
        return SKIPPED
    out_dir = Path(out_dir)
    written = []
    if gauge_rows:
        written.append(_save(gauge_figure(gauge_rows, start), out_dir / SERIES_PICTURES[0]))
    if mass_rows:
        written.append(_save(mass_balance_figure(mass_rows), out_dir / SERIES_PICTURES[1]))
    return written


def _time_axis(ax, top_s: float, start: datetime | None) -> float:
    """Label the x axis with the time unit for times up to ``top_s``; its seconds per unit."""
    from floodsph.output.gauges import utc_text

    scale, unit = time_unit(top_s)
    since = (f"time since {utc_text(start)[:16].replace('T', ' ')} UTC" if start is not None
             else "simulated time")
    ax.set_xlabel(f"{since} [{unit}]")
    return scale


def gauge_figure(rows, start: datetime | None = None):
    """Depth and water level over time at each gauge: two panels, one line per gauge (gaps
    while a gauge is dry). ``rows`` are ``(t, id, depth, level, speed)`` as gauges.csv."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 6.5), dpi=110, layout="constrained")
    depth_ax, level_ax = fig.subplots(2, 1, sharex=True)
    top = max(r[0] for r in rows)
    scale = _time_axis(level_ax, top, start)
    for gid in dict.fromkeys(r[1] for r in rows):
        mine = [r for r in rows if r[1] == gid]
        t = np.array([r[0] for r in mine]) / scale
        depth_ax.plot(t, [r[2] for r in mine], label=gid)
        level_ax.plot(t, [r[3] for r in mine], label=gid)
    if top > 0:
        level_ax.set_xlim(0.0, top / scale)
    if not any(math.isfinite(r[2]) for r in rows):
        depth_ax.text(0.5, 0.5, "every gauge stayed dry", transform=depth_ax.transAxes,
                      ha="center", va="center")
    depth_ax.set_ylabel("depth [m]")
    level_ax.set_ylabel("water level [m]")
    depth_ax.set_title("gauges: depth and water level (gaps: dry)")
    depth_ax.legend(fontsize=8, ncol=4, loc="upper left", title="gauge", title_fontsize=8)
    for ax in (depth_ax, level_ax):
        ax.grid(alpha=0.3)
    return fig


def mass_balance_figure(rows):
    """The water budget over time (volume in the domain, cumulative inflow and outflow) and
    its relative error. ``rows`` are those of ``mass_balance.csv``."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 6.0), dpi=110, layout="constrained")
    volume_ax, error_ax = fig.subplots(2, 1, sharex=True, height_ratios=(2, 1))
    rows = np.asarray(rows, dtype=np.float64)
    scale = _time_axis(error_ax, float(rows[:, 0].max()), None)
    t = rows[:, 0] / scale
    for column, label in ((1, "in the domain"), (2, "inflow (cumulative)"),
                          (3, "outflow (cumulative)")):
        volume_ax.plot(t, rows[:, column], label=label)
    volume_ax.set_ylabel("volume [m³]")
    volume_ax.set_title("mass balance")
    volume_ax.legend(fontsize=8)
    error_ax.plot(t, rows[:, 5], color="k")
    error_ax.set_ylabel("relative error [-]")
    error_ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3))
    for ax in (volume_ax, error_ax):
        ax.grid(alpha=0.3)
    return fig
