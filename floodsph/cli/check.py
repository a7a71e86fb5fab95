"""``floodsph check SCENARIO``: validate a scenario and its inputs, print what would run."""

from __future__ import annotations

from pathlib import Path

import click


@click.command("check")
@click.argument("scenario", type=click.Path(dir_okay=False, path_type=Path))
def command(scenario: Path) -> None:
    """Validate SCENARIO (a TOML file) without running it.

    Loads the scenario, the DEM and roughness, builds the initial water and seeds the
    particles, then prints the domain size, CRS, water volumes, particle count and the
    estimated peak memory. Exits with status 2 and one message on any input problem, including
    a run whose memory estimate exceeds the memory available.
    """
    from floodsph.inputs import prepare_inputs, summary_lines
    from floodsph.memory import available_memory, check_memory
    from floodsph.scenario import load_scenario

    sc = load_scenario(scenario)
    inputs = prepare_inputs(sc)
    available, _ = available_memory()
    for line in summary_lines(sc, inputs, available):
        click.echo(line)
    check_memory(inputs.memory, str(scenario))
    click.echo("OK: the scenario is valid.")
