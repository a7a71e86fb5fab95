"""Dam-safety scenario comparison: one base scenario against its sensitivity variants.

Variants of the base (default ``data_samples/valley/scenario.toml``):

* Manning n times each ``--manning-factors`` (default 0.8 and 1.2, i.e. -20 % / +20 %): a
  uniform n is scaled; an n raster or a land-cover class table is scaled into a new file in
  the results folder;
* the initial reservoir level plus each ``--level-deltas`` [m] (default -1 and +1): applied
  to the ``[[initial_water]]`` body with the highest ``level_m`` (the reservoir; a sea or a
  tail-water body below it keeps its level);
* when the base has a parametric breach (``[inflows.breach]``): the average breach width and
  the formation time, each times each ``--breach-factors`` (default 0.5 and 1.5), starting
  from the values the base implies (given, or Froehlich 2008 from ``floodsph.breach``).

Each variant is written as a scenario TOML (``tomli_w``, from the base's resolved
copy: absolute paths, every default filled) into ``<out>/scenarios/``, run with
``floodsph.run.pipeline.run_scenario`` into ``<out>/runs/<variant>/``, and compared with the base by
``floodsph.output.compare.compare`` (model = variant, reference = base; wet = depth >
``--threshold``,
default 0.1 m, Wing et al. 2017). Written into the results folder:

* ``differences/<variant>/``: ``difference.tif`` (max depth, variant - base [m], NaN where
  dry in both), ``comparison.png`` (wet/dry agreement and difference), ``comparison.json``;
* ``gauge_arrivals.csv``: arrival time (first gauge time with depth > threshold; resolution
  = the gauge interval) per variant and gauge, the base's, and the change [s];
* ``summary.csv`` and ``summary.md`` (printed): per variant the initial particles and volume,
  mass-budget error, wall time, flooded area (cells wet above the threshold x cell area) and
  its change, CSI, hit rate, false-alarm ratio, depth bias/RMSE over cells wet in both, and
  the mean / min / max arrival-time change over gauges reached in both runs.

The base is compared with itself too (its row: CSI = 1, no change) as a check of the chain.

Usage: ``python workflows/compare_breach_scenarios.py [--base SCENARIO] [--out DIR]
[--end-time S] [--spacing M] [--max-steps N] [--overwrite]``
"""

from __future__ import annotations

import argparse
import copy
import csv
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DEFAULT_BASE = REPO / "data_samples" / "valley" / "scenario.toml"
SUMMARY_COLUMNS = (
    "variant", "parameter", "value", "particles_initial", "volume_initial_m3",
    "volume_out_m3", "mass_error_rel", "wall_time_s", "flooded_area_km2", "area_change_km2",
    "area_change_pct", "csi", "hit_rate", "false_alarm_ratio", "depth_bias_m",
    "depth_rmse_m", "arrival_change_mean_s", "arrival_change_min_s", "arrival_change_max_s",
)
ARRIVAL_COLUMNS = ("variant", "gauge", "arrival_s", "base_arrival_s", "change_s")


@dataclass
class Variant:
    """One scenario of the study: file-safe ``name``, what changed and the scenario data."""

    name: str
    parameter: str
    value: str
    data: dict


def base_data(base_path: Path, end_time: float | None = None,
              spacing: float | None = None) -> dict:
    """The base scenario's resolved dict (absolute paths), with optional overrides."""
    from floodsph.scenario.reader import load_scenario

    data = load_scenario(base_path).to_dict()
    if end_time is not None:
        data["scenario"]["end_time_s"] = float(end_time)
    if spacing is not None:
        data["numerics"]["particle_spacing_m"] = float(spacing)
    return data


def _scaled_manning(terrain: dict, factor: float, folder: Path, name: str) -> tuple[dict, str]:
    """``terrain`` with Manning n times ``factor`` and a label of the new n."""
    terrain = dict(terrain)
    manning = terrain.get("manning")
    if isinstance(manning, int | float):
        terrain["manning"] = manning * factor
        return terrain, f"{manning * factor:.4g}"
    folder.mkdir(parents=True, exist_ok=True)
    if manning is not None:
        import rasterio

        with rasterio.open(manning) as src:
            profile, n = src.profile, src.read(1)
        scaled = n * factor
        if profile.get("nodata") is not None:
            scaled[n == profile["nodata"]] = profile["nodata"]
        out = folder / f"{name}_manning.tif"
        with rasterio.open(out, "w", **profile) as dst:
            dst.write(scaled, 1)
        terrain["manning"] = str(out)
        return terrain, f"n raster x {factor:g}"
    from floodsph.io.manning import WORLDCOVER, read_manning_table

    table = read_manning_table(terrain.get("manning_table", WORLDCOVER))
    out = folder / f"{name}_manning_table.csv"
    with open(out, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["class", "manning_n"])
        w.writerows([cls, repr(n * factor)] for cls, n in table.items())
    terrain["manning_table"] = str(out)
    return terrain, f"class table x {factor:g}"


