"""A small scenario that every run feature meets: a dam break with an inflow, open edges,
gauges, refinement, snapshots and checkpoints, beside the valley DEM of ``conftest``. Shared by
``tests/run/test_checkpoint_resume.py`` and the golden results (``golden_cases``)."""

from __future__ import annotations

from conftest import CELL, NY, X0, Y0

DAM_BREAK = f"""
[scenario]
name = "resume"
end_time_s = 40.0

[terrain]
dem = "dem.tif"
manning = 0.03
edges = "open"

[[initial_water]]
level_m = 101.0
polygon = [[{X0}, {Y0}], [{X0 + 100}, {Y0}], [{X0 + 100}, {Y0 + NY * CELL}],
           [{X0}, {Y0 + NY * CELL}]]

[[inflows]]
line = [[{X0 + 150}, {Y0 + 50}], [{X0 + 150}, {Y0 + 150}]]
hydrograph = "q.csv"
direction = [1.0, 0.0]

[gauges]
file = "gauges.csv"
interval_s = 2.0

[numerics]
particle_spacing_m = 10.0
refinement = "split+coalesce"
time_stepping = "{{stepping}}"

[output]
resolution_m = 10.0
mass_balance_interval_s = 2.0
checkpoint_interval_s = 10.0
snapshot_interval_s = 5.0
"""


FLUX_LINES = f"""
[[flux_lines]]
name = "floor"
polyline = [[{X0 + 250}, {Y0 - 10}], [{X0 + 260}, {Y0 + 100}], [{X0 + 250}, {Y0 + NY * CELL + 10}]]

[[flux_lines]]
name = "basin_edge"
polyline = [[{X0 + 100}, {Y0 + NY * CELL}], [{X0 + 100}, {Y0}]]
"""
"""Two flux lines across the valley for :func:`write_dam_break` (``flux=True``)."""


def write_dam_break(folder, stepping: str = "global", end_time: float = 40.0,
                    flux: bool = False):
    """The scenario file of :data:`DAM_BREAK` with its hydrograph and gauges, beside the
    valley DEM in ``folder``; ``flux``: with :data:`FLUX_LINES` and snapshots at two listed
    times besides the interval's."""
    (folder / "q.csv").write_text("time_s,discharge_m3s\n0,0\n10,20\n30,20\n40,0\n")
    (folder / "gauges.csv").write_text(
        f"id,x,y\nbasin,{X0 + 50},{Y0 + 100}\nfloor,{X0 + 250},{Y0 + 100}\n")
    text = DAM_BREAK.replace("{stepping}", stepping).replace(
        "end_time_s = 40.0", f"end_time_s = {end_time}")
    if flux:
        text = text.replace("\n[numerics]", FLUX_LINES + "\n[numerics]") + (
            "snapshot_times_s = [7.3, 23.9]\n")
    path = folder / f"{stepping}-{end_time:g}{'-flux' if flux else ''}.toml"
    path.write_text(text, encoding="utf-8")
    return path
