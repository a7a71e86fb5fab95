"""``report.html``: one self-contained page that sums a run up for the people who commission a
flood study.

The page holds, in this order: the run (status, calendar start, CRS, timings, particles); the
flooded area by maximum-depth band and by hazard class (UK and Australian), each row with its
colour; the peak depth and level, their time and the arrival time at each gauge; the mass
balance; the maps (maximum depth in bands, hazard classes, arrival time, maximum speed) with
the walls, sinks and gauges drawn, the gauge hydrographs and the mass-balance plot; and the
run's settings. It is one file: pictures are embedded as base64 ``data:`` URIs, the style is
inline, and nothing is fetched from a network, so it can be mailed or archived as it is.

The pictures are the run's quick-look PNGs (:mod:`floodsph.output.pictures`). Without
matplotlib (the ``plot`` extra) the page is still written, with every table and a line
saying that the pictures were left out and how to get them.
"""

from __future__ import annotations

import base64
import html
import math
from datetime import datetime
from pathlib import Path

import numpy as np

from floodsph.output.areas import AreaRow, area_by_class, area_by_depth

MAP_PICTURES = (("max_depth.png", "Maximum depth"),
                ("hazard_uk.png", "UK flood hazard rating (maximum over time)"),
                ("hazard_arr.png", "Australian flood hazard class (maximum over time)"),
                ("arrival_time.png", "Arrival time"),
                ("max_speed.png", "Maximum speed"))
"""The map pictures the page shows, with their headings."""
NO_PICTURES = ("The pictures were left out: matplotlib is not installed "
               "(<code>pip install 'floodsph[plot]'</code> adds it). The tables are complete.")

STYLE = """
body { font-family: sans-serif; margin: 2em auto; max-width: 1100px; color: #222; }
h1 { margin-bottom: 0.2em; } h2 { border-bottom: 1px solid #bbb; margin-top: 1.6em; }
table { border-collapse: collapse; margin: 0.6em 0; }
th, td { border: 1px solid #ccc; padding: 4px 10px; text-align: left; }
td.n { text-align: right; font-variant-numeric: tabular-nums; }
td.swatch { width: 70px; min-width: 70px; height: 22px; }
p.note { background: #fff4d6; border: 1px solid #e0b64b; padding: 6px 10px; }
figure { margin: 1em 0; } figcaption { font-weight: bold; margin-bottom: 0.3em; }
img { max-width: 100%; border: 1px solid #ddd; }
"""


def write_report(path, *, manifest: dict, envelopes, caption: str, gauge_rows=(),
                 mass_rows=(), start: datetime | None = None, pictures=None) -> Path:
    """Write the page (see the module docstring) to ``path``.

    Parameters
    ----------
    manifest : dict
        ``run.json`` as it will be written (status, timings, volumes, the resolved scenario).
    envelopes : Envelopes
        The run's maps, their grid and hazard tables.
    caption : str
        Where and when the maps are (:func:`floodsph.output.pictures.map_caption`).
    gauge_rows, mass_rows : sequences of tuples
        The rows of ``gauges.csv`` and ``mass_balance.csv``.
    start : datetime, optional
        The calendar instant of t = 0.
    pictures : path-like or None
        The folder holding the quick-look PNGs to embed; None when they were not drawn
        (no matplotlib): the page says so.
    """
    path = Path(path)
    sections = [_run_section(manifest, caption, start),
                _area_section(envelopes),
                _gauge_section(gauge_rows, start),
                _mass_section(manifest),
                _picture_section(pictures),
                _settings_section(manifest.get("scenario", {}))]
    name = html.escape(str(manifest.get("scenario", {}).get("scenario", {}).get("name", "")))
    page = (f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
            f"<title>floodsph run report: {name}</title>\n<style>{STYLE}</style>\n</head>\n"
            f"<body>\n<h1>Flood run report: {name}</h1>\n" + "\n".join(sections)
            + "\n</body>\n</html>\n")
    path.write_text(page, encoding="utf-8")
    return path


