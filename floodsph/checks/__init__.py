"""Sanity checks of the user's inputs: refuse garbage with one message, warn where meant.

Each module checks one kind of input (the table of every check, its threshold and why is
``docs/input-checks.md``):

* :mod:`~floodsph.checks.shapes`: polygons and walls that are degenerate or cross themselves;
* :mod:`~floodsph.checks.placement`: geometry off the DEM, in degrees, or too small;
* :mod:`~floodsph.checks.elevation`: DEM values no terrain holds, vertical units in feet;
* :mod:`~floodsph.checks.roughness`: Manning values that are Strickler or Chezy coefficients;
* :mod:`~floodsph.checks.water`: initial water bodies that hold no water, a dry scenario.

Refusals raise :class:`floodsph.errors.InputError`; warnings go through
:func:`floodsph.errors.warn` into ``floodsph.inputs.prepare.Inputs.warnings``.
"""
