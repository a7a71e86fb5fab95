"""``floodsph breach``: parametric dam-breach hydrograph (Froehlich 2008 + level-pool routing)."""

from pathlib import Path

import click


class _BadInput(click.ClickException):
    """One plain message, exit status 2 (the project's bad-input status)."""

    exit_code = 2


def _resolved(path):
    return None if path is None else str(Path(path).resolve())


@click.command("breach")
@click.argument("params_file", required=False, type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(dir_okay=False),
              help="Write the hydrograph CSV (time_s,discharge_m3s) here.")
@click.option("--volume", type=float, help="Reservoir volume V_w above the breach invert, m3 "
              "(key reservoir_volume_m3).")
@click.option("--height", type=float, help="Breach height h_b, m (key breach_height_m).")
@click.option("--head", type=float, help="Head h_w at failure, m (key head_m; default h_b).")
@click.option("--mode", type=click.Choice(["overtopping", "piping"]), help="Failure mode.")
@click.option("--area", type=float, help="Constant reservoir surface area, m2 "
              "(key reservoir_area_m2).")
@click.option("--storage-table", type=click.Path(dir_okay=False),
              help="CSV elevation_m,volume_m3 (or area_m2) (key storage_table).")
@click.option("--progression", type=click.Choice(["linear", "sine"]), help="Breach growth.")
@click.option("--weir-coefficient", type=float, help="Breach weir coefficient C_w, m^0.5/s "
              "(default 1.7).")
@click.option("--duration", type=float, help="Hydrograph length, s (key duration_s).")
@click.option("--dt", type=float, help="Time step and output interval, s (key dt_s).")
def command(params_file, output, volume, height, head, mode, area, storage_table, progression,
            weir_coefficient, duration, dt):
    """Compute a dam-breach outflow hydrograph from PARAMS_FILE (a TOML [breach] table) and/or
    the options (which override the file), print the breach parameters with the regression
    peak discharges as a cross-check, and write the CSV that a scenario's [[inflows]] reads.
    """
    from floodsph.breach import (
        BreachParams,
        breach_hydrograph,
        load_breach_params,
        write_hydrograph_csv,
    )
    from floodsph.errors import InputError

    options = {"reservoir_volume_m3": volume, "breach_height_m": height, "head_m": head,
               "mode": mode, "reservoir_area_m2": area,
               "storage_table": _resolved(storage_table), "progression": progression,
               "weir_coefficient": weir_coefficient, "duration_s": duration, "dt_s": dt}
    options = {key: value for key, value in options.items() if value is not None}
    try:
        if params_file is not None:
            params = load_breach_params(params_file, options)
        else:
            params = BreachParams.from_mapping(options, "breach")
        t, Q, s = breach_hydrograph(params)
    except InputError as err:
        raise _BadInput(str(err)) from None

    line = "  {:<40s} {}".format
    click.echo(f"Breach: {params.method}, {params.mode}, {params.progression} progression")
    click.echo(line("reservoir volume V_w", f"{s.reservoir_volume_m3:.4g} m3"))
    click.echo(line("head h_w / breach height h_b",
                    f"{s.head_m:.2f} m / {params.breach_height_m:.2f} m"))
    click.echo(line("average width B_avg", f"{s.average_width_m:.2f} m"))
    click.echo(line("bottom width / side slopes",
                    f"{s.bottom_width_m:.2f} m / {s.side_slope:g}H:1V"))
    click.echo(line("formation time t_f",
                    f"{s.formation_time_s:.1f} s ({s.formation_time_s / 3600:.2f} h)"))
    click.echo("Peak discharge (cross-check)")
    click.echo(line(f"routed, level pool (C_w = {params.weir_coefficient:g})",
                    f"{s.peak_discharge_m3s:.1f} m3/s at t = {s.time_to_peak_s:.1f} s"))
    click.echo(line("Froehlich (1995)", f"{s.froehlich1995_peak_m3s:.1f} m3/s"))
    click.echo(line("MacDonald & Langridge-Monopolis (1984)",
                    f"{s.macdonald1984_peak_m3s:.1f} m3/s"))
    click.echo(line("released / remaining volume",
                    f"{s.released_volume_m3:.4g} m3 / {s.remaining_storage_m3:.4g} m3 "
                    f"(balance error {s.volume_error_rel:.1e})"))
    if output is None:
        click.echo("No hydrograph written (use -o FILE).")
        return
    try:
        write_hydrograph_csv(output, t, Q)
    except OSError as err:
        raise _BadInput(f"{output}: cannot write the hydrograph ({err.strerror})") from None
    click.echo(f"Wrote {output}: {len(t)} rows, 0 to {t[-1]:.0f} s")
