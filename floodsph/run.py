"""``run_scenario``: one scenario from its TOML to a finished run folder.

The chain (architecture.md 3.2): inputs (terrain, particles, hydrographs; every input check
happens here, before the run folder is touched) -> run folder (``floodsph.log``,
``scenario.resolved.toml``, ``run.json`` with status ``"running"``) -> ``FloodModel`` ->
``Simulation`` with the mass-balance, progress and recorder callbacks (map envelopes,
gauges, snapshots: ``floodsph.recorders``) -> maps and gauges (written only when the run
completes) -> ``run.json`` with the final status.

``run.json`` is rewritten (atomically) however the run ends: ``"completed"``,
``"interrupted"`` (Ctrl-C; the KeyboardInterrupt is re-raised) or ``"failed"`` (the exception
is re-raised, its message is in ``error``). A folder holding a completed run is refused unless
``overwrite=True``; known output files of an earlier run are deleted before a new run starts,
so no stale map survives next to a new manifest.
"""

from __future__ import annotations

import logging
import time
from pathlib import Path

from floodsph.errors import InputError
from floodsph.manifest import new_manifest, now_iso, read_manifest, write_manifest
from floodsph.scenario import Edges, Scenario, write_resolved
from floodsph.schedules import time_tolerance

log = logging.getLogger(__name__)

LOG_NAME = "floodsph.log"
#: Quick-look PNGs written by ``floodsph.output.write_pictures`` when matplotlib is installed.
PICTURE_NAMES = ("max_depth.png", "hazard_uk.png", "hazard_arr.png", "arrival_time.png")
RESOLVED_NAME = "scenario.resolved.toml"
MASS_BALANCE_NAME = "mass_balance.csv"
#: Files of the run folder (scenario-format.md) removed before a new run writes its own.
RUN_FILES = (
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
    "snapshots.nc",
    "gauges.csv",
    MASS_BALANCE_NAME,
    "run.json",
    RESOLVED_NAME,
    LOG_NAME,
    *PICTURE_NAMES,
)
PROGRESS_BAR_S = 0.5
PROGRESS_LOG_S = 30.0


def run_scenario(
    scenario: Scenario,
    out_dir: str | Path | None = None,
    max_steps: int | None = None,
    progress: bool = True,
    overwrite: bool = False,
    threads: int | None = None,
    callbacks=(),
) -> dict:
    """Run ``scenario`` and write its run folder; return the manifest (``run.json``).

    Parameters
    ----------
    scenario : Scenario
    out_dir : path, optional
        The run folder; default ``scenario.output_directory`` (``out/<name>``).
    max_steps : int, optional
        Stop after this many steps (a trial run; ``run.json`` has ``end_time_reached``).
    progress : bool
        Show the progress bar (it is off anyway when stderr is not a terminal).
    overwrite : bool
        Replace a completed run in ``out_dir``.
    threads : int, optional
        Numba threads; default ``numerics.threads`` (0 = all cores).
    callbacks : sequence of (callable, schedule)
        Extra callbacks for the :class:`~floodsph.simulation.Simulation`.

    Raises
    ------
    InputError
        Bad input, an existing completed run, or a run too large for the available memory.
    """
    from floodsph.inputs import prepare_inputs
    from floodsph.memory import check_memory

    out = Path(out_dir) if out_dir is not None else scenario.output_directory
    _check_folder(out, overwrite)
    used_threads = set_threads(scenario.numerics.threads if threads is None else threads)
    inputs = prepare_inputs(scenario)
    check_memory(inputs.memory, str(scenario.path.name))

    out.mkdir(parents=True, exist_ok=True)
    for name in RUN_FILES:
        (out / name).unlink(missing_ok=True)
    for path in out.glob("breach_hydrograph_*.csv"):
        path.unlink()
    log_handler = _attach_log(out / LOG_NAME)
    manifest = new_manifest(scenario.to_dict())
    manifest.update(
        threads=used_threads,
        particle_spacing_m=inputs.spacing_m,
        particles_initial=inputs.particles.n,
        volume_initial_m3=inputs.volume_initial_m3,
        max_steps=max_steps,
    )
    wall_start = time.monotonic()
    model = None
    probes = ()
    try:
        write_resolved(scenario, out / RESOLVED_NAME)
        manifest["breach_hydrographs"] = write_inflow_hydrographs(scenario, inputs, out)
        write_manifest(out, manifest)
        log.info("run folder %s; %d particles, spacing %g m", out, inputs.particles.n,
                 inputs.spacing_m)
        model = build_model(scenario, inputs)
        manifest["seeds_settled"] = model.counters["seeds_settled"]
        manifest["volume_seed_adjustment_m3"] = model.volume_seed_adjustment
        if model.counters["seeds_settled"]:
            log.info("%d seeds settled next to walls in %d rounds; volume adjusted by %.6g m3",
                     model.counters["seeds_settled"], model.counters["settle_steps"],
                     model.volume_seed_adjustment)
        probes, sim = _simulation(scenario, inputs, model, out, max_steps, progress, callbacks)
        sim.run()
        for probe in probes:
            probe.close()
        written = probes[-1].write()
        log.info("wrote %d map and gauge files", len(written))
        manifest["pictures"] = probes[-1].write_pictures()
        if isinstance(manifest["pictures"], str):
            log.warning("quick-look %s", manifest["pictures"])
        manifest["status"] = "completed"
        manifest["end_time_reached"] = model.t >= scenario.end_time_s - time_tolerance(
            scenario.end_time_s
        )
    except KeyboardInterrupt:
        manifest["status"] = "interrupted"
        manifest["error"] = "interrupted by the user (KeyboardInterrupt)"
        log.warning("run interrupted at t = %s s", None if model is None else model.t)
        raise
    except BaseException as exc:
        manifest["status"] = "failed"
        manifest["error"] = str(exc) if isinstance(exc, InputError) else (
            f"{type(exc).__name__}: {exc}")
        log.error("run failed: %s", manifest["error"])
        raise
    finally:
        for probe in probes:
            probe.close()
        _finish_manifest(manifest, model, probes, time.monotonic() - wall_start)
        write_manifest(out, manifest)
        log.info("run %s: wrote %s", manifest["status"], out / "run.json")
        _detach_log(*log_handler)
    return manifest


