"""Quick-look PNGs of a run's maps (depth, speed, d·v, duration, hazard, arrival) and of an
ensemble's probability map.

matplotlib is optional (``floodsph[plot]``): without it every function returns the message
``"pictures skipped: matplotlib not installed"`` instead of paths. Figures are drawn with
``matplotlib.figure.Figure`` (no pyplot state, no GUI backend), north up, axes in km of the
map CRS, over a hillshade of the bed, with a title, a colour bar or legend with units, a
north arrow and a scale bar. The figure builders (``*_figure``) return the Figure, so that
its layout can be checked without writing a file.
"""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import numpy as np

SKIPPED = "pictures skipped: matplotlib not installed"

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


def _axes(grid, title):
    """Figure and axes sized to the map aspect, axes in km, north arrow and scale bar."""
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
    return fig, ax


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


def write_pictures(envelopes, out_dir, title: str = "") -> list[Path] | str:
    """Write one PNG per map of :data:`PICTURES` (``<name>.png``) into ``out_dir``."""
    if not have_matplotlib():
        return SKIPPED
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for name in PICTURES:
        written.append(_save(map_figure(envelopes, name, title), out_dir / f"{name}.png"))
    return written


def map_figure(envelopes, name: str, title: str = ""):
    """The Figure of the map ``name`` (one of :data:`PICTURES`) of the envelopes."""
    grid = envelopes.grid
    maps = envelopes.maps()
    prefix = f"{title}: " if title else ""
    if name in CLASSES:
        return _class_figure(grid, maps[name], envelopes.tables, name, prefix)
    if name == "arrival_time":
        return _arrival_figure(grid, maps[name], prefix)
    label, cmap, units = CONTINUOUS[name]
    wet = np.nan_to_num(maps["max_depth"]) > envelopes.wet_threshold
    values = np.where(wet, maps[name], np.nan)
    scale = 1.0
    if units is None:
        scale, units = time_unit(float(np.nanmax(values)) if wet.any() else 0.0)
    fig, ax = _axes(grid, f"{prefix}{label}")
    im = ax.imshow(np.ma.masked_invalid(values / scale), cmap=cmap, origin="lower",
                   extent=_extent(grid), alpha=0.85, interpolation="nearest", vmin=0.0)
    fig.colorbar(im, ax=ax, label=f"{label} [{units}]", shrink=0.8)
    return fig


def _class_figure(grid, classes, tables, name, prefix):
    """Class map with a legend of every class (wrapped names) beside the map."""
    from matplotlib import colors
    from matplotlib.patches import Patch

    from floodsph.output.hazard import ARR_COLOURS, UK_COLOURS

    names = tables.uk_names if name == "hazard_uk" else tables.arr_names
    rgb = [np.array(c) / 255.0 for c in (UK_COLOURS if name == "hazard_uk" else ARR_COLOURS)]
    k = len(names)
    fig, ax = _axes(grid, f"{prefix}{CLASSES[name]} (maximum)")
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


def _arrival_figure(grid, arrival_s, prefix):
    fig, ax = _axes(grid, f"{prefix}arrival time")
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
