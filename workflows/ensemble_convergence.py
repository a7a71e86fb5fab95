"""How many members? The exceedance-probability map against the ensemble size.

Runs the ensemble file (default ``data_samples/valley_breach/ensemble.toml``) at each size of
``--sizes`` (default 16, 32 and 64 members; same seed and sampling, so each size is the
ensemble a user would run with that ``members``), all on one local dask cluster, into
``<out>/n<N>/``. The largest ensemble is the reference: for each size N and the threshold t
(default 0.1 m), with p_N the map ``p_depth_gt_<t>m.tif``,

* ``max_abs_diff``: max |p_N - p_ref| over the DEM;
* ``mean_abs_diff``: mean |p_N - p_ref| over the cells where either map is > 0 (the area at
  stake; the always-dry cells would only dilute it);
* ``area_p50_km2``: the area with p_N > 0.5 [km2], and ``area_p50_change_pct`` against the
  reference's;
* ``std_error_max``: 0.5 / sqrt(N), the largest standard error of a probability estimated
  from N independent members (binomial, at p = 0.5), for scale.

The reference has sampling error of its own, so the differences of the smaller sizes are
differences to another estimate, not errors against the exact probability.

Prints the table and writes it with the command that made it to ``--doc`` (default
``docs/ensemble_convergence.md``). Ensemble folders that already hold a run are resumed, so
the study can be stopped and continued.

Usage: ``python workflows/ensemble_convergence.py [--ensemble FILE] [--sizes 16 32 64]
[--threshold 0.1] [--out DIR] [--doc FILE] [--workers N] [--threads-per-worker T]``
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import time
from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DEFAULT_ENSEMBLE = REPO / "data_samples" / "valley_breach" / "ensemble.toml"
COLUMNS = ("members", "members_completed", "max_abs_diff", "mean_abs_diff", "area_p50_km2",
           "area_p50_change_pct", "std_error_max", "wall_time_s")


def read_probability(folder: Path, threshold: float) -> tuple[np.ndarray, float]:
    """The map ``p_depth_gt_<t>m.tif`` of an ensemble folder and its cell area [m2]."""
    import rasterio

    from floodsph.ensemble.spec import threshold_label

    with rasterio.open(folder / f"p_depth_gt_{threshold_label(threshold)}m.tif") as src:
        return src.read(1).astype(np.float64), abs(src.transform.a * src.transform.e)


def convergence_rows(folders: dict[int, Path], threshold: float,
                     manifests: dict[int, dict]) -> list[dict]:
    """One table row per ensemble size, against the largest size (module docstring)."""
    reference_n = max(folders)
    p_ref, cell_m2 = read_probability(folders[reference_n], threshold)
    area_ref = np.count_nonzero(p_ref > 0.5) * cell_m2 / 1e6
    rows = []
    for n in sorted(folders):
        p, _ = read_probability(folders[n], threshold)
        diff = np.abs(p - p_ref)
        at_stake = (np.nan_to_num(p) > 0) | (np.nan_to_num(p_ref) > 0)
        area = np.count_nonzero(p > 0.5) * cell_m2 / 1e6
        rows.append({
            "members": n,
            "members_completed": manifests[n]["members_completed"],
            "max_abs_diff": float(np.nanmax(diff)),
            "mean_abs_diff": float(np.nanmean(diff[at_stake])) if at_stake.any() else 0.0,
            "area_p50_km2": area,
            "area_p50_change_pct": 100.0 * (area - area_ref) / area_ref if area_ref else math.nan,
            "std_error_max": 0.5 / math.sqrt(n),
            "wall_time_s": float(manifests[n]["wall_time_s"]),
        })
    return rows


def run_sizes(ensemble: Path, sizes: list[int], out: Path, workers=None,
              threads=None) -> tuple[dict[int, Path], dict[int, dict]]:
    """Run (or resume) the ensemble at every size on one local cluster."""
    from floodsph.ensemble.engine import machine_cores, open_client, plan_workers
    from floodsph.ensemble.runner import prepare_base, run_ensemble
    from floodsph.ensemble.spec import load_ensemble
    from floodsph.inputs.memory import available_memory
    from floodsph.scenario.reader import load_scenario

    spec = load_ensemble(ensemble)
    available, _ = available_memory()
    member_bytes = prepare_base(load_scenario(spec.base)).member_bytes
    plan = plan_workers(max(sizes), machine_cores(), member_bytes, available, workers, threads)
    folders, manifests = {}, {}
    with open_client(plan, None) as client:
        address = client.scheduler.address
        for n in sizes:
            folders[n] = out / f"n{n}"
            sized = replace(spec, members=n, name=f"{spec.name}-n{n}")
            start = time.monotonic()
            manifests[n] = run_ensemble(sized, folders[n], scheduler=address,
                                        threads_per_worker=plan.threads_per_worker,
                                        resume=True, progress=True)
            print(f"{n} members: {manifests[n]['status']} in {time.monotonic() - start:.1f} s",
                  flush=True)
    return folders, manifests


def report(rows: list[dict], threshold: float, command: str) -> str:
    """The markdown page: the command, the table and how to read it."""
    from floodsph.output.tables import markdown

    commit = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip() or "unknown"
    stamp = datetime.now(UTC).strftime("%Y-%m-%d")
    n_ref = max(r["members"] for r in rows)
    return "\n".join([
        "# Ensemble convergence: the exceedance-probability map against the members",
        "",
        f"Made by `{command}` on {stamp} at commit `{commit}`.",
        "",
        f"P(max depth > {threshold:g} m) of each ensemble size against the {n_ref}-member "
        "ensemble (the reference). `mean_abs_diff` is over the cells where either map is "
        "above 0; `std_error_max` = 0.5 / sqrt(N) is the largest standard error of a "
        "probability from N independent members. The reference carries sampling error "
        "too: a difference is to another estimate, not to the exact probability.",
        "",
        markdown(rows, COLUMNS),
        "",
    ])


def main(argv=None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--ensemble", type=Path, default=DEFAULT_ENSEMBLE)
    parser.add_argument("--sizes", type=int, nargs="+", default=[16, 32, 64])
    parser.add_argument("--threshold", type=float, default=0.1)
    parser.add_argument("--out", type=Path, default=REPO / "results" / "ensemble_convergence")
    parser.add_argument("--doc", type=Path, default=REPO / "docs" / "ensemble_convergence.md")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--threads-per-worker", type=int, default=None)
    args = parser.parse_args(argv)
    if len(set(args.sizes)) < 2 or min(args.sizes) < 1:
        parser.error("--sizes needs at least two different ensemble sizes >= 1")
    folders, manifests = run_sizes(args.ensemble, sorted(set(args.sizes)), args.out,
                                   args.workers, args.threads_per_worker)
    rows = convergence_rows(folders, args.threshold, manifests)
    command = "python workflows/ensemble_convergence.py " + " ".join(
        sys.argv[1:] if argv is None else argv)
    text = report(rows, args.threshold, command.strip())
    args.doc.parent.mkdir(parents=True, exist_ok=True)
    args.doc.write_text(text, encoding="utf-8")
    print(text)
    return rows


if __name__ == "__main__":
    main()
