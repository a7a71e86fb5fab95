"""The public calls of the package root: run a scenario from Python and get its results.

``floodsph.run_scenario`` is :func:`run_scenario` here: the run chain of
:func:`floodsph.run.pipeline.run_scenario` (which returns the bare ``run.json`` dict, as the command
line and the workflows use it), returning a :class:`~floodsph.run.results.RunResult` instead.
See ``docs/api.md``.
"""

from __future__ import annotations

from pathlib import Path

from floodsph.run.results import RunResult
from floodsph.scenario.config import Scenario
from floodsph.scenario.reader import load_scenario


def run_scenario(
    scenario: Scenario | str | Path,
    out_dir: str | Path | None = None,
    *,
    max_steps: int | None = None,
    progress: bool = True,
    overwrite: bool = False,
    threads: int | None = None,
    resume: bool = False,
    callbacks=(),
) -> RunResult:
    """Run a scenario (a :class:`~floodsph.scenario.config.Scenario` or the path of its TOML file)
    into its run folder and return the :class:`~floodsph.run.results.RunResult`.

    ``out_dir`` defaults to the scenario's ``output.directory`` (``out/<name>`` beside the
    scenario file). The keyword options are those of :func:`floodsph.run.pipeline.run_scenario`:
    ``max_steps`` (a trial run), ``progress`` (the progress bar), ``overwrite`` (replace a
    completed run), ``threads`` (numba threads, 0 = all), ``resume`` (continue from the last
    checkpoint), ``callbacks`` (extra ``(callable, schedule)`` pairs).

    Raises
    ------
    floodsph.errors.InputError
        Bad input, a run folder the run may not write, or a run too large for the memory.
    """
    from floodsph.run import pipeline as run

    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    folder = Path(out_dir) if out_dir is not None else scenario.output_directory
    manifest = run.run_scenario(scenario, folder, max_steps=max_steps, progress=progress,
                                overwrite=overwrite, threads=threads, callbacks=callbacks,
                                resume=resume)
    return RunResult(folder.resolve(), manifest)
