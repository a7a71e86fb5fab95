"""``floodsph ensemble ENSEMBLE``: run sampled members of a scenario, map probabilities."""

from __future__ import annotations

from pathlib import Path

import click


@click.command("ensemble")
@click.argument("ensemble", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--workers", type=click.IntRange(min=1), default=None,
              help="Worker processes of the local cluster (default: as many as the cores and "
                   "the members' memory estimate allow).")
@click.option("--threads-per-worker", type=click.IntRange(min=1), default=None,
              help="Numba threads of each member (default: the cores shared out among the "
                   "workers).")
@click.option("--scheduler", metavar="ADDRESS", default=None,
              help="Send the members to the dask scheduler at ADDRESS (tcp://host:8786) "
                   "instead of starting a local cluster.")
@click.option("-o", "--output", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Ensemble folder (default: out/<name> beside the ensemble file).")
@click.option("--resume", is_flag=True,
              help="Keep the members already completed with the same sampled scenario; run "
                   "the rest and recompute the maps.")
@click.option("--overwrite", is_flag=True, help="Run every member again in an existing "
                                                "ensemble folder.")
@click.pass_context
def command(ctx: click.Context, ensemble: Path, workers, threads_per_worker, scheduler,
            output, resume: bool, overwrite: bool) -> None:
    """Run the members of ENSEMBLE (a TOML file) and write probability and quantile maps.

    Each member is the base scenario with sampled values, run in its own run folder
    members/<id>/ on a dask.distributed cluster. A member that fails is recorded in
    samples.csv and the others go on; the maps (p_depth_gt_<t>m.tif, *_q<q>.tif,
    p_hazard_uk_ge_<k>.tif, ensemble_maps.nc, ensemble.png) are over the completed members,
    and ensemble.json says how many. Needs the extra: pip install 'floodsph[ensemble]'.
    """
    from floodsph.ensemble.runner import run_ensemble
    from floodsph.ensemble.spec import load_ensemble

    opts = ctx.obj or {}
    quiet = opts.get("quiet", False)
    spec = load_ensemble(ensemble)
    manifest = run_ensemble(spec, output, workers=workers, threads_per_worker=threads_per_worker,
                            scheduler=scheduler, resume=resume, overwrite=overwrite,
                            progress=not quiet)
    folder = output or spec.output_directory
    if manifest["status"] == "failed":
        click.echo(f"Error: the ensemble failed: {manifest['error']} ({folder})", err=True)
        ctx.exit(1)
    if not quiet:
        click.echo(f"{manifest['status']}: {manifest['members_completed']} of "
                   f"{manifest['members']} members completed ({manifest['members_failed']} "
                   f"failed, {manifest['members_kept']} kept) in {manifest['wall_time_s']:.1f} s "
                   f"on {manifest['workers'] or 0} workers; ensemble folder {folder}")
