"""Ensembles: many runs of one base scenario with sampled inputs, as probability maps.

``floodsph ensemble ENSEMBLE.toml`` (contract: ``ensemble-format.md``; guide:
``docs/ensembles.md``) goes through these modules, each with one job:

=================  ================================================================
``spec``           read and validate the ensemble TOML (:func:`load_ensemble`)
``distributions``  the five distributions and their inverse CDFs
``keys``           key paths into the scenario (``inflows[0].breach.average_width_m``)
``sampling``       Latin hypercube / Monte Carlo draws, seeded (:func:`draw_samples`)
``members``        member scenarios: build, validate, write, run one, recognise done ones
``rasters``        a raster scaled by a factor into a member's folder
``engine``         the dask.distributed cluster: sizing, submission, progress
``aggregate``      streamed exceedance-probability and quantile maps over the members
``outputs``        the map files: COG GeoTIFFs, ``ensemble_maps.nc``, ``ensemble.png``
``netcdf``         the ``ensemble_maps.nc`` writer
``manifest``       ``ensemble.json`` and ``samples.csv``
``runner``         the whole ensemble, start to finish (:func:`run_ensemble`)
=================  ================================================================

Nothing here is imported by ``import floodsph.ensemble``; import the submodule you need.
"""
