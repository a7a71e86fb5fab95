"""The names of the files and folders a run writes in its run folder (``docs/run-folder.md``).

They are kept apart from ``floodsph.run.folder``, which guards the folder, so that the time
loop's recorders and checkpoints (``floodsph.simulation``) and the writers of the maps
(``floodsph.output``) can name their files without importing the run.
"""

LOG_NAME = "floodsph.log"
RESOLVED_NAME = "scenario.resolved.toml"
MASS_BALANCE_NAME = "mass_balance.csv"
GAUGES_NAME = "gauges.csv"
FLUX_NAME = "flux.csv"
SNAPSHOTS_NAME = "snapshots.nc"
CHECKPOINT_DIR = "checkpoint"
CHECKPOINT_NAME = "state.npz"
"""The checkpoint in ``CHECKPOINT_DIR``: named arrays (``floodsph.simulation.checkpoint``)."""
PICKLED_CHECKPOINT_NAME = "state.pkl"
"""The checkpoint of floodsph before format 5 (a Python pickle): recognised, never read."""
CHECKPOINT_NAMES = (CHECKPOINT_NAME, PICKLED_CHECKPOINT_NAME)
STAGING_DIR = ".floodsph-new"
LOCK_NAME = ".floodsph.lock"
MAP_NAMES = (
    "max_depth.tif",
    "max_speed.tif",
    "max_unit_discharge.tif",
    "max_level.tif",
    "arrival_time.tif",
    "time_of_max_depth.tif",
    "duration.tif",
    "hazard_uk.tif",
    "hazard_arr.tif",
    "flood_maps.nc",
)
#: Quick-look PNGs written by ``floodsph.output.write_pictures`` when matplotlib is installed.
PICTURE_NAMES = ("max_depth.png", "max_speed.png", "max_unit_discharge.png", "duration.png",
                 "hazard_uk.png", "hazard_arr.png", "arrival_time.png")
#: Time-series PNGs (``floodsph.output.pictures.write_series_pictures``), with matplotlib.
SERIES_PICTURE_NAMES = ("gauges.png", "mass_balance.png")
#: The run's summary page (``floodsph.output.report``).
REPORT_NAME = "report.html"
BREACH_GLOB = "breach_hydrograph_*.csv"
