"""The shipped sample ``data_samples/valley``: ``floodsph check`` and a 20-step ``floodsph run``.

The reservoir is the DEM cells upstream of the dam line (inside the ``[[initial_water]]``
polygon) whose bed lies below the 234 m level: one particle per 10 m cell, and the deepest
still water is 234 m minus the lowest bed there (11.9 m, data_samples/valley/README.md). In
20 steps (a few seconds of flow) the dam-break wave travels a few tens of metres from the dam
line, far from the open east edge 2.1 km away, so no water leaves and the mass budget is closed.
"""

from __future__ import annotations

import json
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from floodsph.cli.main import cli

SAMPLE = Path(__file__).resolve().parents[2] / "data_samples" / "valley"
SCENARIO = SAMPLE / "scenario.toml"
DEM = SAMPLE / "dem.tif"
MAX_STEPS = 20


def _reservoir() -> tuple[np.ndarray, np.ndarray, float]:
    """The DEM's bed [m] (row 0 = north), its reservoir cells (centre inside the polygon,
    below the level) and the level [m]."""
    import rasterio

    water = tomllib.loads(SCENARIO.read_text())["initial_water"][0]
    xs, ys = zip(*water["polygon"], strict=True)
    with rasterio.open(DEM) as src:
        bed = src.read(1)
        rows, cols = np.indices(bed.shape)
        x, y = rasterio.transform.xy(src.transform, rows.ravel(), cols.ravel())
    x = np.asarray(x).reshape(bed.shape)
    y = np.asarray(y).reshape(bed.shape)
    # The polygon is an axis-aligned rectangle on cell edges: no centre lies on its boundary.
    inside = (x > min(xs)) & (x < max(xs)) & (y > min(ys)) & (y < max(ys))
    return bed, inside & (bed < water["level_m"]), water["level_m"]


def _reservoir_beds() -> tuple[np.ndarray, float]:
    """Bed [m] of the reservoir cells, level [m]."""
    bed, wet, level = _reservoir()
    return bed[wet], level


@pytest.fixture(scope="module")
def sample_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("sample") / "out"
    result = CliRunner().invoke(
        cli, ["-q", "run", str(SCENARIO), "--max-steps", str(MAX_STEPS), "--output", str(out)]
    )
    return result, out


def test_check_prints_one_particle_per_wet_cell():
    """One particle per reservoir cell at the DEM spacing, less the thin shore cells lumped
    into deeper neighbours (``floodsph.inputs.initial_water.lump_thin_cells``)."""
    from floodsph.inputs.initial_water import lump_thin_cells

    bed, wet, level = _reservoir()
    depth = np.where(wet, level - bed, 0.0)[::-1]  # row 0 = south, as the terrain's grid
    result = CliRunner().invoke(cli, ["check", str(SCENARIO)])
    assert result.exit_code == 0, result.output
    match = re.search(r"^Particles:\s+(\d+)$", result.output, flags=re.MULTILINE)
    assert match is not None, result.output
    assert np.count_nonzero(wet) == 2924
    assert int(match.group(1)) == np.count_nonzero(lump_thin_cells(depth) > 1e-3)


def test_run_completes_the_asked_steps_with_closed_mass_budget(sample_run):
    """The sample takes local time steps (the default): ``--max-steps`` counts finest steps
    and stops at the end of the big step that holds the last, at most 2^step_levels - 1
    later."""
    result, out = sample_run
    assert result.exit_code == 0, result.output
    run = json.loads((out / "run.json").read_text())
    numerics = run["scenario"]["numerics"]
    assert run["status"] == "stopped" and numerics["time_stepping"] == "local"
    assert MAX_STEPS <= run["steps"] < MAX_STEPS + 2 ** numerics["step_levels"]
    assert run["end_time_reached"] is False
    assert 0.0 < run["sim_time_s"] < run["scenario"]["scenario"]["end_time_s"]
    # Nothing has reached the open edge yet: no outflow, so the volume must be exactly kept.
    assert run["volume_out_m3"] == 0.0
    assert run["mass_error_rel"] < 1e-9


def test_max_depth_map_georeferenced_and_reservoir_deep(sample_run):
    import rasterio

    _, out = sample_run
    beds, level = _reservoir_beds()
    deepest = level - float(beds.min())
    assert 11.0 < deepest < 12.5  # the DEM, as the sample README describes it
    with rasterio.open(out / "max_depth.tif") as tif, rasterio.open(DEM) as dem:
        assert tif.crs.to_epsg() == 32632
        assert tif.transform.almost_equals(dem.transform)
        assert tif.shape == dem.shape
        depth = tif.read(1)
    top = float(np.nanmax(depth))
    assert 5.0 < top < 15.0
    assert abs(top - deepest) < 1.0


def test_netcdf_is_cf_and_pictures_listed(sample_run):
    import xarray as xr

    _, out = sample_run
    with xr.open_dataset(out / "flood_maps.nc") as ds:
        assert ds.attrs["Conventions"] == "CF-1.8"
    pictures = json.loads((out / "run.json").read_text())["pictures"]
    if isinstance(pictures, str):
        assert pictures.startswith("skipped: ")
    else:
        assert "max_depth.png" in pictures
        assert all((out / name).stat().st_size > 0 for name in pictures)
