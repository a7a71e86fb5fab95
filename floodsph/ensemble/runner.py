"""One ensemble from start to finish: :func:`run_ensemble` (what ``floodsph ensemble`` runs).

1. Load the base scenario, draw the samples, build and check every member
   (:mod:`floodsph.ensemble.members`): a refused value stops everything before any member runs
   or any file is written.
2. Check the ensemble folder: new or empty, or an earlier ensemble with ``resume`` (run only
   the members that are missing) or ``overwrite`` (run every member again).
3. Prepare the base scenario's inputs once: its map grid and DEM mask (the maps' common grid)
   and its peak-memory estimate, which sizes the local cluster
   (:func:`floodsph.ensemble.engine.plan_workers`).
4. With ``resume``, keep the members whose folder holds a completed run of their scenario.
5. Write the other members' folders and run them on the cluster; a member that fails is
   recorded and the others go on.
6. Aggregate the completed members' maps (:mod:`floodsph.ensemble.aggregate`), write them
   (:mod:`floodsph.ensemble.outputs`), ``samples.csv`` and ``ensemble.json``.

Steps 1-3 are :func:`prepare_ensemble`, which ``floodsph check ENSEMBLE`` runs too.

``samples.csv`` and ``ensemble.json`` are written however the ensemble ends (completed,
failed, or interrupted by Ctrl-C, SIGTERM or SIGHUP). On an interruption the cluster is
closed, and each member that was running is recorded as ``interrupted``: in its own
``run.json`` (which its killed worker left at ``running``) and in ``samples.csv``.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from floodsph.ensemble.manifest import (
    ENSEMBLE_JSON,
    final_status,
    new_manifest,
    read_manifest,
    write_manifest,
    write_samples,
)
from floodsph.ensemble.members import MEMBERS_DIR, MemberResult, MemberTask
from floodsph.ensemble.spec import EnsembleSpec
from floodsph.errors import InputError
from floodsph.output.grid import OutputGrid
from floodsph.run.manifest import now_iso

if TYPE_CHECKING:
    from floodsph.ensemble.sampling import Samples
    from floodsph.scenario.config import Scenario

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class EnsemblePlan:
    """An ensemble checked and ready to run (:func:`prepare_ensemble`)."""

    out: Path
    base: Scenario
    samples: Samples
    members: list
    previous: dict | None
    setup: BaseSetup


@dataclass(frozen=True)
class BaseSetup:
    """What every member shares: the map grid, its DEM mask and a member's memory estimate;
    and the base scenario's ``floodsph check`` summary (``summary_lines``)."""

    grid: OutputGrid
    inside: np.ndarray
    member_bytes: int
    summary: tuple[str, ...] = ()


def run_ensemble(spec: EnsembleSpec, out_dir: str | Path | None = None, *,
                 workers: int | None = None, threads_per_worker: int | None = None,
                 scheduler: str | None = None, resume: bool = False, overwrite: bool = False,
                 progress: bool = True) -> dict:
    """Run the ensemble ``spec`` into ``out_dir`` (default ``out/<name>`` beside the file).

    Parameters
    ----------
    workers, threads_per_worker : int, optional
        Local cluster size and numba threads per member (default: from the cores and the
        members' memory estimate).
    scheduler : str, optional
        Address of an existing dask scheduler (``tcp://host:8786``) instead of a local
        cluster.
    resume : bool
        Keep the members already completed with the same sampled scenario; run the rest.
    overwrite : bool
        Run every member again in an existing ensemble folder.
    progress : bool
        The progress bar over members (off anyway when stderr is not a terminal).

    Returns the manifest (``ensemble.json``).

    Raises
    ------
    InputError
        A bad ensemble or base scenario, a sampled value the scenario refuses, an ensemble
        folder that may not be used, or dask.distributed missing.
    """
    from floodsph.ensemble.members import completed_manifest
    from floodsph.simulation.stop_signals import StopSignals

    wall_start = time.monotonic()
    plan = prepare_ensemble(spec, out_dir, resume=resume, overwrite=overwrite)
    out, base, samples, members, previous, setup = (
        plan.out, plan.base, plan.samples, plan.members, plan.previous, plan.setup)
    results: dict[str, MemberResult] = {}
    if resume:
        for member in members:
            kept = completed_manifest(member)
            if kept is not None:
                results[member.id] = MemberResult(member.id, "completed",
                                                  kept.get("wall_time_s"))
    to_run = [m for m in members if m.id not in results]
    out.mkdir(parents=True, exist_ok=True)
    manifest = new_manifest(spec.to_dict(), spec.members, scheduler)
    manifest["members_kept"] = len(results)
    write_manifest(out, manifest)
    log.info("ensemble %s: %d members, %d kept from an earlier run, %d to run; folder %s",
             spec.name, len(members), len(results), len(to_run), out)
    try:
        with StopSignals(during="") as stop:
            if to_run:
                _run_members(to_run, out, manifest, results, setup, scheduler, workers,
                             threads_per_worker, resume or overwrite, progress, stop)
            _write_maps(spec, base, members, results, setup, out, manifest, previous)
    except KeyboardInterrupt as exc:
        manifest["status"] = "interrupted"
        manifest["error"] = str(exc) or "interrupted by the user (KeyboardInterrupt)"
        _record_interrupted(to_run, results, manifest["error"])
        raise
    except BaseException as exc:
        manifest["status"] = "failed"
        manifest["error"] = str(exc) if isinstance(exc, InputError) else (
            f"{type(exc).__name__}: {exc}")
        raise
    finally:
        manifest["members_completed"] = sum(r.status == "completed" for r in results.values())
        manifest["members_interrupted"] = sum(r.status == "interrupted"
                                              for r in results.values())
        manifest["members_failed"] = (len(results) - manifest["members_completed"]
                                      - manifest["members_interrupted"])
        manifest["finished"] = now_iso()
        manifest["wall_time_s"] = time.monotonic() - wall_start
        write_samples(out, samples.keys, [m.id for m in members], samples.rows, results)
        write_manifest(out, manifest)
    return manifest