def breach_defaults(breach: dict) -> tuple[float, float]:
    """(average width [m], formation time [s]) that a breach table implies (Froehlich 2008)."""
    from floodsph.breach.params import BreachParams, resolve

    setup = resolve(BreachParams.from_mapping(breach, "inflows.breach"))
    return setup.average_width_m, setup.formation_time_s


def make_variants(base: dict, folder: Path, manning_factors=(0.8, 1.2),
                  level_deltas=(-1.0, 1.0), breach_factors=(0.5, 1.5)) -> list[Variant]:
    """The base and its variants (see the module docstring); ``folder`` gets derived inputs."""
    out = [Variant("base", "base", "", copy.deepcopy(base))]
    for f in manning_factors:
        data = copy.deepcopy(base)
        name = f"manning_x{f:g}"
        data["terrain"], label = _scaled_manning(data["terrain"], f, folder, name)
        out.append(Variant(name, "manning_n", label, data))
    levels = [(k, w["level_m"]) for k, w in enumerate(base.get("initial_water", []))
              if "level_m" in w]
    if levels:
        k, level = max(levels, key=lambda item: item[1])
        for delta in level_deltas:
            data = copy.deepcopy(base)
            data["initial_water"][k]["level_m"] = level + delta
            out.append(Variant(f"level_{delta:+g}m", "reservoir_level_m",
                               f"{level + delta:g}", data))
    for i, inflow in enumerate(base.get("inflows", [])):
        if "breach" not in inflow:
            continue
        width, t_f = breach_defaults(inflow["breach"])
        for key, start, label in (("average_width_m", width, "breach_width_m"),
                                  ("formation_time_s", t_f, "formation_time_s")):
            for f in breach_factors:
                data = copy.deepcopy(base)
                data["inflows"][i]["breach"][key] = start * f
                suffix = f"_{i}" if len(base["inflows"]) > 1 else ""
                out.append(Variant(f"{label.rsplit('_', 1)[0]}{suffix}_x{f:g}", label,
                                   f"{start * f:.4g}", data))
    return out


def write_variant(v: Variant, scenarios: Path, runs: Path, base_name: str) -> Path:
    """``scenarios/<name>.toml`` with its run folder ``runs/<name>``; returns the TOML path."""
    from tomli_w import dumps

    data = copy.deepcopy(v.data)
    data["scenario"]["name"] = f"{base_name}-{v.name}"
    data["output"]["directory"] = str(runs / v.name)
    scenarios.mkdir(parents=True, exist_ok=True)
    path = scenarios / f"{v.name}.toml"
    path.write_text(f"# {v.parameter} = {v.value or 'base'}\n" + dumps(data), encoding="utf-8")
    return path


def arrival_times(run_dir: Path, threshold: float) -> dict[str, float]:
    """First gauge time with depth > threshold per gauge id (NaN: never); {} without gauges."""
    path = run_dir / "gauges.csv"
    out: dict[str, float] = {}
    if not path.is_file():
        return out
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            t = out.setdefault(row["id"], math.nan)
            if math.isnan(t) and float(row["depth_m"]) > threshold:
                out[row["id"]] = float(row["time_s"])
    return out


def compare_with_base(v: Variant, runs: Path, out: Path, threshold: float,
                      base_arrival: dict) -> tuple[dict, list[dict]]:
    """The summary row and per-gauge arrival rows of variant ``v`` against the base."""
    import json

    from floodsph.output.compare import compare, write_outputs

    run = json.loads((runs / v.name / "run.json").read_text())
    result = compare(runs / v.name / "max_depth.tif", runs / "base" / "max_depth.tif",
                     threshold=threshold)
    write_outputs(result, out / "differences" / v.name)
    s = result.summary
    t = result.model.transform
    cell_km2 = abs(t.a * t.e) / 1e6
    area = (s["hits"] + s["false_alarms"]) * cell_km2
    area_base = (s["hits"] + s["misses"]) * cell_km2
    arrival = arrival_times(runs / v.name, threshold)
    gauges = []
    for gid, t0 in base_arrival.items():
        t1 = arrival.get(gid, math.nan)
        gauges.append({"variant": v.name, "gauge": gid, "arrival_s": t1, "base_arrival_s": t0,
                       "change_s": t1 - t0})
    changes = [g["change_s"] for g in gauges if math.isfinite(g["change_s"])]
    row = {"variant": v.name, "parameter": v.parameter, "value": v.value,
           "particles_initial": run["particles_initial"],
           "volume_initial_m3": run["volume_initial_m3"],
           "volume_out_m3": run["volume_out_m3"], "mass_error_rel": run["mass_error_rel"],
           "wall_time_s": run["wall_time_s"], "flooded_area_km2": area,
           "area_change_km2": area - area_base,
           "area_change_pct": 100.0 * (area - area_base) / area_base if area_base else math.nan,
           "csi": s["csi"], "hit_rate": s["hit_rate"],
           "false_alarm_ratio": s["false_alarm_ratio"], "depth_bias_m": s["depth"]["bias"],
           "depth_rmse_m": s["depth"]["rmse"],
           "arrival_change_mean_s": float(np.mean(changes)) if changes else math.nan,
           "arrival_change_min_s": min(changes, default=math.nan),
           "arrival_change_max_s": max(changes, default=math.nan)}
    return row, gauges


