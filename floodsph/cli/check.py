"""``floodsph check FILE``: validate a scenario (or an ensemble) and its inputs, print what
would run."""

from __future__ import annotations

from pathlib import Path

import click


@click.command("check")
@click.argument("scenario", type=click.Path(dir_okay=False, path_type=Path))
@click.option("-o", "--output", type=str, default=None,
              help="The run (or ensemble) folder to check (default: output.directory, or "
                   "out/<name>).")
def command(scenario: Path, output) -> None:
    """Validate SCENARIO (a scenario or an ensemble TOML file) without running it.

    A scenario: makes every test a run makes before its first step (the same function), then
    prints the domain size, CRS, water volumes, particle count and the estimated peak memory.
    An ensemble (a file with an [ensemble] table): makes every test `floodsph ensemble` makes
    before a member runs -- the base scenario and its inputs, the sampled values and every
    member's scenario -- plus the inputs of the members with each parameter's lowest and
    highest value, and prints the members and the base scenario's summary. Exits with
    status 2 and one message on any input problem, including a run whose memory estimate
    exceeds the memory available, and a folder that a run could not write (a file, not
    writable, holding files that are not a run's).
    """
    from floodsph.scenario.schema import read_toml

    output = None if output is None else Path(output)
    data = read_toml(scenario, "scenario")
    if "ensemble" in data and "scenario" not in data:
        _check_ensemble(scenario, output)
    else:
        _check_scenario(scenario, output)


def _check_scenario(path: Path, output: Path | None) -> None:
    from floodsph.inputs.memory import available_memory
    from floodsph.inputs.prepare import summary_lines
    from floodsph.run.preflight import preflight
    from floodsph.scenario.reader import load_scenario

    sc = load_scenario(path)
    inputs = preflight(sc, output, overwrite=True).inputs
    available, _ = available_memory()
    for line in summary_lines(sc, inputs, available):
        click.echo(line)
    click.echo("OK: the scenario is valid.")


def _check_ensemble(path: Path, output: Path | None) -> None:
    from floodsph.ensemble.runner import check_extreme_members, prepare_ensemble
    from floodsph.ensemble.spec import load_ensemble

    spec = load_ensemble(path)
    plan = prepare_ensemble(spec, output, overwrite=True)
    click.echo(f"Ensemble:        {spec.name} ({spec.path})")
    click.echo(f"Members:         {spec.members} ({spec.sampling.value} sampling, seed "
               f"{spec.seed}); every member's scenario is valid")
    for p in spec.parameters:
        law = dict(p.distribution.to_dict())
        shape = ", ".join(f"{k} = {v}" for k, v in law.items() if k != "distribution")
        click.echo(f"Parameter:       {p.key.text}: {law['distribution']} ({shape}), "
                   f"mode {p.mode.value}")
    extremes = check_extreme_members(spec, plan)
    if extremes:
        click.echo(f"Inputs checked:  members {', '.join(extremes)} (the lowest and highest "
                   "value of each parameter)")
    click.echo(f"Folder:          {plan.out}")
    for line in plan.setup.summary:
        click.echo(line.replace("Scenario:       ", "Base scenario:  ", 1))
    click.echo("OK: the ensemble is valid.")