def prepare_ensemble(spec: EnsembleSpec, out_dir: str | Path | None = None, *,
                     resume: bool = False, overwrite: bool = False) -> EnsemblePlan:
    """Every check before a member runs: the base scenario and its inputs (with their
    memory estimate), the sampled values, every member's scenario, the ensemble folder and
    dask.distributed. Nothing is written.

    Raises InputError (see :func:`run_ensemble`).
    """
    from floodsph.ensemble.engine import require_distributed
    from floodsph.ensemble.members import build_members
    from floodsph.ensemble.sampling import draw_samples
    from floodsph.scenario.reader import load_scenario

    if resume and overwrite:
        raise InputError("--resume keeps the completed members and --overwrite runs them "
                         "again: give one of them")
    out = Path(out_dir if out_dir is not None else spec.output_directory).resolve()
    base = load_scenario(spec.base)
    samples = draw_samples(spec)
    members = build_members(spec, base, samples, out)
    previous = _check_folder(out, resume, overwrite)
    require_distributed()
    return EnsemblePlan(out, base, samples, members, previous, prepare_base(base))


def check_extreme_members(spec: EnsembleSpec, plan: EnsemblePlan) -> list[str]:
    """Prepare the inputs (``floodsph.inputs.prepare.prepare_inputs``) of the members that
    drew the lowest and the highest value of each parameter, where a sampled value is most
    likely refused by the inputs (a reservoir level below its bed, say); returns their ids.

    Members that scale a raster are left out (their rasters are written when they run).
    """
    import tomllib

    from floodsph.inputs.prepare import prepare_inputs
    from floodsph.scenario.reader import scenario_from_dict

    picked: list[int] = []
    for j in range(len(plan.samples.keys)):
        column = [row[j] for row in plan.samples.rows]
        if all(isinstance(v, int | float) for v in column):
            picked += [int(np.argmin(column)), int(np.argmax(column))]
    checked = []
    for m in dict.fromkeys(picked):
        member = plan.members[m]
        if member.rasters:
            continue
        source = f"{spec.path.name}: member {member.id}"
        scenario = scenario_from_dict(tomllib.loads(member.scenario_text), source=source,
                                      base_dir=spec.path.parent)
        try:
            prepare_inputs(scenario)
        except InputError as exc:
            drawn = "; ".join(f"{key} = {value:.6g}" if isinstance(value, float)
                              else f"{key} = {value}"
                              for key, value in zip(plan.samples.keys, plan.samples.rows[m],
                                                    strict=True))
            raise InputError(f"{exc} (the member's sampled values: {drawn})") from None
        checked.append(member.id)
    return checked


