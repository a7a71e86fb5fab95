"""UK Environment Agency 2D benchmark Test 4 (flood propagation over a flat floodplain).

Néelz & Pender (2013), *Benchmarking the latest generation of 2D hydraulic modelling packages*,
Environment Agency report SC120002, Test 4: a flat, initially dry floodplain 1000 m x 2000 m,
Manning n = 0.05, fed through a 20 m wide opening in the middle of its west edge
(y = 990-1010 m) by a trapezoidal hydrograph (0 -> 20 m3/s from 300 s to 3600 s, 20 m3/s to
14400 s, -> 0 at 18000 s); 18000 s simulated; depth and velocity reported at six points.

Reads the benchmark files from ``$FLOODSPH_BENCHMARKS/ea_test4`` or
``<repo>/../shared/benchmarks/ea_test4`` (never copied into the repository) and writes into the
results folder: the hydrograph as ``ea4_hydrograph.csv`` (``time_s,discharge_m3s``), the output
points as ``ea4_gauges.csv`` (``id,x,y``), the scenario ``ea_test4.toml`` (absolute path to the
DEM, which lies outside the repository), the run folder ``run/``, and the results:

* ``ea4_points.csv``: per output point, the arrival time (first gauge sample deeper than the
  wet threshold, 0.01 m; and the same from ``arrival_time.tif``, recorded every step), the peak
  depth and its time (and the map ``max_depth.tif`` value at the point);
* ``ea4_volume.csv``: the volume balance: volume injected (``run.json`` ``volume_in_m3``)
  against the integral of the hydrograph up to the simulated time, the volume in the domain,
  the outflow and ``mass_error_rel``;
* ``ea4_depths.png`` (depth at the six points against time) and ``ea4_volume.png`` (injected
  volume against the hydrograph integral).

Usage: ``python benchmarks/ea_test4/run_ea_test4.py [--end-time 18000] [--dem-cell 5]
[--spacing 5] [--threads N] [--time-stepping global|local]
[--refinement split+coalesce|split|none] [--out DIR] [--overwrite]``
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import sys
from pathlib import Path

import numpy as np

from floodsph.output.tables import write_csv
from floodsph.scenario.numerics import Refinement

REPO = Path(__file__).resolve().parents[2]
DEM_NAMES = {5: "ea4_dem_5m.asc", 10: "ea4_dem_10m.asc"}
HYDROGRAPH_NAME = "ea4_inflow_hydrograph.csv"
POINTS_NAME = "ea4_output_points.csv"
#: The DEM (an ESRI ASCII grid without .prj) carries no CRS. The test is a synthetic UK case in
#: a local frame with origin (0, 0); British National Grid is given so that the outputs are
#: georeferenced. The coordinates are metres either way.
CRS = "EPSG:27700"
MANNING_N = 0.05
END_TIME_S = 18000.0
#: The inflow opening on the west edge x = 0 (ea4_boundaries.csv), water entering eastwards.
INLET = ((0.0, 990.0), (0.0, 1010.0))
INLET_DIRECTION = (1.0, 0.0)
#: The rest of the west edge is a wall (LISFLOOD-FP's default closed boundary; the inflow
#: cuts its opening out of it); the other edges are free (transmissive): ``edges = "open"``
#: with ``closed_sides = ["west"]``.
CLOSED_SIDES = ("west",)
WET_THRESHOLD_M = 0.01
GAUGE_INTERVAL_S = 10.0


def data_folder() -> Path | None:
    """The ``ea_test4`` benchmark folder, or None when its files are not there."""
    root = os.environ.get("FLOODSPH_BENCHMARKS")
    base = Path(root) if root else REPO.parent / "shared" / "benchmarks"
    folder = base / "ea_test4"
    needed = (DEM_NAMES[5], DEM_NAMES[10], HYDROGRAPH_NAME, POINTS_NAME)
    return folder if all((folder / name).is_file() for name in needed) else None


def read_points(folder: Path) -> list[tuple[str, float, float]]:
    """The six output points ``(id, x, y)`` [m]; ids ``P1``..``P6`` from the ``point`` column."""
    with open(folder / POINTS_NAME, newline="") as f:
        return [(f"P{row['point']}", float(row["x_m"]), float(row["y_m"]))
                for row in csv.DictReader(f)]


def write_inputs(folder: Path, out: Path, end_time: float, dem_cell: int,
                 spacing: float, time_stepping: str = "global",
                 refinement: str | None = None) -> Path:
    """Hydrograph CSV, gauge CSV and the scenario TOML in ``out``; returns the scenario path.

    ``time_stepping`` is ``numerics.time_stepping`` ("global" or "local"), ``refinement``
    ``numerics.refinement`` (None: floodsph's default)."""
    from tomli_w import dumps

    from floodsph.io.hydrograph import read_hydrograph, write_hydrograph_csv

    hydrograph = read_hydrograph(folder / HYDROGRAPH_NAME, "EA test 4 hydrograph")
    write_hydrograph_csv(out / "ea4_hydrograph.csv", hydrograph.t, hydrograph.Q)
    with open(out / "ea4_gauges.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["id", "x", "y"])
        w.writerows(read_points(folder))
    scenario = {
        "scenario": {
            "name": "ea_test4",
            "end_time_s": end_time,
            "description": "EA 2D benchmark Test 4: flat floodplain, n = 0.05, 20 m3/s "
                           "trapezoidal inflow through a 20 m opening in the west edge",
        },
        "terrain": {"dem": str(folder / DEM_NAMES[dem_cell]), "crs": CRS,
                    "manning": MANNING_N, "edges": "open",
                    "closed_sides": list(CLOSED_SIDES)},
        "inflows": [{"line": [list(p) for p in INLET], "hydrograph": "ea4_hydrograph.csv",
                     "direction": list(INLET_DIRECTION)}],
        "gauges": {"file": "ea4_gauges.csv", "interval_s": GAUGE_INTERVAL_S},
        "numerics": {"particle_spacing_m": spacing, "time_stepping": time_stepping},
        "output": {"resolution_m": float(dem_cell), "wet_threshold_m": WET_THRESHOLD_M},
    }
    if refinement is not None:
        scenario["numerics"]["refinement"] = refinement
    path = out / "ea_test4.toml"
    path.write_text(dumps(scenario), encoding="utf-8")
    return path


def gauge_series(path: Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """``gauges.csv`` -> {id: (time_s, depth_m)}; a dry sample (NaN) becomes depth 0."""
    series: dict[str, tuple[list, list]] = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            t, d = series.setdefault(row["id"], ([], []))
            t.append(float(row["time_s"]))
            d.append(float(row["depth_m"]))
    return {k: (np.array(t), np.nan_to_num(np.array(d), nan=0.0)) for k, (t, d) in series.items()}


def arrival_and_peak(t: np.ndarray, d: np.ndarray, threshold: float) -> tuple[float, float, float]:
    """Arrival time, peak depth and time of the peak of one depth series.

    Arrival is the first sample time with ``d > threshold`` (NaN if never); the peak is the
    largest sample (NaN time if the point stays dry).
    """
    wet = np.flatnonzero(d > threshold)
    arrival = float(t[wet[0]]) if wet.size else math.nan
    k = int(np.argmax(d))
    peak = float(d[k])
    return arrival, peak, (float(t[k]) if peak > threshold else math.nan)


def map_values(path: Path, points) -> np.ndarray:
    """Values of a single-band map at the cells holding ``points`` (NaN off the map)."""
    import rasterio

    with rasterio.open(path) as src:
        values = np.array([v[0] for v in src.sample([(x, y) for _, x, y in points])],
                          dtype=np.float64)
        if src.nodata is not None and not math.isnan(src.nodata):
            values[values == src.nodata] = np.nan
    return values


def point_table(run: Path, points, threshold: float) -> list[dict]:
    """One row per output point: gauge arrival / peak and the map values at the point."""
    series = gauge_series(run / "gauges.csv")
    arrival_map = map_values(run / "arrival_time.tif", points)
    depth_map = map_values(run / "max_depth.tif", points)
    rows = []
    for k, (pid, x, y) in enumerate(points):
        arrival, peak, t_peak = arrival_and_peak(*series[pid], threshold)
        rows.append({"point": pid, "x_m": x, "y_m": y, "arrival_s": arrival,
                     "peak_depth_m": peak, "time_of_peak_s": t_peak,
                     "map_arrival_s": arrival_map[k], "map_max_depth_m": depth_map[k]})
    return rows


def volume_balance(manifest: dict, hydrograph) -> dict:
    """Injected volume against the hydrograph integral up to the simulated time [m3]."""
    expected = float(hydrograph.volume(0.0, manifest["sim_time_s"]))
    injected = float(manifest["volume_in_m3"])
    return {"sim_time_s": manifest["sim_time_s"], "hydrograph_volume_m3": expected,
            "volume_in_m3": injected,
            "injected_rel_error": (injected - expected) / expected if expected > 0 else math.nan,
            "volume_domain_m3": manifest["volume_domain_m3"],
            "volume_out_m3": manifest["volume_out_m3"],
            "mass_error_rel": manifest["mass_error_rel"], "steps": manifest["steps"],
            "particles_final": manifest["particles_final"],
            "wall_time_s": manifest["wall_time_s"]}


def plot_depths(path: Path, run: Path, points) -> Path | None:
    """Depth against time at the output points (None without matplotlib)."""
    try:
        import matplotlib
    except ImportError:
        return None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    series = gauge_series(run / "gauges.csv")
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for pid, x, y in points:
        t, d = series[pid]
        ax.plot(t / 3600.0, d, label=f"{pid} ({x:g}, {y:g})")
    ax.set(xlabel="time [h]", ylabel="depth [m]", title="EA Test 4: depth at the output points")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_volume(path: Path, run: Path, hydrograph) -> Path | None:
    """Injected volume (mass_balance.csv) against the hydrograph integral."""
    try:
        import matplotlib
    except ImportError:
        return None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with open(run / "mass_balance.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["time_s"]) for r in rows])
    v_in = np.array([float(r["volume_in_m3"]) for r in rows])
    v_dom = np.array([float(r["volume_domain_m3"]) for r in rows])
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.plot(t / 3600.0, v_in, lw=3, alpha=0.6, label="injected (floodsph)")
    ax.plot(t / 3600.0, v_dom, label="in the domain (floodsph)")
    ax.plot(t / 3600.0, hydrograph.volume(0.0, t), "k--", label="hydrograph integral")
    ax.set(xlabel="time [h]", ylabel="volume [m3]", title="EA Test 4: volume balance")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time", type=float, default=END_TIME_S, help="simulated time [s]")
    parser.add_argument("--dem-cell", type=int, choices=sorted(DEM_NAMES), default=5,
                        help="DEM (and output map) cell size [m]")
    parser.add_argument("--spacing", type=float, default=None,
                        help="particle spacing [m] (default: the DEM cell)")
    parser.add_argument("--out", type=Path, default=REPO / "benchmarks" / "ea_test4" / "results",
                        help="results folder (inputs, run folder 'run/', CSVs, PNGs)")
    parser.add_argument("--overwrite", action="store_true", help="replace an earlier run")
    parser.add_argument("--max-steps", type=int, default=None, help="stop after N steps")
    parser.add_argument("--threads", type=int, default=None,
                        help="numba threads (default: the scenario's, 0 = all cores)")
    parser.add_argument("--time-stepping", choices=("global", "local"), default="global",
                        help="numerics.time_stepping: one step for all particles, or each "
                             "at its own")
    parser.add_argument("--refinement", choices=[mode.value for mode in Refinement], default=None,
                        help="numerics.refinement (default: floodsph's, split+coalesce)")
    args = parser.parse_args(argv)

    folder = data_folder()
    if folder is None:
        print("EA Test 4 data not found: set FLOODSPH_BENCHMARKS to the folder holding "
              "ea_test4/ (or place it in <repo>/../shared/benchmarks); nothing run.",
              file=sys.stderr)
        return 0
    from floodsph.io.hydrograph import read_hydrograph
    from floodsph.run.pipeline import run_scenario
    from floodsph.scenario.reader import load_scenario

    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    path = write_inputs(folder, out, args.end_time, args.dem_cell,
                        args.spacing or float(args.dem_cell), args.time_stepping,
                        args.refinement)
    run = out / "run"
    manifest = run_scenario(load_scenario(path), out_dir=run, overwrite=args.overwrite,
                            max_steps=args.max_steps, threads=args.threads)
    points = read_points(folder)
    hydrograph = read_hydrograph(out / "ea4_hydrograph.csv")
    table = point_table(run, points, WET_THRESHOLD_M)
    balance = volume_balance(manifest, hydrograph)
    write_csv(out / "ea4_points.csv", table)
    write_csv(out / "ea4_volume.csv", [balance])
    plot_depths(out / "ea4_depths.png", run, points)
    plot_volume(out / "ea4_volume.png", run, hydrograph)
    for r in table:
        print(f"{r['point']} ({r['x_m']:g}, {r['y_m']:g}): arrival {r['arrival_s']:.0f} s "
              f"(map {r['map_arrival_s']:.0f} s), peak depth {r['peak_depth_m']:.3f} m at "
              f"{r['time_of_peak_s']:.0f} s")
    print(f"volume injected {balance['volume_in_m3']:.1f} m3 vs hydrograph "
          f"{balance['hydrograph_volume_m3']:.1f} m3 ({balance['injected_rel_error']:+.2e}); "
          f"mass error {balance['mass_error_rel']:.2e}; {balance['steps']} steps, "
          f"{balance['wall_time_s']:.0f} s wall; results in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