def _fmt(value) -> str:
    if isinstance(value, float | np.floating):
        return f"{value:.6g}"
    return str(value)


def write_table(path: Path, columns, rows: list[dict]) -> Path:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        w.writerows([_fmt(r[c]) for c in columns] for r in rows)
    return path


MARKDOWN_COLUMNS = (("variant", "variant", "s"), ("value", "value", "s"),
                    ("flooded_area_km2", "area km2", ".4f"),
                    ("area_change_pct", "d area %", "+.2f"),
                    ("csi", "CSI", ".3f"), ("depth_bias_m", "depth bias m", "+.3f"),
                    ("depth_rmse_m", "depth RMSE m", ".3f"),
                    ("arrival_change_mean_s", "d arrival s", "+.1f"),
                    ("mass_error_rel", "mass err", ".1e"), ("wall_time_s", "wall s", ".1f"))


def markdown(rows: list[dict], threshold: float) -> str:
    """The summary as a markdown table (selected columns)."""
    head = "| " + " | ".join(h for _, h, _ in MARKDOWN_COLUMNS) + " |"
    lines = [f"Variants against the base (wet = max depth > {threshold:g} m)", "", head,
             "|" + "---|" * len(MARKDOWN_COLUMNS)]
    for r in rows:
        cells = []
        for key, _, spec in MARKDOWN_COLUMNS:
            v = r[key]
            cells.append(format(v, spec) if isinstance(v, float) and math.isfinite(v)
                         else ("n/a" if isinstance(v, float) else str(v)))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def run_study(base_path: Path, out: Path, end_time=None, spacing=None, max_steps=None,
              overwrite=False, threshold=0.1, manning_factors=(0.8, 1.2),
              level_deltas=(-1.0, 1.0), breach_factors=(0.5, 1.5)) -> list[dict]:
    """Write, run and compare every variant; returns the summary rows (base first)."""
    from floodsph.run.pipeline import run_scenario
    from floodsph.scenario.reader import load_scenario

    out = Path(out).resolve()
    base = base_data(Path(base_path), end_time, spacing)
    variants = make_variants(base, out / "inputs", manning_factors, level_deltas,
                             breach_factors)
    runs = out / "runs"
    for v in variants:
        path = write_variant(v, out / "scenarios", runs, base["scenario"]["name"])
        print(f"running {v.name} ({path.name})", flush=True)
        run_scenario(load_scenario(path), out_dir=runs / v.name, max_steps=max_steps,
                     progress=False, overwrite=overwrite)
    base_arrival = arrival_times(runs / "base", threshold)
    rows, gauges = [], []
    for v in variants:
        row, g = compare_with_base(v, runs, out, threshold, base_arrival)
        rows.append(row)
        gauges += g
    write_table(out / "summary.csv", SUMMARY_COLUMNS, rows)
    write_table(out / "gauge_arrivals.csv", ARRIVAL_COLUMNS, gauges)
    text = markdown(rows, threshold)
    (out / "summary.md").write_text(text, encoding="utf-8")
    print(text)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=Path, default=DEFAULT_BASE, help="base scenario TOML")
    ap.add_argument("--out", type=Path, default=Path("results/compare_breach_scenarios"))
    ap.add_argument("--end-time", type=float, default=None, help="override end_time_s [s]")
    ap.add_argument("--spacing", type=float, default=None, help="override particle spacing [m]")
    ap.add_argument("--max-steps", type=int, default=None, help="stop each run after N steps")
    ap.add_argument("--threshold", type=float, default=0.1, help="wet depth [m] (CSI, area, "
                    "arrival)")
    ap.add_argument("--manning-factors", type=float, nargs="*", default=[0.8, 1.2])
    ap.add_argument("--level-deltas", type=float, nargs="*", default=[-1.0, 1.0])
    ap.add_argument("--breach-factors", type=float, nargs="*", default=[0.5, 1.5])
    ap.add_argument("--overwrite", action="store_true", help="replace earlier runs")
    args = ap.parse_args(argv)
    from floodsph.errors import InputError

    try:
        run_study(args.base, args.out, args.end_time, args.spacing, args.max_steps,
                  args.overwrite, args.threshold, args.manning_factors, args.level_deltas,
                  args.breach_factors)
    except InputError as exc:
        print(f"Error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
