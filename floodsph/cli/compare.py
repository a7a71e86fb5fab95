"""`floodsph compare MODEL REFERENCE`: skill scores and differences between two flood maps."""

from pathlib import Path

import click

_FILE = click.Path(exists=True, dir_okay=False, path_type=Path)


@click.command("compare", short_help="Compare two flood maps (CSI, hit rate, depth RMSE).")
@click.argument("model")
@click.argument("reference")
@click.option("--threshold", type=float, default=0.1, show_default=True,
              help="Depth [m] above which a cell is wet in both maps.")
@click.option("--points", type=_FILE, default=None,
              help="CSV of observations (id,x,y,observed) in the map CRS.")
@click.option("--arrival", is_flag=True,
              help="Take maps that do not say what they hold as arrival times (read from "
                   "the standard name, band description, NetCDF variable or units otherwise).")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Folder for difference.tif, comparison.json, points.csv (with --points) "
                   "and comparison.png.")
def command(model, reference, threshold, points, arrival, out):
    """Compare MODEL with REFERENCE (a benchmark or another scenario).

    Each map is a single-band raster file (GeoTIFF, ASCII grid, ...) or a NetCDF variable
    named FILE.nc:VARIABLE, e.g. out/valley/flood_maps.nc:max_depth. Both must hold the same
    quantity (depth, speed, arrival time, ...: read from their metadata). REFERENCE is
    reprojected onto MODEL's grid (bilinear; nearest for class maps). Prints the contingency
    counts, hit rate, false alarm ratio, CSI, F2, error bias and the RMSE and bias of the
    values over cells wet in both. Observation points off the model map are reported as
    outside and left out of the statistics.
    """
    from floodsph.output.compare import compare, format_table, write_outputs

    result = compare(model, reference, threshold=threshold, points=points, arrival=arrival)
    click.echo(format_table(result.summary))
    if out is not None:
        for path in write_outputs(result, out):
            click.echo(f"wrote {path}")