def _record_interrupted(to_run, results: dict, reason: str) -> None:
    """Members that were running when the ensemble was interrupted: ``interrupted`` in
    ``results`` and in their own ``run.json`` (left at ``running`` by the closed worker)."""
    from floodsph.io.run_names import STAGING_DIR
    from floodsph.run.manifest import read_manifest, write_manifest

    for member in to_run:
        if member.id in results:
            continue
        for folder in (member.folder / STAGING_DIR, member.folder):  # a replacing run first
            manifest = read_manifest(folder)
            if manifest is not None and manifest.get("status") == "running":
                manifest.update(status="interrupted", error=f"the ensemble was {reason}",
                                finished=now_iso())
                write_manifest(folder, manifest)
                results[member.id] = MemberResult(member.id, "interrupted",
                                                  manifest.get("wall_time_s"),
                                                  manifest["error"])
                break


def _check_folder(out: Path, resume: bool, overwrite: bool) -> dict | None:
    """Refuse a folder the ensemble may not write; returns the earlier manifest, if any."""
    if not out.exists():
        return None
    if not out.is_dir():
        raise InputError(f"{out}: exists and is not a folder")
    previous = read_manifest(out)
    if previous is not None or (out / MEMBERS_DIR).exists():
        if not (resume or overwrite):
            raise InputError(f"{out}: already holds an ensemble ({ENSEMBLE_JSON}); pass "
                             "--resume to run only its missing members, or --overwrite to run "
                             "every member again")
        return previous
    if any(out.iterdir()):
        raise InputError(f"{out}: is not empty and holds no ensemble; choose another output "
                         "folder (-o)")
    return None


def prepare_base(base) -> BaseSetup:
    """The base scenario's inputs: the map grid, DEM mask and memory estimate (checked)."""
    from floodsph.ensemble.aggregate import dem_mask
    from floodsph.inputs.memory import available_memory
    from floodsph.inputs.prepare import prepare_inputs, summary_lines

    inputs = prepare_inputs(base)  # refuses a member too large for the memory
    grid = OutputGrid.from_terrain(inputs.terrain, base.output.resolution_m)
    summary = tuple(summary_lines(base, inputs, available_memory()[0]))
    return BaseSetup(grid, dem_mask(inputs.terrain, grid), inputs.memory.total, summary)


def _run_members(to_run, out: Path, manifest, results, setup: BaseSetup, scheduler, workers,
                 threads, replace: bool, progress: bool, stop) -> None:
    """Write the members' folders and run them on the cluster; results go into ``results``."""
    from floodsph.ensemble.engine import (
        WorkerPlan,
        cluster_workers,
        open_client,
        plan_workers,
        run_tasks,
        thread_budget,
    )
    from floodsph.ensemble.members import write_member
    from floodsph.inputs.memory import available_memory

    for member in to_run:
        write_member(member)
    if scheduler:
        plan = WorkerPlan(workers or 0, threads or 1)
    else:
        available, _ = available_memory()
        plan = plan_workers(len(to_run), thread_budget(), setup.member_bytes, available,
                            workers, threads)
    with open_client(plan, scheduler) as client:
        manifest["workers"] = cluster_workers(client)
        manifest["threads_per_worker"] = plan.threads_per_worker
        write_manifest(out, manifest)
        log.info("running %d members on %d workers x %d threads (%s)", len(to_run),
                 manifest["workers"], plan.threads_per_worker, manifest["scheduler"])
        tasks = [MemberTask(m.id, str(m.folder), plan.threads_per_worker, replace)
                 for m in to_run]
        run_tasks(client, tasks, lambda r: results.__setitem__(r.id, r), progress, stop)


def _write_maps(spec, base, members, results, setup: BaseSetup, out: Path, manifest,
                previous) -> None:
    """Aggregate the completed members and write the maps; the final status."""
    from floodsph.ensemble.aggregate import aggregate
    from floodsph.ensemble.outputs import remove_previous, write_outputs

    completed = [m.folder for m in members
                 if m.id in results and results[m.id].status == "completed"]
    failed = len(members) - len(completed)
    if previous is not None:
        pictures = previous.get("pictures")
        remove_previous(out, [*previous.get("maps", []),
                              *(pictures if isinstance(pictures, list) else [])])
    if not completed:
        manifest["status"] = "failed"
        manifest["error"] = f"no member completed ({failed} failed; see samples.csv)"
        return
    maps = aggregate(completed, setup.grid, setup.inside, spec.output.depth_thresholds_m,
                     spec.output.quantiles, out)
    written = write_outputs(maps, setup.grid, out, ensemble=spec.to_dict(),
                            scenario=base.to_dict(), wet_threshold=base.output.wet_threshold_m,
                            title=spec.name)
    if isinstance(written.pictures, str):
        log.warning("quick-look %s", written.pictures)
    manifest.update(maps=written.maps, pictures=written.pictures,
                    status=final_status(len(completed), failed))
