"""Quick-look PNGs: max depth over a hillshade, hazard classes, arrival-time contours, and
an ensemble's probability map.

matplotlib is optional (``floodsph[plot]``): without it every function returns the message
``"pictures skipped: matplotlib not installed"`` instead of paths. Figures are drawn with
``matplotlib.figure.Figure`` (no pyplot state, no GUI backend), north up, axes in km of the
map CRS, with a title, a colour bar or legend with units, and a north arrow.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

SKIPPED = "pictures skipped: matplotlib not installed"


def _matplotlib():
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return None
    from matplotlib import colors
    from matplotlib.figure import Figure

    return Figure, colors


def _axes(Figure, grid, title):
    """Figure and axes sized to the map aspect, axes in km, north arrow."""
    aspect = (grid.ny * grid.dy) / (grid.nx * grid.dx)
    fig = Figure(figsize=(8.0, min(max(8.0 * aspect, 3.5), 11.0)), dpi=120)
    ax = fig.add_subplot()
    ax.set_title(title)
    ax.set_xlabel("Easting [km]")
    ax.set_ylabel("Northing [km]")
    ax.annotate("N", xy=(0.95, 0.95), xytext=(0.95, 0.83), xycoords="axes fraction",
                ha="center", va="center", fontsize=12, fontweight="bold",
                arrowprops={"arrowstyle": "-|>", "color": "k"})
    return fig, ax


def _extent(grid):
    """imshow extent in km of the world coordinates (for south-up arrays, origin='lower')."""
    return (grid.x0 / 1e3, (grid.x0 + grid.nx * grid.dx) / 1e3, grid.y0 / 1e3,
            (grid.y0 + grid.ny * grid.dy) / 1e3)


def _hillshade(ax, colors, grid):
    shade = colors.LightSource(azdeg=315, altdeg=45).hillshade(
        grid.bed[::-1], vert_exag=2.0, dx=grid.dx, dy=grid.dy)
    ax.imshow(shade[::-1], cmap="gray", origin="lower", extent=_extent(grid), vmin=0, vmax=1,
              interpolation="nearest")


def _save(fig, path) -> Path:
    fig.savefig(path, bbox_inches="tight")
    return Path(path)


def write_pictures(envelopes, out_dir, title: str = "") -> list[Path] | str:
    """Write ``max_depth.png``, ``hazard_uk.png``, ``hazard_arr.png``, ``arrival_time.png``."""
    mpl = _matplotlib()
    if mpl is None:
        return SKIPPED
    Figure, colors = mpl
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    grid = envelopes.grid
    maps = envelopes.maps()
    prefix = f"{title}: " if title else ""
    wet = np.nan_to_num(maps["max_depth"]) > envelopes.wet_threshold
    written = []

    fig, ax = _axes(Figure, grid, f"{prefix}maximum depth")
    _hillshade(ax, colors, grid)
    depth = np.ma.masked_where(~wet, maps["max_depth"])
    im = ax.imshow(depth, cmap="Blues", origin="lower", extent=_extent(grid), alpha=0.85,
                   interpolation="nearest", vmin=0.0)
    fig.colorbar(im, ax=ax, label="maximum depth [m]", shrink=0.8)
    written.append(_save(fig, out_dir / "max_depth.png"))

    tables = envelopes.tables
    from floodsph.output.hazard import ARR_COLOURS, UK_COLOURS

    for name, names, rgb, label in (
            ("hazard_uk", tables.uk_names, UK_COLOURS, "UK hazard rating class"),
            ("hazard_arr", tables.arr_names, ARR_COLOURS, "Australian hazard class")):
        fig, ax = _axes(Figure, grid, f"{prefix}{label} (maximum)")
        _hillshade(ax, colors, grid)
        k = len(names)
        cmap = colors.ListedColormap([np.array(c) / 255.0 for c in rgb[1:k]])
        norm = colors.BoundaryNorm(np.arange(0.5, k), cmap.N)
        cls = np.ma.masked_equal(maps[name], 0)
        im = ax.imshow(cls, cmap=cmap, norm=norm, origin="lower", extent=_extent(grid),
                       interpolation="nearest")
        bar = fig.colorbar(im, ax=ax, ticks=np.arange(1, k), shrink=0.8)
        bar.ax.set_yticklabels([_short(n) for n in names[1:]])
        bar.set_label(f"{label} (dry cells not shown)")
        written.append(_save(fig, out_dir / f"{name}.png"))

    fig, ax = _axes(Figure, grid, f"{prefix}arrival time")
    _hillshade(ax, colors, grid)
    minutes = maps["arrival_time"] / 60.0
    if np.isfinite(minutes).any():
        im = ax.imshow(np.ma.masked_invalid(minutes), cmap="viridis_r", origin="lower",
                       extent=_extent(grid), alpha=0.6, interpolation="nearest")
        fig.colorbar(im, ax=ax, label="arrival time [min]", shrink=0.8)
        top = float(np.nanmax(minutes))
        if top > 0:
            levels = _nice_levels(top)
            xc, yc = grid.world_centres()
            cs = ax.contour(xc / 1e3, yc[::-1] / 1e3, np.ma.masked_invalid(minutes),
                            levels=levels, colors="k", linewidths=0.8)
            ax.clabel(cs, fmt="%g min", fontsize=7)
    written.append(_save(fig, out_dir / "arrival_time.png"))
    return written


def write_probability_picture(grid, probability, path, title: str,
                              label: str = "probability") -> Path | str:
    """One PNG of a probability map (0..1, south-up) over the hillshade, cells of zero
    probability left clear, with the p = 0.5 contour; or the ``SKIPPED`` message."""
    mpl = _matplotlib()
    if mpl is None:
        return SKIPPED
    Figure, colors = mpl
    fig, ax = _axes(Figure, grid, title)
    _hillshade(ax, colors, grid)
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


def _short(name: str) -> str:
    """Class label for a legend, wrapped to lines of at most 32 characters."""
    return textwrap.fill(name, 32)


def _nice_levels(top: float) -> np.ndarray:
    """About 6 round contour levels between 0 and top."""
    raw = top / 6.0
    mag = 10.0 ** np.floor(np.log10(raw))
    step = min((s * mag for s in (1, 2, 5, 10) if s * mag >= raw), default=raw)
    return np.arange(step, top + 1e-9, step)


def plot_comparison(result, path) -> Path | str:
    """Two panels: agreement categories (hit / false alarm / miss) and the difference map."""
    mpl = _matplotlib()
    if mpl is None:
        return SKIPPED
    Figure, colors = mpl
    m = result.model
    ny, nx = m.data.shape
    t = m.transform
    extent = (t.c / 1e3, (t.c + nx * t.a) / 1e3, (t.f + ny * t.e) / 1e3, t.f / 1e3)
    fig = Figure(figsize=(13.0, 5.5), dpi=110)
    ax1, ax2 = fig.subplots(1, 2)
    cmap = colors.ListedColormap(["#f0f0f0", "#2b8cbe", "#e34a33", "#fdbb84"])
    norm = colors.BoundaryNorm(np.arange(0.5, 5), cmap.N)
    im = ax1.imshow(np.ma.masked_equal(result.categories, 0), cmap=cmap, norm=norm,
                    extent=extent, interpolation="nearest")
    bar = fig.colorbar(im, ax=ax1, ticks=[1, 2, 3, 4], shrink=0.8)
    bar.ax.set_yticklabels(["dry in both", "hit", "false alarm\n(model only)",
                            "miss\n(reference only)"])
    s = result.summary
    ax1.set_title(f"wet/dry agreement: CSI = {s['csi']:.3f}, H = {s['hit_rate']:.3f}")
    diff = result.difference
    lim = float(np.nanmax(np.abs(diff))) if np.isfinite(diff).any() else 1.0
    units = "s" if s["kind"] == "arrival" else ("class" if s["kind"] == "class" else "m")
    im = ax2.imshow(diff, cmap="RdBu_r", vmin=-lim, vmax=lim, extent=extent,
                    interpolation="nearest")
    fig.colorbar(im, ax=ax2, label=f"model - reference [{units}]", shrink=0.8)
    ax2.set_title(f"{s['kind']} difference")
    for ax in (ax1, ax2):
        ax.set_xlabel("Easting [km]")
        ax.set_ylabel("Northing [km]")
    return _save(fig, path)
