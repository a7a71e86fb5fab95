"""``report.html``: a small dam break with a wall, a sink and two gauges, run twice (with and
without matplotlib); the page's tables against the run's own files, its self-containedness,
and a screenshot of it in a real headless browser (Chromium), skipped where none is installed.

The run: the conftest valley (400 m x 200 m, 10 m cells, EPSG:32632) with water at level
101 m held in its western 200 m, released at t = 0 onto the dry floor, 6 s, a calendar start.
"""

from __future__ import annotations

import base64
import csv
import html
import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import rasterio
from conftest import CELL, NY, X0, Y0, valley_elevation, write_geotiff

from floodsph.output.areas import DEPTH_COLOURS, area_by_depth, depth_bands, hex_colour
from floodsph.output.hazard import UK_COLOURS
from floodsph.run.pipeline import run_scenario
from floodsph.scenario.reader import load_scenario

END_S, DAM_M, WET_M = 6.0, 200.0, 0.02
SCENARIO = f"""
[scenario]
name = "report"
end_time_s = {END_S}
start = 2024-01-15T06:00:00Z
description = "dam break onto a dry floor"

[terrain]
dem = "dem.tif"
manning = 0.03
edges = "closed"

[[initial_water]]
level_m = 101.0
polygon = [[{X0}, {Y0}], [{X0 + DAM_M}, {Y0}], [{X0 + DAM_M}, {Y0 + NY * CELL}],
           [{X0}, {Y0 + NY * CELL}]]

[[walls]]
polyline = [[{X0 + 300}, {Y0 + 20}], [{X0 + 300}, {Y0 + 80}]]

[[sinks]]
polygon = [[{X0 + 370}, {Y0}], [{X0 + 400}, {Y0}], [{X0 + 400}, {Y0 + 200}],
           [{X0 + 370}, {Y0 + 200}]]

[gauges]
file = "gauges.csv"
interval_s = 1.0

[numerics]
particle_spacing_m = 10.0
refinement = "none"

[output]
wet_threshold_m = {WET_M}
"""


def run(folder: Path) -> Path:
    write_geotiff(folder / "dem.tif", valley_elevation())
    (folder / "scenario.toml").write_text(SCENARIO)
    (folder / "gauges.csv").write_text(f"id,x,y\nbasin,{X0 + 50},{Y0 + 100}\n"
                                       f"far,{X0 + 390},{Y0 + 190}\n")
    manifest = run_scenario(load_scenario(folder / "scenario.toml"), folder / "out",
                            progress=False)
    assert manifest["status"] == "completed"
    return folder / "out"


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    pytest.importorskip("matplotlib")
    return run(tmp_path_factory.mktemp("report"))


@pytest.fixture(scope="module")
def run_without_matplotlib(tmp_path_factory) -> Path:
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr("floodsph.output.pictures.have_matplotlib", lambda: False)
        return run(tmp_path_factory.mktemp("report-no-plot"))


