"""Every test a run makes before its first step, in one function.

``floodsph check`` and :func:`floodsph.run.pipeline.run_scenario` both call :func:`preflight`,
so a scenario that ``check`` passes is one that ``run`` starts: the options (``--overwrite``
with ``--resume``), the run folder (``floodsph.run.folder.RunFolder.check``), every input
(``floodsph.inputs.prepare.prepare_inputs``: hydrographs, DEM, roughness, geometry on the DEM,
water to move, the side each inflow enters on, gauges, the memory estimate) and, on
``--resume``, the checkpoint against the scenario. Nothing here writes a file, compiles a
kernel or builds the model.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from floodsph.errors import InputError
from floodsph.run.folder import RunFolder
from floodsph.scenario.config import Scenario
from floodsph.simulation.schedules import time_tolerance

if TYPE_CHECKING:
    from floodsph.inputs.prepare import Inputs
    from floodsph.simulation.checkpoint import Checkpoint

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Preflight:
    """What :func:`preflight` checked: the run folder, the inputs and, on resume, the
    checkpoint to continue from (else None)."""

    folder: RunFolder
    inputs: Inputs
    checkpoint: Checkpoint | None


def preflight(scenario: Scenario, out_dir: str | Path | None = None, *,
              overwrite: bool = False, resume: bool = False,
              threads: int | None = None) -> Preflight:
    """Check ``scenario`` for a run into ``out_dir`` (default ``scenario.output_directory``).

    ``threads`` (the number the run uses) is compared with a resumed checkpoint's.

    Raises
    ------
    InputError
        Bad input, a run folder the run may not write, a run too large for the memory, or a
        checkpoint the scenario cannot continue.
    """
    from floodsph.inputs.prepare import prepare_inputs

    if overwrite and resume:
        raise InputError("--overwrite and --resume exclude each other: resume continues the "
                         "run in the folder, overwrite replaces it")
    out = Path(out_dir) if out_dir is not None else scenario.output_directory
    folder = RunFolder(out, scenario.input_files(), overwrite=overwrite, resume=resume)
    folder.check()
    inputs = prepare_inputs(scenario)
    _check_crest_walls(scenario, inputs)
    checkpoint = _resumable(folder, scenario, inputs, threads) if resume else None
    return Preflight(folder, inputs, checkpoint)


def _check_crest_walls(scenario: Scenario, inputs) -> None:
    """The crests and breaches of the walls on their walls and the DEM (a breach beyond its
    wall, a crest below the ground), as the model will build them
    (``floodsph.model.from_scenario.weirs``)."""
    from dataclasses import replace

    from floodsph.model.from_scenario import weirs

    if any(wall.crest_m is not None for wall in scenario.walls):
        numerics = replace(scenario.numerics, particle_spacing_m=inputs.spacing_m)
        weirs(inputs, numerics, scenario.path.name)


def _resumable(folder: RunFolder, scenario: Scenario, inputs, threads: int | None):
    """The checkpoint to resume from, refused unless the scenario is the same."""
    from floodsph.simulation.checkpoint import (
        load_checkpoint,
        plain_scenario,
        scenario_difference,
    )

    directory = folder.checkpoint_dir()
    if directory is None:
        raise InputError(f"{folder.path}: no checkpoint to resume from")
    checkpoint = load_checkpoint(directory)
    where = scenario_difference(checkpoint.scenario, plain_scenario(scenario.to_dict()))
    if where is not None:
        raise InputError(f"{scenario.path}: {where} differs from the checkpointed run's "
                         f"({directory}); only scenario.end_time_s may change on --resume")
    if checkpoint.t >= scenario.end_time_s - time_tolerance(scenario.end_time_s):
        raise InputError(f"{scenario.path}: scenario.end_time_s = {scenario.end_time_s:g} s "
                         f"is not after the checkpoint at t = {checkpoint.t:g} s; raise it "
                         "to extend the run")
    if threads is not None and checkpoint.threads != threads:
        log.warning("the checkpoint was written with %d threads, this run has %d: the resumed "
                    "run may differ from an uninterrupted one in the last digits",
                    checkpoint.threads, threads)
    return checkpoint
