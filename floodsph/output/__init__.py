"""Map outputs: rasterisation, envelopes, hazard, GeoTIFF/NetCDF writers, gauges, pictures.

Submodules are imported on demand (several compile numba kernels); this package module only
offers the two calls the run uses at the end: :func:`write_maps` and :func:`write_pictures`.
"""

from __future__ import annotations

from pathlib import Path

FORMATS = ("geotiff", "netcdf")


def write_maps(envelopes, out_dir, formats=FORMATS, scenario: dict | None = None,
               start=None) -> list[Path]:
    """Write every envelope map of the run-folder contract.

    ``geotiff``: ``<name>.tif`` for each map of :data:`floodsph.output.envelopes.MAPS`;
    ``netcdf``: all of them in ``flood_maps.nc``. The wet threshold and hazard land use are
    taken from ``envelopes`` and recorded in the files with the resolved ``scenario``; the
    NetCDF ``time`` counts from ``start`` (a time zone aware datetime, or None).

    Returns the written paths.
    """
    from floodsph._version import __version__
    from floodsph.errors import InputError
    from floodsph.output.envelopes import MAPS
    from floodsph.output.hazard import ARR_COLOURS, UK_COLOURS

    unknown = set(formats) - set(FORMATS)
    if unknown:
        raise InputError(f"output.formats: unknown format(s) {sorted(unknown)}; "
                         f"expected any of {list(FORMATS)}")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    maps = envelopes.maps()
    grid = envelopes.grid
    tables = envelopes.tables
    class_names = {"hazard_uk": tables.uk_names, "hazard_arr": tables.arr_names}
    colours = {"hazard_uk": UK_COLOURS, "hazard_arr": ARR_COLOURS}
    tags = {"wet_threshold_m": envelopes.wet_threshold, "hazard_land_use": tables.land_use,
            "source": f"floodsph {__version__}"}
    if envelopes.t_last is not None:
        tags["period_s"] = repr(float(envelopes.t_last))
    written = []
    if "geotiff" in formats:
        from floodsph.output.geotiff import write_geotiff

        for name, (long_name, units, _) in MAPS.items():
            written.append(write_geotiff(out_dir / f"{name}.tif", maps[name], grid, name, units,
                                         long_name=long_name, tags=tags,
                                         class_names=class_names.get(name),
                                         colours=colours.get(name)))
    if "netcdf" in formats:
        from floodsph.output.netcdf import write_flood_maps

        written.append(write_flood_maps(out_dir / "flood_maps.nc", maps, MAPS, grid,
                                        class_names=class_names, scenario=scenario,
                                        wet_threshold=envelopes.wet_threshold,
                                        period_s=envelopes.t_last, start=start))
    return written


def write_pictures(envelopes, out_dir, title: str = "", features=None) -> list[Path] | str:
    """Quick-look PNGs of the envelopes, with the walls, sinks, gauges and caption of
    ``features`` (see :mod:`floodsph.output.pictures`).

    Returns the written paths, or the message ``"pictures skipped: matplotlib not
    installed"``.
    """
    from floodsph.output.pictures import write_pictures as _write

    return _write(envelopes, out_dir, title, features)
