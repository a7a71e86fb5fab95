"""Sanity checks of the user's inputs: refuse garbage with one message, warn where meant.

Each module checks one kind of input (the table of every check, its threshold and why is
``docs/input-checks.md``):

* :mod:`~floodsph.checks.shapes`: polygons and walls that are degenerate or cross themselves;
* :mod:`~floodsph.checks.placement`: geometry off the DEM, in degrees, or too small;
* :mod:`~floodsph.checks.elevation`: DEM values no terrain holds, vertical units in feet;
* :mod:`~floodsph.checks.water`: initial water bodies that hold no water, a dry scenario;
* :mod:`~floodsph.checks.inflows`: inflow lines whose side of entry cannot be told.

The checks of Manning values (Strickler or Chezy coefficients given as n) are
:mod:`floodsph.io.roughness`, beside the reader of roughness rasters and tables that applies
them, so that the readers in ``floodsph.io`` do not depend on this package.

Refusals raise :class:`floodsph.errors.InputError`; warnings go through
:func:`floodsph.errors.warn` into ``floodsph.inputs.prepare.Inputs.warnings``.
"""