def _check_folder(out: Path, overwrite: bool) -> None:
    """Refuse to replace a completed run unless asked to."""
    previous = read_manifest(out)
    if previous is not None and previous.get("status") == "completed" and not overwrite:
        raise InputError(
            f"{out}: already holds a completed run (run.json); pass --overwrite to replace it "
            "or choose another --output folder"
        )


def set_threads(threads: int) -> int:
    """Use ``threads`` numba threads (0 = all); returns the number in use."""
    import numba

    available = numba.config.NUMBA_NUM_THREADS
    n = available if threads == 0 else min(int(threads), available)
    if threads > available:
        log.warning("%d threads asked for, %d available; using %d", threads, available, n)
    numba.set_num_threads(n)
    return n


def build_model(scenario: Scenario, inputs):
    """The FloodModel of ``scenario`` from prepared inputs, with its open boundaries."""
    from floodsph.model import FloodModel, Numerics
    from floodsph.refinement import Refiner

    num = scenario.numerics
    numerics = Numerics(
        cfl=num.cfl,
        kappa=num.kappa,
        spacing=inputs.spacing_m,
        density_tol=num.density_tol,
        stabilisation=num.stabilisation.value,
        friction_depth_floor=num.friction_depth_floor_m,
        max_slope=num.max_slope,
        time_stepping=num.time_stepping.value,
        step_levels=num.step_levels,
    )
    return FloodModel(
        inputs.terrain,
        inputs.particles,
        numerics,
        walls=inputs.walls,
        closed_edges=_closed_edges(scenario.terrain),
        boundaries=open_boundaries(scenario, inputs, numerics),
        refiner=Refiner.from_settings(num.refinement.value, inputs.spacing_m,
                                      area_max=num.refine_area_max,
                                      area_min=num.refine_area_min,
                                      d_min=num.refine_d_min_m,
                                      max_level=num.refine_max_level),
    )


def _closed_edges(terrain) -> bool | tuple[str, ...]:
    """``FloodModel(closed_edges=...)``: True, False, or the sides kept closed."""
    if terrain.edges is Edges.CLOSED:
        return True
    return terrain.closed_sides or False


