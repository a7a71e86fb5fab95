"""``run_scenario``: one scenario from its TOML to a finished run folder.

The chain (``docs/developing.md``): every test ``floodsph check`` makes, in the one function
both call (``floodsph.run.preflight``: the run folder, with nothing that is not a floodsph
run's and no completed run unless replaced; the inputs -- terrain, particles, hydrographs,
inflow sides, memory -- all before the run folder is touched) -> the folder is locked and
opened (``floodsph.log``, ``scenario.resolved.toml``, ``run.json`` with status
``"running"``) -> ``FloodModel`` (on resume, given the checkpoint's state) -> ``Simulation``
with the mass-balance, progress, recorder and checkpoint callbacks -> maps, gauges and mass
balance (written under temporary names, then renamed) -> quick-looks and ``report.html``
(``floodsph.output.report``) -> ``run.json`` last.

``run.json`` records every ending: ``"completed"``; ``"stopped"`` (``max_steps`` reached
before the end time); ``"interrupted"`` (SIGINT, SIGTERM or SIGHUP:
``floodsph.simulation.stop_signals``; once the time loop runs, a checkpoint is written first
and the manifest is returned);
``"failed"`` (the exception is re-raised, its one-line message is in ``error``). A run that
replaces a completed one is built in ``.floodsph-new/`` and swapped in when it completes.
"""

from __future__ import annotations

import logging
import os
import time
from dataclasses import dataclass
from pathlib import Path

from floodsph.errors import InputError
from floodsph.io.atomic_files import TEMP_PREFIX, atomic_path
from floodsph.io.atomic_files import umask as _umask
from floodsph.io.run_names import LOG_NAME, MASS_BALANCE_NAME, RESOLVED_NAME
from floodsph.run.folder import RunFolder
from floodsph.run.log_file import attach_log, detach_log
from floodsph.run.manifest import new_manifest, now_iso, write_manifest
from floodsph.scenario.config import Scenario
from floodsph.scenario.writer import write_resolved
from floodsph.simulation.schedules import time_tolerance
from floodsph.simulation.stop_signals import StopSignals

log = logging.getLogger(__name__)

#: ``extra`` of the records the command line reports itself, in one line (log file only).
FILE_ONLY = {"file_only": True}
PROGRESS_BAR_S = 0.5


def run_scenario(
    scenario: Scenario,
    out_dir: str | Path | None = None,
    max_steps: int | None = None,
    progress: bool = True,
    overwrite: bool = False,
    threads: int | None = None,
    callbacks=(),
    resume: bool = False,
    stop_requested=None,
) -> dict:
    """Run ``scenario`` and write its run folder; return the manifest (``run.json``).

    Parameters
    ----------
    scenario : Scenario
    out_dir : path, optional
        The run folder; default ``scenario.output_directory`` (``out/<name>``).
    max_steps : int, optional
        Stop after this many time steps (a trial run: status ``"stopped"`` unless the end time
        came first); with local time steps, at the end of the big step that holds the last.
    progress : bool
        Show the progress bar (it is off anyway when stderr is not a terminal).
    overwrite : bool
        Replace a completed (or checkpointed) run in ``out_dir``; the old one stays until the
        new one completes.
    threads : int, optional
        Numba threads; default ``numerics.threads`` (0 = all cores).
    callbacks : sequence of (callable, schedule)
        Extra callbacks for the :class:`~floodsph.simulation.loop.Simulation`.
    resume : bool
        Continue from the latest checkpoint in ``out_dir``; the scenario must equal the
        checkpointed one but for a later ``end_time_s``.
    stop_requested : callable, optional
        ``stop_requested() -> reason or None``, asked after every step: a reason ends the run
        as a stop signal does (checkpoint, status ``"interrupted"``). An ensemble's member
        on a dask worker is stopped this way.

    Raises
    ------
    InputError
        Bad input, a run folder the run may not write, or a run too large for the memory.
    """
    from floodsph.run.preflight import preflight

    with StopSignals(external=stop_requested) as stop:
        used_threads = set_threads(scenario.numerics.threads if threads is None else threads)
        checked = preflight(scenario, out_dir, overwrite=overwrite, resume=resume,
                            threads=used_threads)
        inputs, folder, checkpoint = checked.inputs, checked.folder, checked.checkpoint
        work = folder.open()
        try:
            return _run(scenario, inputs, folder, work, checkpoint, stop,
                        RunOptions(max_steps, progress, used_threads, tuple(callbacks)))
        finally:
            folder.close()


