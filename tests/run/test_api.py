"""The public Python API (docs/api.md): lazy root imports, and the page's example run on the
test valley, with facts checked on its result."""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import CELL, CRS, NX, NY, RESERVOIR_VOLUME_M3, X0, Y0

import floodsph

DOCS = Path(__file__).parents[2] / "docs" / "api.md"


def python_block(page: Path) -> str:
    """The one fenced ```python block of ``page``."""
    blocks = re.findall(r"^```python\n(.*?)^```$", page.read_text(encoding="utf-8"),
                        flags=re.S | re.M)
    assert len(blocks) == 1, f"{page} should hold one python example, holds {len(blocks)}"
    return blocks[0]


def test_import_loads_nothing_heavy():
    code = ("import sys, floodsph; floodsph.__version__; "
            "print(sorted(m for m in ('numba', 'xarray', 'rasterio', 'numpy') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"


def test_public_names():
    from floodsph.scenario.config import Scenario
    from floodsph.scenario.reader import load_scenario

    assert floodsph.load_scenario is load_scenario and floodsph.Scenario is Scenario
    assert {"load_scenario", "run_scenario", "Scenario", "RunResult", "open_run",
            "__version__"} <= set(dir(floodsph))
    assert re.fullmatch(r"\d+\.\d+\.\d+\S*", floodsph.__version__)
    with pytest.raises(AttributeError, match="no attribute 'run_scenarios'"):
        floodsph.run_scenarios  # noqa: B018


def test_docs_example_on_the_valley(scenario_file, monkeypatch):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(scenario_file.parent)
    namespace: dict = {}
    exec(compile(python_block(DOCS), str(DOCS), "exec"), namespace)
    result, maps = namespace["result"], namespace["maps"]

    assert result.status == "completed"
    assert result.folder == (scenario_file.parent / "out" / "valley").resolve()
    assert (result.folder / "run.json").is_file()
    # Closed valley at rest: the basin's 40 000 m3 seeded, and still there at the end.
    m = result.manifest
    assert math.isclose(m["volume_initial_m3"], RESERVOIR_VOLUME_M3, rel_tol=1e-9)
    assert m["volume_in_m3"] == 0.0 and m["volume_out_m3"] == 0.0
    assert math.isclose(m["volume_domain_m3"], RESERVOIR_VOLUME_M3, rel_tol=1e-9)
    # The maps on the DEM's grid and CRS, cell centres north to south.
    import pyproj

    assert maps["max_depth"].shape == (NY, NX)
    assert pyproj.CRS.from_wkt(maps["crs"].attrs["crs_wkt"]) == pyproj.CRS(CRS)
    assert result.crs == pyproj.CRS(CRS)
    assert np.allclose(maps.x, X0 + CELL * (np.arange(NX) + 0.5))
    assert np.allclose(maps.y, Y0 + CELL * (NY - 0.5 - np.arange(NY)))
    # Water 2 m deep in the basin (the western 100 m): its maximum over the run stays near
    # 2 m (the particles settle against the walls at the start); the floor east of it dry.
    basin = maps["max_depth"].sel(x=slice(X0 + 30, X0 + 70), y=slice(Y0 + 150, Y0 + 50))
    assert basin.min() >= 1.9 and basin.max() <= 2.5
    assert not np.any(maps["max_depth"].sel(x=slice(X0 + 200, None)) > 0.1)

    # open_run reads the same folder back; without flood_maps.nc the GeoTIFFs give the
    # same maps on the same coordinates.
    again = floodsph.open_run(result.folder)
    assert again.manifest == m
    (result.folder / "flood_maps.nc").unlink()
    tif_maps = again.maps()
    assert np.array_equal(tif_maps["max_depth"], maps["max_depth"], equal_nan=True)
    assert np.array_equal(tif_maps["hazard_uk"], maps["hazard_uk"])
    assert np.allclose(tif_maps.y, maps.y) and again.crs == pyproj.CRS(CRS)


def test_open_run_refuses_a_folder_without_run_json(tmp_path):
    with pytest.raises(floodsph.InputError, match=f"{tmp_path}: not a floodsph run folder"):
        floodsph.open_run(tmp_path)
