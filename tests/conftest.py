"""Shared fixtures: a tiny GeoTIFF valley with a reservoir and scenario files around it.

The DEM (``valley_dem``) is 40 x 20 cells of 10 m in EPSG:32632 with its lower-left corner at
world (500000, 4000000): a flat floor at 100 m with a 2 m deep reservoir basin (bed 98 m) in
its western 100 m. ``[[initial_water]]`` at level 100 m over the whole DEM therefore holds
exactly 100 m x 200 m x 2 m = 40 000 m3, all in the basin.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

X0, Y0 = 500_000.0, 4_000_000.0
CELL = 10.0
NX, NY = 40, 20
BASIN_COLS = 10
RESERVOIR_VOLUME_M3 = BASIN_COLS * CELL * NY * CELL * 2.0
CRS = "EPSG:32632"

TESTS = Path(__file__).resolve().parent
"""The tests' root: its helper modules (``sph_cases``, ``golden_cases``, ``ensemble_cases``,
this one) are imported by the test modules in the folders below, which mirror the package."""
if str(TESTS) not in sys.path:
    sys.path.insert(0, str(TESTS))


def write_geotiff(path: Path, z: np.ndarray, *, x0=X0, y0=Y0, cell=CELL, crs=CRS, nodata=-9999.0):
    """Write a north-up float32 GeoTIFF whose lower-left corner is (x0, y0)."""
    import rasterio
    from rasterio.transform import Affine

    z = np.asarray(z, dtype=np.float32)
    transform = Affine(cell, 0.0, x0, 0.0, -cell, y0 + z.shape[0] * cell)
    with rasterio.open(
        path, "w", driver="GTiff", width=z.shape[1], height=z.shape[0], count=1,
        dtype="float32", crs=crs, transform=transform, nodata=nodata,
    ) as dst:
        dst.write(z, 1)
    return path


def valley_elevation() -> np.ndarray:
    """North-up elevation grid [m]: floor 100 m, basin 98 m in the first BASIN_COLS columns."""
    z = np.full((NY, NX), 100.0)
    z[:, :BASIN_COLS] = 98.0
    return z


@pytest.fixture
def valley_dem(tmp_path) -> Path:
    return write_geotiff(tmp_path / "dem.tif", valley_elevation())


BASE_SCENARIO = f"""\
[scenario]
name = "valley"
end_time_s = 20.0

[terrain]
dem = "dem.tif"
manning = 0.03
edges = "closed"

[[initial_water]]
level_m = 100.0
polygon = [[{X0}, {Y0}], [{X0 + NX * CELL}, {Y0}], [{X0 + NX * CELL}, {Y0 + NY * CELL}],
           [{X0}, {Y0 + NY * CELL}]]

[numerics]
particle_spacing_m = 10.0
cfl = 0.3
refinement = "none"
time_stepping = "global"

[output]
resolution_m = 10.0
mass_balance_interval_s = 5.0
"""


@pytest.fixture
def write_scenario(tmp_path, valley_dem):
    """``write_scenario(text=BASE_SCENARIO, name="scenario.toml") -> Path`` beside the DEM."""

    def write(text: str = BASE_SCENARIO, name: str = "scenario.toml") -> Path:
        path = tmp_path / name
        path.write_text(text, encoding="utf-8")
        return path

    return write


@pytest.fixture
def scenario_file(write_scenario) -> Path:
    """The base scenario (valley DEM, reservoir at rest behind nothing, closed edges)."""
    return write_scenario()


def load_script(name: str, path: Path):
    """Import a script (``workflows/...`` or ``benchmarks/...``) as module ``name``; its folder
    goes on ``sys.path`` so that it finds the modules beside it."""
    if str(path.parent) not in sys.path:
        sys.path.insert(0, str(path.parent))
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module