@dataclass(frozen=True)
class RunOptions:
    """The caller's settings of one run (:func:`run_scenario`)."""

    max_steps: int | None
    progress: bool
    threads: int
    callbacks: tuple


def _run(scenario, inputs, folder, work, checkpoint, stop, opts) -> dict:
    """The run proper, in the opened folder ``work``; see :func:`run_scenario`."""
    from floodsph.io.coordinates import coordinates_wkt
    from floodsph.io.raster import crs_label

    log_handler = attach_log(work / LOG_NAME, append=checkpoint is not None)
    manifest = new_manifest(scenario.to_dict())
    manifest.update(
        threads=opts.threads,
        particle_spacing_m=inputs.spacing_m,
        particles_initial=inputs.particles.n,
        volume_initial_m3=inputs.volume_initial_m3,
        max_steps=opts.max_steps,
        warnings=list(inputs.warnings),
        crs=crs_label(inputs.terrain.crs_wkt),
        dem_crs=crs_label(inputs.terrain.source_crs_wkt or inputs.terrain.crs_wkt),
        coordinates_crs=crs_label(coordinates_wkt(inputs.terrain)),
        resumed_from=[] if checkpoint is None else [*checkpoint.resumed_from, checkpoint.t],
        checkpoint_time_s=None if checkpoint is None else checkpoint.t,
    )
    wall_start = time.monotonic() - (0.0 if checkpoint is None else checkpoint.wall_time_s)
    model = mass = recorders = None
    try:
        with atomic_path(work / RESOLVED_NAME) as tmp:
            write_resolved(scenario, tmp)
        manifest["breach_hydrographs"] = write_inflow_hydrographs(scenario, inputs, work)
        write_manifest(work, manifest)
        log.info("run folder %s; %d particles, spacing %g m", folder.path, inputs.particles.n,
                 inputs.spacing_m)
        from floodsph.model.from_scenario import build_model

        model = build_model(scenario, inputs)
        if checkpoint is not None:  # the fresh model takes the checkpoint's state
            from floodsph.simulation.model_state import restore_model

            restore_model(model, checkpoint.model, str(checkpoint.path))
            log.info("resumed from the checkpoint at t = %g s (step %d)", model.t, model.steps)
        _record_setup(manifest, model)
        mass, recorders, sim = _simulation(scenario, inputs, model, folder, opts, checkpoint,
                                           stop, manifest, wall_start)
        stop.armed = True
        sim.run()
        if sim.interrupted:
            path = _save(sim, scenario, opts.threads, manifest, mass, recorders, work,
                         wall_start)
            manifest["status"] = "interrupted"
            manifest["error"] = f"interrupted by {stop.requested}; checkpoint {path}"
            log.warning("run interrupted at t = %g s: %s", model.t, manifest["error"],
                        extra=FILE_ONLY)
        else:
            features = recorders.map_features(inputs)
            _write_outputs(manifest, recorders, mass, work, features)
            reached = model.t >= scenario.end_time_s - time_tolerance(scenario.end_time_s)
            manifest["status"] = "completed" if reached else "stopped"
            manifest["end_time_reached"] = reached
            _finish_manifest(manifest, model, mass, time.monotonic() - wall_start)
            manifest["report"] = recorders.write_report(manifest, mass.rows, features)
    except KeyboardInterrupt as exc:
        manifest["status"] = "interrupted"
        manifest["error"] = str(exc) or "interrupted by the user (KeyboardInterrupt)"
        log.warning("run interrupted at t = %s s", None if model is None else model.t,
                    extra=FILE_ONLY)
        raise
    except BaseException as exc:
        manifest["status"] = "failed"
        manifest["error"] = error_message(exc)
        log.error("run failed: %s", manifest["error"], extra=FILE_ONLY)
        folder.clear_temporaries()
        raise
    finally:
        if recorders is not None:
            recorders.close()
        _finish_manifest(manifest, model, mass, time.monotonic() - wall_start)
        _final_manifest(folder, work, manifest)
        detach_log(*log_handler)
    return manifest


