"""``floodsph run SCENARIO``: run a scenario and write its run folder."""

from __future__ import annotations

from pathlib import Path

import click


@click.command("run")
@click.argument("scenario", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "-o",
    "--output",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="Run folder (default: output.directory, or out/<name> beside the scenario).",
)
@click.option("--overwrite", is_flag=True, help="Replace a completed run in the run folder.")
@click.option(
    "--max-steps",
    type=click.IntRange(min=1),
    default=None,
    help="Stop after this many time steps (a trial run).",
)
@click.pass_context
def command(ctx: click.Context, scenario: Path, output, overwrite: bool, max_steps) -> None:
    """Run SCENARIO (a TOML file): maps, mass balance and run.json in the run folder.

    The run folder gets floodsph.log, scenario.resolved.toml, mass_balance.csv, run.json and,
    when the run completes, the flood maps. run.json records the status whether the run
    completes, fails or is interrupted (Ctrl-C).
    """
    from floodsph.run import run_scenario
    from floodsph.scenario import load_scenario

    opts = ctx.obj or {}
    sc = load_scenario(scenario)
    manifest = run_scenario(
        sc,
        out_dir=output,
        max_steps=max_steps,
        progress=not opts.get("quiet", False),
        overwrite=overwrite,
        threads=opts.get("threads"),
    )
    if not opts.get("quiet", False):
        click.echo(
            f"{manifest['status']}: t = {manifest['sim_time_s']:g} s in {manifest['steps']} steps, "
            f"{manifest['wall_time_s']:.1f} s wall; mass error {manifest['mass_error_rel']:.2e}; "
            f"run folder {output or sc.output_directory}"
        )
