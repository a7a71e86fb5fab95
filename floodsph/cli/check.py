"""``floodsph check SCENARIO``: validate a scenario and its inputs, print what would run."""

from __future__ import annotations

from pathlib import Path

import click


@click.command("check")
@click.argument("scenario", type=click.Path(dir_okay=False, path_type=Path))
@click.option("-o", "--output", type=str, default=None,
              help="The run folder to check (default: output.directory, or out/<name>).")
def command(scenario: Path, output) -> None:
    """Validate SCENARIO (a TOML file) without running it.

    Makes every test a run makes before its first step (the same function), then prints the
    domain size, CRS, water volumes, particle count and the estimated peak memory. Exits with
    status 2 and one message on any input problem, including a run whose memory estimate
    exceeds the memory available, and a run folder that a run could not write (a file, not
    writable, holding files that are not a run's).
    """
    from floodsph.inputs.memory import available_memory
    from floodsph.inputs.prepare import summary_lines
    from floodsph.run.preflight import preflight
    from floodsph.scenario.reader import load_scenario

    sc = load_scenario(scenario)
    inputs = preflight(sc, None if output is None else Path(output), overwrite=True).inputs
    available, _ = available_memory()
    for line in summary_lines(sc, inputs, available):
        click.echo(line)
    click.echo("OK: the scenario is valid.")
