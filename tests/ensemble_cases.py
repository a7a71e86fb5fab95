"""A tiny dam break for ensembles: the conftest valley with its basin filled above the floor.

The basin (western 100 m, bed 98 m) holds water at ``level_m`` (102 m by default, 2 m above
the 100 m floor) behind nothing, with closed edges: 200 particles, 20 s of flow, about a
second per member once compiled. Raising the level floods further along the floor, so a
sampled level gives members of different extents.
"""

from __future__ import annotations

from pathlib import Path

from conftest import CELL, NY, X0, Y0, valley_elevation, write_geotiff

DAM_BREAK = f"""\
[scenario]
name = "dam-break"
end_time_s = 20.0

[terrain]
dem = "dem.tif"
manning = 0.03
edges = "closed"

[[initial_water]]
level_m = 102.0
polygon = [[{X0}, {Y0}], [{X0 + 100.0}, {Y0}], [{X0 + 100.0}, {Y0 + NY * CELL}],
           [{X0}, {Y0 + NY * CELL}]]

[numerics]
particle_spacing_m = 10.0
refinement = "none"

[output]
resolution_m = 10.0
"""

LEVEL = """
[[ensemble.parameters]]
key = "initial_water[0].level_m"
distribution = "uniform"
low = 101.5
high = 103.5
"""


def ensemble_text(parameters: str = LEVEL, members: int = 4, seed: int = 3,
                  header: str = "") -> str:
    """An ensemble file of the dam break with ``parameters`` (TOML tables)."""
    return (f'[ensemble]\nname = "tiny"\nbase = "scenario.toml"\nmembers = {members}\n'
            f"seed = {seed}\n{header}\n{parameters}")


def write_case(folder: Path, ensemble: str, scenario: str = DAM_BREAK) -> Path:
    """The DEM, ``scenario.toml`` and ``ensemble.toml`` in ``folder``; returns the last."""
    write_geotiff(folder / "dem.tif", valley_elevation())
    (folder / "scenario.toml").write_text(scenario, encoding="utf-8")
    path = folder / "ensemble.toml"
    path.write_text(ensemble, encoding="utf-8")
    return path
