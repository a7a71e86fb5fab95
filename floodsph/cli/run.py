"""``floodsph run SCENARIO``: run a scenario and write its run folder."""

from __future__ import annotations

from pathlib import Path

import click

#: Exit status of each ending (``floodsph.cli.main`` has those of errors).
EXIT_STATUS = {"completed": 0, "stopped": 0, "interrupted": 130}


@click.command("run")
@click.argument("scenario", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "-o",
    "--output",
    type=str,  # not click.Path: the run folder checks reach every name with one message
    default=None,
    help="Run folder (default: output.directory, or out/<name> beside the scenario).",
)
@click.option("--overwrite", is_flag=True,
              help="Replace the completed run in the run folder (kept until the new one "
                   "completes).")
@click.option("--resume", is_flag=True,
              help="Continue the run in the run folder from its latest checkpoint (a larger "
                   "scenario.end_time_s extends it).")
@click.option(
    "--max-steps",
    type=click.IntRange(min=1),
    default=None,
    help="Stop after this many time steps (a trial run; status \"stopped\"); with local "
         "time steps, at the end of the big step that holds the last.",
)
@click.pass_context
def command(ctx: click.Context, scenario: Path, output, overwrite: bool, resume: bool,
            max_steps) -> None:
    """Run SCENARIO (a TOML file): maps, mass balance and run.json in the run folder.

    run.json records how the run ended: completed, stopped (--max-steps), interrupted
    (Ctrl-C, SIGTERM or SIGHUP: a checkpoint is written first; exit status 130) or failed
    (exit status 1, or 2 for bad input). The maps are written only when the run completes.
    """
    from floodsph.run.compile_notice import CompileNotice
    from floodsph.run.pipeline import run_scenario
    from floodsph.scenario.reader import load_scenario

    opts = ctx.obj or {}
    quiet = opts.get("quiet", False)
    output = None if output is None else Path(output)
    sc = load_scenario(scenario)
    with CompileNotice(lambda message: None if quiet else click.echo(message, err=True)):
        manifest = run_scenario(
            sc,
            out_dir=output,
            max_steps=max_steps,
            progress=not quiet,
            overwrite=overwrite,
            threads=opts.get("threads"),
            resume=resume,
        )
    folder = output or sc.output_directory
    status = manifest["status"]
    if status == "interrupted":
        click.echo(f"Interrupted at t = {manifest['sim_time_s']:g} s: {manifest['error']}. "
                   f"Continue with: floodsph run {scenario} --resume"
                   + (f" -o {output}" if output else ""), err=True)
    elif not quiet:
        click.echo(
            f"{status}: t = {manifest['sim_time_s']:g} s in {manifest['steps']} steps, "
            f"{manifest['wall_time_s']:.1f} s wall; mass error {manifest['mass_error_rel']:.2e}; "
            f"run folder {folder}"
        )
    ctx.exit(EXIT_STATUS[status])