def error_message(exc: BaseException) -> str:
    """The one line a user sees for ``exc``: the message of an input or simulation error,
    the file and reason of an OS error (a full disk, say), else the type and message."""
    from floodsph.simulation.loop import SimulationError

    if isinstance(exc, InputError):
        return str(exc)
    if isinstance(exc, SimulationError):
        return f"the simulation failed: {exc}"
    if isinstance(exc, OSError) and exc.strerror:
        where = f"{exc.filename}: " if exc.filename else ""
        return f"{where}{exc.strerror}"
    return f"{type(exc).__name__}: {exc}"


def _record_setup(manifest: dict, model) -> None:
    manifest["seeds_settled"] = model.state.counters["seeds_settled"]
    manifest["volume_seed_adjustment_m3"] = model.state.volume_seed_adjustment
    if model.state.counters["seeds_settled"]:
        log.info("%d seeds settled next to walls in %d rounds; volume adjusted by %.6g m3",
                 model.state.counters["seeds_settled"], model.state.counters["settle_steps"],
                 model.state.volume_seed_adjustment)


def _write_outputs(manifest: dict, recorders, mass, work: Path, features) -> None:
    """Maps, gauges, snapshots, mass balance and quick-looks (with the walls, sinks and gauges
    of ``features``) of a run that ended its loop.

    They are written into a temporary folder and moved into ``work`` only once all of them
    are complete, so a failure half-way (a full disk) leaves none of them.
    """
    import shutil

    staging = work / f"{TEMP_PREFIX}outputs"
    shutil.rmtree(staging, ignore_errors=True)
    staging.mkdir()
    written = [*recorders.write(staging), mass.write(staging / MASS_BALANCE_NAME)]
    umask = _umask()
    for path in written:
        os.chmod(path, 0o666 & ~umask)
        os.replace(path, work / path.name)
    staging.rmdir()
    log.info("wrote %d map and table files", len(written))
    manifest["pictures"] = recorders.write_pictures(features, mass.rows)
    if isinstance(manifest["pictures"], str):
        log.warning("quick-look %s", manifest["pictures"])


def _final_manifest(folder: RunFolder, work: Path, manifest: dict) -> None:
    """Write ``run.json`` last (a completed replacement is then swapped in, ``run.json`` last
    again). A manifest that cannot be written (a full disk) is logged, not raised over the
    run's own error."""
    try:
        write_manifest(work, manifest)
        if manifest["status"] in ("completed", "stopped"):
            folder.swap_in()
        log.info("run %s: wrote %s", manifest["status"], folder.work / "run.json")
    except OSError as exc:
        log.error("run.json could not be written: %s", error_message(exc))
        if manifest["status"] != "failed":
            raise


def set_threads(threads: int) -> int:
    """Use ``threads`` numba threads (0 = all); returns the number in use."""
    import numba

    available = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # set at import
    n = available if threads == 0 else min(int(threads), available)
    if threads > available:
        log.warning("%d threads asked for, %d available; using %d", threads, available, n)
    numba.set_num_threads(n)
    return n


