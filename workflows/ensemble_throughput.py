"""Ensemble throughput on this machine: members per hour, and what the cluster costs.

K members (``--members``, default 8) of the ensemble file (default
``data_samples/valley_breach/ensemble.toml``) are run

1. as ensembles (``floodsph.ensemble.runner.run_ensemble``, a fresh local cluster each) with
   1 worker x 2 threads and with 2 workers x 1 thread: the wall time from start to finish
   (ensemble.json ``wall_time_s``) gives ``members_per_hour`` = K / wall x 3600;
2. alone, right after each ensemble: each member's ``scenario.toml`` through
   ``floodsph.run.pipeline.run_scenario`` in this process with the configuration's threads (after
   one
   untimed warm-up run, the compiled kernels loaded from numba's cache):
   ``member_alone_s`` is their mean.

For each configuration, with W workers, ``ideal_s`` = (sum of the members' alone times at the
configuration's threads) / W is the wall of the members back to back with nothing else, and

* ``overhead_per_member_s`` = (wall - ideal) / K, ``overhead_pct`` of ``member_alone_s``;
* ``fixed_s``: the parts paid once per ensemble, measured separately: checking the members
  and preparing the base inputs, starting and stopping a cluster of that size with no task,
  and aggregating the completed members and writing the maps;
* ``scheduling_per_member_s`` = (wall - ideal - fixed) / K, ``scheduling_pct`` of
  ``member_alone_s``: what remains per member (task submission and results, and each worker
  process loading floodsph and the compiled kernels before its first member).

Run it on a quiet machine, without ``NUMBA_NUM_THREADS`` set below 2. Writes
``throughput.csv`` and ``throughput.md`` into ``--out`` and prints the table.

Usage: ``python workflows/ensemble_throughput.py [--ensemble FILE] [--members 8] [--out DIR]``
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DEFAULT_ENSEMBLE = REPO / "data_samples" / "valley_breach" / "ensemble.toml"
CONFIGS = ((1, 2), (2, 1))  # (workers, threads per worker)
COLUMNS = ("workers", "threads", "members", "wall_s", "members_per_hour", "member_alone_s",
           "ideal_s", "fixed_s", "overhead_per_member_s", "overhead_pct",
           "scheduling_per_member_s", "scheduling_pct")


def timed(function, *args, **kwargs) -> tuple[object, float]:
    """``function(*args, **kwargs)`` and its wall time [s]."""
    start = time.monotonic()
    value = function(*args, **kwargs)
    return value, time.monotonic() - start


def alone_times(folders: list[Path], threads: int, scratch: Path) -> list[float]:
    """Wall time [s] of ``run_scenario`` on each member's scenario alone in this process."""
    from floodsph.run.pipeline import run_scenario
    from floodsph.scenario.reader import load_scenario

    out = []
    for folder in folders:
        scenario = load_scenario(folder / "scenario.toml")
        target = scratch / f"t{threads}-{folder.name}"
        _, wall = timed(run_scenario, scenario, out_dir=target, progress=False, threads=threads)
        out.append(wall)
    return out


def fixed_times(spec, base, folder: Path, members: list[Path], workers: int,
                scratch: Path) -> float:
    """Seconds paid once per ensemble: member checks and base inputs, an idle cluster's
    start and stop, the aggregation and map writing."""
    from floodsph.ensemble.aggregate import aggregate
    from floodsph.ensemble.engine import WorkerPlan, open_client
    from floodsph.ensemble.members import build_members
    from floodsph.ensemble.outputs import write_outputs
    from floodsph.ensemble.runner import prepare_base
    from floodsph.ensemble.sampling import draw_samples

    def prepare():
        build_members(spec, base, draw_samples(spec), folder)
        return prepare_base(base)

    setup, t_prepare = timed(prepare)

    def idle_cluster():
        with open_client(WorkerPlan(workers, 1), None) as client:
            client.wait_for_workers(workers)

    _, t_cluster = timed(idle_cluster)
    maps_dir = scratch / f"maps-{workers}"
    maps_dir.mkdir()

    def maps():
        result = aggregate(members, setup.grid, setup.inside, spec.output.depth_thresholds_m,
                           spec.output.quantiles, maps_dir)
        write_outputs(result, setup.grid, maps_dir, ensemble=spec.to_dict(),
                      scenario=base.to_dict(), wet_threshold=base.output.wet_threshold_m,
                      title=spec.name)

    _, t_maps = timed(maps)
    return t_prepare + t_cluster + t_maps


def measure(ensemble: Path, members: int, out: Path) -> list[dict]:
    """The table rows, one per configuration (module docstring).

    Each configuration's alone runs follow its ensemble at once, so that both meet the same
    load on a shared machine.
    """
    from floodsph.ensemble.runner import run_ensemble
    from floodsph.ensemble.spec import load_ensemble
    from floodsph.scenario.reader import load_scenario

    spec = replace(load_ensemble(ensemble), members=members)
    base = load_scenario(spec.base)
    rows = []
    with tempfile.TemporaryDirectory(prefix="alone-", dir=out) as tmp:
        scratch = Path(tmp)
        for k, (workers, threads) in enumerate(CONFIGS):
            folder = out / f"w{workers}x{threads}"
            if folder.exists():
                shutil.rmtree(folder)
            manifest = run_ensemble(spec, folder, workers=workers, threads_per_worker=threads,
                                    progress=True)
            wall = float(manifest["wall_time_s"])
            member_folders = sorted((folder / "members").iterdir())
            if k == 0:
                alone_times(member_folders[:1], threads, scratch / "warm-up")
            alone = alone_times(member_folders, threads, scratch)
            mean = statistics.fmean(alone)
            ideal = sum(alone) / workers
            fixed = fixed_times(spec, base, scratch / f"check-{workers}", member_folders,
                                workers, scratch)
            print(f"{workers} x {threads}: ensemble {wall:.1f} s, members alone "
                  f"{sum(alone):.1f} s", flush=True)
            rows.append({
                "workers": workers, "threads": threads, "members": members, "wall_s": wall,
                "members_per_hour": members / wall * 3600.0, "member_alone_s": mean,
                "ideal_s": ideal, "fixed_s": fixed,
                "overhead_per_member_s": (wall - ideal) / members,
                "overhead_pct": 100.0 * (wall - ideal) / members / mean,
                "scheduling_per_member_s": (wall - ideal - fixed) / members,
                "scheduling_pct": 100.0 * (wall - ideal - fixed) / members / mean,
            })
    return rows


def main(argv=None) -> list[dict]:
    from floodsph.output.tables import markdown, write_csv

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--ensemble", type=Path, default=DEFAULT_ENSEMBLE)
    parser.add_argument("--members", type=int, default=8)
    parser.add_argument("--out", type=Path, default=REPO / "results" / "ensemble_throughput")
    args = parser.parse_args(argv)
    if args.members < 2:
        parser.error("--members must be at least 2")
    args.out.mkdir(parents=True, exist_ok=True)
    rows = measure(args.ensemble, args.members, args.out)
    write_csv(args.out / "throughput.csv", rows, COLUMNS)
    command = "python workflows/ensemble_throughput.py " + " ".join(
        sys.argv[1:] if argv is None else argv)
    table = markdown(rows, COLUMNS)
    (args.out / "throughput.md").write_text(f"Made by `{command.strip()}`.\n\n{table}\n",
                                            encoding="utf-8")
    print(table)
    return rows


if __name__ == "__main__":
    main()