def tables(page: str) -> dict[str, list[list[str]]]:
    """The page's tables under their headings (h2/h3 text), as rows of cell texts."""
    out = {}
    for heading, body in re.findall(r"<h[23]>([^<]*)</h[23]>\s*(?:<p>[^<]*</p>\s*)?<table>"
                                    r"(.*?)</table>", page, flags=re.S):
        rows = re.findall(r"<tr>(.*?)</tr>", body, flags=re.S)
        out[html.unescape(heading)] = [
            [html.unescape(c) for c in re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", r)]
            for r in rows]
    return out


def test_depth_and_hazard_areas_are_those_of_the_maps(run_dir):
    page = (run_dir / "report.html").read_text(encoding="utf-8")
    found = tables(page)
    with rasterio.open(run_dir / "max_depth.tif") as src:
        depth = src.read(1)
    cell = CELL * CELL
    expected = area_by_depth(depth, cell, WET_M)
    rows = found["By maximum depth"]
    assert [r[1] for r in rows[1:-1]] == [b.label for b in depth_bands(WET_M)]
    assert [int(r[2].replace(",", "")) for r in rows[1:-1]] == [e.cells for e in expected]
    flooded_ha = np.count_nonzero(np.nan_to_num(depth) > WET_M) * cell / 1e4
    assert rows[-1][1] == "total" and float(rows[-1][3]) == pytest.approx(flooded_ha, abs=0.01)
    assert flooded_ha > 2.0                      # the basin's 200 m x 200 m and more
    with rasterio.open(run_dir / "hazard_uk.tif") as src:
        uk = src.read(1)
    uk_rows = found["By UK flood hazard rating (Defra/EA FD2320)"]
    assert [int(r[2].replace(",", "")) for r in uk_rows[1:-1]] == [
        int(np.count_nonzero(uk == k)) for k in range(1, 5)]
    # Each row's colour is the one of its band in the quick-look and of its class in the map.
    assert f"background:{depth_bands(WET_M)[0].colour}" in page
    assert f"background:{hex_colour(UK_COLOURS[1])}" in page


def test_gauges_mass_balance_start_and_crs_are_stated(run_dir):
    page = (run_dir / "report.html").read_text(encoding="utf-8")
    found = tables(page)
    with open(run_dir / "gauges.csv", newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["id"] == "basin"]
    peak = max(float(r["depth_m"]) for r in rows)
    gauge_rows = {r[0]: r for r in found["Gauges"][1:]}
    assert float(gauge_rows["basin"][2]) == pytest.approx(peak, abs=5e-4)
    assert gauge_rows["basin"][1] == "0 s (2024-01-15 06:00:00 UTC)"       # wet from the start
    assert gauge_rows["far"][1] == "dry throughout"
    manifest = json.loads((run_dir / "run.json").read_text())
    assert manifest["report"] == "report.html"
    mass = dict(found["Mass balance"][1:])
    assert float(mass["initial volume"].replace(",", "")) == pytest.approx(
        manifest["volume_initial_m3"], abs=0.1)
    run_rows = dict((r[0], r[1]) for r in found["The run"][1:])
    assert run_rows["calendar start (t = 0)"] == "2024-01-15T06:00:00+00:00"
    assert "EPSG:32632" in run_rows["maps"] and "2024-01-15 06:00 UTC" in run_rows["maps"]
    assert run_rows["status"] == "completed"


def test_the_page_is_self_contained_with_every_picture_embedded(run_dir):
    page = (run_dir / "report.html").read_text(encoding="utf-8")
    assert not re.search(r"https?://|<link|<script|@import|url\(", page)
    sources = re.findall(r'<img [^>]*src="([^"]*)"', page)
    assert len(sources) == 7                     # five maps, the gauges and the mass balance
    for src in sources:
        assert src.startswith("data:image/png;base64,")
        assert base64.b64decode(src.split(",", 1)[1])[:8] == b"\x89PNG\r\n\x1a\n"
    from floodsph.io.run_names import SERIES_PICTURE_NAMES
    from floodsph.output.pictures import SERIES_PICTURES

    assert SERIES_PICTURES == SERIES_PICTURE_NAMES
    assert set(SERIES_PICTURE_NAMES) <= set(json.loads(
        (run_dir / "run.json").read_text())["pictures"])


def test_without_matplotlib_the_tables_are_written_and_the_page_says_so(run_without_matplotlib):
    page = (run_without_matplotlib / "report.html").read_text(encoding="utf-8")
    assert "<img" not in page and "matplotlib is not installed" in page
    found = tables(page)
    assert found["By maximum depth"][-1][1] == "total" and "Gauges" in found
    manifest = json.loads((run_without_matplotlib / "run.json").read_text())
    assert manifest["report"] == ("report.html (tables only: skipped: matplotlib not "
                                  "installed)")
    assert not list(run_without_matplotlib.glob("*.png"))


def browser() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        if shutil.which(name):
            return shutil.which(name)
    return None


def screenshot(page: Path, png: Path, width: int, height: int) -> np.ndarray:
    """The page as a headless Chromium draws it, as (height, width, 3) uint8 RGB; the browser
    runs offline (no proxy, no network services)."""
    from matplotlib.image import imread

    chromium = browser()
    if chromium is None:
        pytest.skip("no Chromium installed (Debian: apt-get install chromium)")
    subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu",
                    "--hide-scrollbars", "--no-proxy-server", "--disable-background-networking",
                    f"--window-size={width},{height}", f"--screenshot={png}",
                    page.as_uri()], check=True, capture_output=True, timeout=120)
    return (imread(png)[:, :, :3] * 255).round().astype(np.uint8)


def colour_pixels(image: np.ndarray, colour: str) -> int:
    rgb = [int(colour[k:k + 2], 16) for k in (1, 3, 5)]
    return int(np.count_nonzero(np.all(image == rgb, axis=2)))


@pytest.mark.parametrize("which", ["run_dir", "run_without_matplotlib"])
def test_a_browser_draws_the_tables_colours_and_the_maps(which, request, tmp_path):
    """Chromium's screenshot of the page: the page's size, not blank, each depth band's and
    a hazard class's colour swatch drawn (70 x 22 px each), and with matplotlib many more
    colours (the embedded maps) than without."""
    folder = request.getfixturevalue(which)
    image = screenshot(folder / "report.html", tmp_path / "shot.png", 1200, 2600)
    assert image.shape == (2600, 1200, 3)
    assert len(np.unique(image.reshape(-1, 3), axis=0)) > 20         # not a blank page
    depth_rows = area_by_depth(_depth(folder), CELL * CELL, WET_M)
    for row in depth_rows:
        assert colour_pixels(image, row.colour) >= 60 * 15, row.label
    assert colour_pixels(image, hex_colour(UK_COLOURS[1])) >= 60 * 15
    assert DEPTH_COLOURS[0] == depth_bands(WET_M)[0].colour
    if which == "run_dir":
        full = screenshot(folder / "report.html", tmp_path / "full.png", 1200, 9000)
        assert len(np.unique(full.reshape(-1, 3), axis=0)) > 2000   # the embedded pictures


def _depth(folder: Path) -> np.ndarray:
    with rasterio.open(folder / "max_depth.tif") as src:
        return src.read(1)