def write_inflow_hydrographs(scenario: Scenario, inputs, out: Path) -> list[str]:
    """Write the routed hydrograph of each parametric breach (``inflows[i].breach``).

    The file ``breach_hydrograph_<i>.csv`` (time_s, discharge_m3s) in the run folder is what
    the run used, so it can be checked or reused as a ``hydrograph`` input.
    """
    from floodsph.io.hydrograph import write_hydrograph_csv

    names = []
    for i, (inflow, hydrograph) in enumerate(zip(scenario.inflows, inputs.hydrographs,
                                                 strict=True)):
        if inflow.breach is not None:
            name = f"breach_hydrograph_{i}.csv"
            write_hydrograph_csv(out / name, hydrograph.t, hydrograph.Q)
            names.append(name)
    return names


def _terminal() -> bool:
    """Whether stderr is a terminal (the progress bar draws there; else progress lines)."""
    import sys

    return bool(getattr(sys.stderr, "isatty", lambda: False)())


def _simulation(scenario, inputs, model, folder, opts, checkpoint, stop, manifest, wall_start):
    """The mass balance, the recorders and the Simulation with every callback.

    The checkpoint callback comes last, so that a checkpoint holds what every other callback
    recorded at its step.
    """
    from floodsph.simulation.loop import Simulation
    from floodsph.simulation.probes import MassBalance, Progress, ProgressLines
    from floodsph.simulation.recorders import Recorders
    from floodsph.simulation.schedules import IterationInterval, TimeInterval, WallTimeInterval

    work = folder.work
    source = None if checkpoint is None else str(checkpoint.path)
    state = None if checkpoint is None else checkpoint.recorders
    mass = MassBalance(inputs.volume_initial_m3 + model.state.volume_seed_adjustment,
                       None if checkpoint is None else checkpoint.mass_rows)
    bar = Progress(scenario.end_time_s, enabled=opts.progress)
    recorders = Recorders(scenario, inputs.terrain, inputs.gauges, work, state=state,
                          snapshots_from=folder.finished_snapshots(),
                          flux_lines=model.flux_lines, source=source)
    callbacks = [
        (mass, TimeInterval(scenario.output.mass_balance_interval_s)),
        *recorders.callbacks(),
        (bar, WallTimeInterval(PROGRESS_BAR_S)),
        (ProgressLines(scenario.end_time_s, to_stderr=opts.progress and not _terminal()),
         IterationInterval(1)),
        *opts.callbacks,
    ]
    interval = scenario.output.checkpoint_interval_s
    if interval > 0:
        def write_checkpoint(sim) -> None:
            if sim.model.steps > 0:
                _save(sim, scenario, opts.threads, manifest, mass, recorders, work, wall_start)
                write_manifest(work, manifest)

        callbacks.append((write_checkpoint, TimeInterval(interval, align=False)))
    sim = Simulation(model, scenario.end_time_s, callbacks, max_steps=opts.max_steps,
                     should_stop=stop)
    if checkpoint is not None:
        from floodsph.simulation.state_arrays import conform

        saved = conform(sim.state(), checkpoint.simulation, "simulation", source)
        if len(saved["last_call"]) != len(callbacks):
            raise InputError(f"{source}: the field simulation.last_call holds "
                             f"{len(saved['last_call'])} callbacks, this run has "
                             f"{len(callbacks)}")
        sim.restore(saved)
    return mass, recorders, sim