def open_boundaries(scenario: Scenario, inputs, numerics) -> list:
    """The ``[[inflows]]`` sections and ``[[sinks]]`` polygons as model boundaries."""
    import numpy as np

    from floodsph.boundaries import Inflow, Sink

    terrain = inputs.terrain
    source = scenario.path.name
    out = []
    for i, (inflow, hydrograph) in enumerate(zip(scenario.inflows, inputs.hydrographs,
                                                 strict=True)):
        line = np.column_stack(terrain.to_local(*np.asarray(inflow.line, dtype=np.float64).T))
        out.append(Inflow(line, hydrograph, numerics.spacing, numerics.kappa, terrain,
                          direction=inflow.direction, name=f"{source}: inflows[{i}]"))
    reach = 4.0 * numerics.kappa * numerics.spacing
    for sink in scenario.sinks:
        polygon = np.column_stack(terrain.to_local(*np.asarray(sink.polygon, dtype=np.float64).T))
        out.append(Sink(polygon, terrain, reach))
    return out


def write_inflow_hydrographs(scenario: Scenario, inputs, out: Path) -> list[str]:
    """Write the routed hydrograph of each parametric breach (``inflows[i].breach``).

    The file ``breach_hydrograph_<i>.csv`` (time_s, discharge_m3s) in the run folder is what
    the run used, so it can be checked or reused as a ``hydrograph`` input.
    """
    from floodsph.hydrograph import write_hydrograph_csv

    names = []
    for i, (inflow, hydrograph) in enumerate(zip(scenario.inflows, inputs.hydrographs,
                                                 strict=True)):
        if inflow.breach is not None:
            name = f"breach_hydrograph_{i}.csv"
            write_hydrograph_csv(out / name, hydrograph.t, hydrograph.Q)
            names.append(name)
    return names


def _simulation(scenario, inputs, model, out, max_steps, progress, extra):
    """The Simulation and its probes (mass balance, progress bar, recorders; closed by caller)."""
    from floodsph.probes import MassBalance, Progress, log_progress
    from floodsph.recorders import Recorders
    from floodsph.schedules import TimeInterval, WallTimeInterval
    from floodsph.simulation import Simulation

    mass = MassBalance(out / MASS_BALANCE_NAME,
                       inputs.volume_initial_m3 + model.volume_seed_adjustment)
    bar = Progress(scenario.end_time_s, enabled=progress)
    recorders = Recorders(scenario, inputs.terrain, inputs.gauges, out)
    callbacks = [
        (mass, TimeInterval(scenario.output.mass_balance_interval_s)),
        *recorders.callbacks(),
        (bar, WallTimeInterval(PROGRESS_BAR_S)),
        (log_progress, WallTimeInterval(PROGRESS_LOG_S)),
        *extra,
    ]
    probes = (mass, bar, recorders)
    return probes, Simulation(model, scenario.end_time_s, callbacks, max_steps=max_steps)


def _finish_manifest(manifest: dict, model, probes, wall_time: float) -> None:
    manifest["finished"] = now_iso()
    manifest["wall_time_s"] = wall_time
    if model is None:
        return
    counters = getattr(model, "counters", {})
    manifest.update(
        sim_time_s=float(model.t),
        steps=int(model.steps),
        particles_max=int(counters.get("particles_max", len(model.particles))),
        particles_final=len(model.particles),
        splits=int(counters.get("splits", 0)),
        merges=int(counters.get("merges", 0)),
        particle_updates=int(counters.get("particle_updates", 0)),
        volume_domain_m3=float(model.volume()),
        volume_in_m3=float(model.volume_in),
        volume_out_m3=float(model.volume_out),
        inflows=[_inflow_summary(b) for b in model.boundaries if hasattr(b, "pending")],
    )
    if probes:
        manifest["mass_error_rel"] = probes[0].budget(model)[4]


def _inflow_summary(inflow) -> dict:
    """Injected volume of an inflow against its hydrograph up to the end of the run."""
    return {
        "name": inflow.name,
        "volume_injected_m3": float(inflow.volume_in),
        "volume_hydrograph_m3": float(inflow.hydrograph.volume(0.0, inflow.t)),
    }


def _attach_log(path: Path) -> tuple[logging.Handler, int]:
    """Send floodsph's INFO (and higher) records to ``path`` for the length of the run.

    Returns the handler and the logger level to restore afterwards.
    """
    handler = logging.FileHandler(path, encoding="utf-8")
    handler.setLevel(logging.INFO)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    logger = logging.getLogger("floodsph")
    previous = logger.level
    if logger.getEffectiveLevel() > logging.INFO:
        logger.setLevel(logging.INFO)
    logger.addHandler(handler)
    return handler, previous


def _detach_log(handler: logging.Handler, previous_level: int) -> None:
    logger = logging.getLogger("floodsph")
    logger.removeHandler(handler)
    logger.setLevel(previous_level)
    handler.close()