def _table(header, rows, numeric=()) -> str:
    """An HTML table; cells are escaped text, except ``("swatch", colour)`` cells."""
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = []
    for row in rows:
        cells = []
        for k, cell in enumerate(row):
            if isinstance(cell, tuple) and cell[0] == "swatch":
                cells.append(f'<td class="swatch" style="background:{cell[1]}"></td>')
            else:
                css = ' class="n"' if k in numeric else ""
                cells.append(f"<td{css}>{html.escape(str(cell))}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    return f"<table>\n<tr>{head}</tr>\n" + "\n".join(body) + "\n</table>"


def _number(value, spec: str = ",.1f") -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return format(value, spec)


def _when(start: datetime | None, t: float) -> str:
    """Simulated time ``t`` [s] and, with a start, its calendar instant in UTC."""
    from datetime import timedelta

    from floodsph.output.gauges import utc_text

    text = f"{t:,.0f} s"
    if start is not None:
        text += f" ({utc_text(start + timedelta(seconds=t))[:19].replace('T', ' ')} UTC)"
    return text


def _run_section(manifest: dict, caption: str, start: datetime | None) -> str:
    info = manifest.get("scenario", {}).get("scenario", {})
    wall = manifest.get("wall_time_s") or 0.0
    sim = manifest.get("sim_time_s") or 0.0
    rows = [
        ("status", manifest.get("status", "")),
        ("description", info.get("description", "")),
        ("calendar start (t = 0)", start.isoformat() if start is not None
         else "none given ([scenario] start): times are seconds from the start of the run"),
        ("simulated time", f"{sim:,.1f} s of {info.get('end_time_s', float('nan')):,.1f} s"),
        ("maps", caption),
        ("run started / finished (UTC)", f"{manifest.get('started')} / "
                                         f"{manifest.get('finished')}"),
        ("wall time", f"{wall:,.1f} s ({sim / wall:,.2f} s simulated per second)"
         if wall > 0 else "-"),
        ("time steps", f"{manifest.get('steps', 0):,}"),
        ("threads", manifest.get("threads", "")),
        ("particles (initial / most / final)", f"{manifest.get('particles_initial', 0):,} / "
                                                f"{manifest.get('particles_max', 0):,} / "
                                                f"{manifest.get('particles_final', 0):,}"),
        ("particle spacing", f"{manifest.get('particle_spacing_m', float('nan')):g} m"),
        ("floodsph version", manifest.get("floodsph_version", "")),
    ]
    warnings = manifest.get("warnings") or []
    notes = "".join(f'<p class="note">Warning: {html.escape(w)}</p>' for w in warnings)
    return "<h2>The run</h2>\n" + _table(("", ""), rows) + notes


def _area_rows(rows: list[AreaRow]) -> list[tuple]:
    total = sum(r.area_m2 for r in rows)
    return [(("swatch", r.colour), r.label, f"{r.cells:,}", _number(r.area_m2 / 1e4, ",.2f"),
             _number(100.0 * r.area_m2 / total if total else float("nan"), ".1f"))
            for r in rows] + [("", "total", f"{sum(r.cells for r in rows):,}",
                               _number(total / 1e4, ",.2f"), "100.0" if total else "-")]


def _area_section(envelopes) -> str:
    from floodsph.output.hazard import ARR_COLOURS, UK_COLOURS

    grid = envelopes.grid
    maps = envelopes.maps()
    cell = grid.dx * grid.dy
    header = ("colour", "class", "cells", "area [ha]", "share of the flooded area [%]")
    numeric = (2, 3, 4)
    # binned as the map files hold it (float32): a depth on a band's edge, as a lake at rest
    # has, falls in the same band in the table as in max_depth.tif
    depth = area_by_depth(np.asarray(maps["max_depth"], dtype=np.float32), cell,
                          envelopes.wet_threshold)
    uk = area_by_class(maps["hazard_uk"], envelopes.tables.uk_names, UK_COLOURS, cell)
    arr = area_by_class(maps["hazard_arr"], envelopes.tables.arr_names, ARR_COLOURS, cell)
    return ("<h2>Flooded area</h2>\n"
            f"<p>Cells of {grid.dx:g} m x {grid.dy:g} m wet above "
            f"{envelopes.wet_threshold:g} m at some time, by their maximum over the run.</p>\n"
            "<h3>By maximum depth</h3>\n" + _table(header, _area_rows(depth), numeric)
            + "\n<h3>By UK flood hazard rating (Defra/EA FD2320)</h3>\n"
            + _table(header, _area_rows(uk), numeric)
            + "\n<h3>By Australian flood hazard class (AIDR 7-3)</h3>\n"
            + _table(header, _area_rows(arr), numeric))


def gauge_summary(rows) -> list[dict]:
    """Per gauge, in file order: the first wet time (arrival), the peak depth and level and
    the time of the peak depth [s]; None while a gauge never got wet. ``rows`` are
    ``(t, id, depth, level, speed)`` with NaN when dry (gauges.csv)."""
    out: dict[str, dict] = {}
    for t, gid, depth, level, _ in rows:
        g = out.setdefault(gid, {"id": gid, "arrival_s": None, "peak_depth_m": None,
                                 "peak_level_m": None, "peak_time_s": None})
        if not math.isfinite(depth):
            continue
        if g["arrival_s"] is None:
            g["arrival_s"] = t
        if g["peak_depth_m"] is None or depth > g["peak_depth_m"]:
            g["peak_depth_m"], g["peak_time_s"] = depth, t
        if g["peak_level_m"] is None or level > g["peak_level_m"]:
            g["peak_level_m"] = level
    return list(out.values())


def _gauge_section(rows, start: datetime | None) -> str:
    if not rows:
        return "<h2>Gauges</h2>\n<p>The scenario has no gauges ([gauges]).</p>"
    table = []
    for g in gauge_summary(rows):
        if g["arrival_s"] is None:
            table.append((g["id"], "dry throughout", "-", "-", "-"))
            continue
        table.append((g["id"], _when(start, g["arrival_s"]), _number(g["peak_depth_m"], ".3f"),
                      _number(g["peak_level_m"], ".3f"), _when(start, g["peak_time_s"])))
    return ("<h2>Gauges</h2>\n" + _table(("gauge", "arrival (first wet)", "peak depth [m]",
                                          "peak level [m]", "time of the peak depth"),
                                         table, numeric=(2, 3)))


def _mass_section(manifest: dict) -> str:
    keys = (("initial volume", "volume_initial_m3"), ("inflow", "volume_in_m3"),
            ("outflow", "volume_out_m3"), ("in the domain at the end", "volume_domain_m3"))
    rows = [(label, _number(manifest.get(key), ",.1f")) for label, key in keys]
    error = manifest.get("mass_error_rel")
    rows.append(("relative error of the balance", "-" if error is None else f"{error:.2e}"))
    return ("<h2>Mass balance</h2>\n<p>Volumes in m³; error = in the domain - (initial + "
            "inflow - outflow), relative to initial + inflow.</p>\n"
            + _table(("", "m³"), rows, numeric=(1,)))


def _picture_section(folder) -> str:
    from floodsph.output.pictures import SERIES_PICTURES

    if folder is None:
        return f'<h2>Maps and plots</h2>\n<p class="note">{NO_PICTURES}</p>'
    folder = Path(folder)
    shown = [*MAP_PICTURES, (SERIES_PICTURES[0], "Gauge hydrographs"),
             (SERIES_PICTURES[1], "Mass balance")]
    figures = []
    for name, heading in shown:
        png = folder / name
        if png.is_file():
            data = base64.b64encode(png.read_bytes()).decode("ascii")
            figures.append(f"<figure><figcaption>{html.escape(heading)}</figcaption>"
                           f'<img alt="{html.escape(heading)}" '
                           f'src="data:image/png;base64,{data}"></figure>')
    return ("<h2>Maps and plots</h2>\n<p>Walls are black lines, sinks dashed purple outlines, "
            "gauges red triangles.</p>\n" + "\n".join(figures))


def _settings_section(scenario: dict) -> str:
    rows = []
    for table in ("scenario", "terrain", "numerics", "output"):
        for key, value in (scenario.get(table) or {}).items():
            if isinstance(value, dict | list):
                continue
            rows.append((f"{table}.{key}", value))
    counts = [(f"[[{table}]] entries", len(scenario.get(table) or []))
              for table in ("initial_water", "walls", "inflows", "sinks")]
    gauges = scenario.get("gauges")
    if gauges:
        rows.append(("gauges.file", gauges.get("file", "")))
    return "<h2>Settings</h2>\n" + _table(("key", "value"), rows + counts)