def _save(sim, scenario, threads, manifest, mass, recorders, work, wall_start) -> Path:
    """Write a checkpoint of the run now; ``manifest`` gets its time."""
    from floodsph.simulation.checkpoint import Checkpoint, save_checkpoint
    from floodsph.simulation.model_state import model_state

    model = sim.model
    checkpoint = Checkpoint(scenario=scenario.to_dict(), threads=threads,
                            model=model_state(model),
                            simulation=sim.state(), recorders=recorders.state(),
                            mass_rows=list(mass.rows), resumed_from=manifest["resumed_from"],
                            wall_time_s=time.monotonic() - wall_start)
    started = time.monotonic()
    path = save_checkpoint(work, checkpoint)
    seconds = time.monotonic() - started
    manifest["checkpoint_time_s"] = float(model.t)
    manifest["checkpoint_bytes"] = path.stat().st_size
    manifest["checkpoints_written"] = manifest.get("checkpoints_written", 0) + 1
    manifest["checkpoint_wall_time_s"] = manifest.get("checkpoint_wall_time_s", 0.0) + seconds
    _finish_manifest(manifest, model, mass, time.monotonic() - wall_start)
    log.info("checkpoint at t = %g s (step %d): %s, %.1f MB in %.2f s", model.t, model.steps,
             path, manifest["checkpoint_bytes"] / 1e6, seconds)
    return path


def _finish_manifest(manifest: dict, model, mass, wall_time: float) -> None:
    from floodsph.boundaries import Inflow, LevelBoundary, Weir

    manifest["finished"] = now_iso()
    manifest["wall_time_s"] = wall_time
    if model is None:
        return
    counters = model.state.counters
    manifest.update(
        sim_time_s=float(model.t),
        steps=int(model.steps),
        particles_max=int(counters.get("particles_max", len(model.particles))),
        particles_final=len(model.particles),
        splits=int(counters.get("splits", 0)),
        merges=int(counters.get("merges", 0)),
        particle_updates=int(counters.get("particle_updates", 0)),
        volume_domain_m3=float(model.volume()),
        volume_in_m3=float(model.state.volume_in),
        volume_out_m3=float(model.state.volume_out),
        inflows=[_inflow_summary(b) for b in model.boundaries if isinstance(b, Inflow)],
        **outflow_summary(model),
    )
    if getattr(model, "flux_lines", None) is not None:
        manifest["flux_lines"] = model.flux_lines.summary()
    weirs = [b for b in model.boundaries if isinstance(b, Weir)]
    if weirs:  # the volume passed over each crest wall (floodsph.boundaries.weir)
        manifest["walls_overtopped_m3"] = {b.name: b.summary() for b in weirs}
    levels = [b for b in model.boundaries if isinstance(b, LevelBoundary)]
    if levels:  # what entered and left at each imposed level (floodsph.boundaries.level)
        manifest["level_boundaries"] = {b.name: b.summary() for b in levels}
    if mass is not None:
        manifest["mass_error_rel"] = mass.budget(model).error_rel


def outflow_summary(model) -> dict:
    """``volume_out_m3`` by where the water left [m3]: ``volume_out_sinks_m3`` (one per sink,
    in the order of ``[[sinks]]`` and the features of their files), ``volume_out_sides_m3``
    (per open side of the DEM), ``volume_out_levels_m3`` (per level boundary, by name) and
    ``volume_out_other_m3`` (off the grid or into nodata elsewhere); together they make
    ``volume_out_m3``."""
    from floodsph.boundaries import LevelBoundary, Sink
    from floodsph.boundaries.open_edges import OpenEdges

    sides: dict[str, float] = {}
    levels: dict[str, float] = {}
    sinks = []
    for boundary in getattr(model, "boundaries", ()):
        if isinstance(boundary, OpenEdges):
            sides.update(boundary.volume_out_sides)
        elif isinstance(boundary, Sink):
            sinks.append(float(boundary.volume_out))
        elif isinstance(boundary, LevelBoundary):
            levels[boundary.name] = float(boundary.volume_out)
    return {"volume_out_sinks_m3": sinks, "volume_out_sides_m3": sides,
            "volume_out_levels_m3": levels,
            "volume_out_other_m3": float(model.state.volume_out_other)}


def _inflow_summary(inflow) -> dict:
    """Injected volume of an inflow against its hydrograph up to the end of the run."""
    return {
        "name": inflow.name,
        "volume_injected_m3": float(inflow.volume_in),
        "volume_hydrograph_m3": float(inflow.hydrograph.volume(0.0, inflow.t)),
    }
