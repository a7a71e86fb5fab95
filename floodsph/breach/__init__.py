"""Parametric dam breach: Froehlich (2008) breach size and time, level-pool routing, hydrograph.

``floodsph breach PARAMS.toml -o breach.csv`` and a scenario's ``[inflows.breach]`` table use the
same keys (SI units; elevations in any consistent datum, by default the breach invert = 0):

=======================  ==========================================================================
key                      meaning
=======================  ==========================================================================
method                   ``"froehlich2008"`` (default; the only method so far)
mode                     ``"overtopping"`` (default; k0 = 1.3, side slopes 1.0 H:V) or ``"piping"``
                         (k0 = 1.0, 0.7 H:V). Piping is routed as weir flow through the same
                         growing trapezoid (no orifice phase).
breach_height_m          h_b, dam crest at the breach minus the final breach invert (required)
reservoir_volume_m3      V_w, volume above the breach invert at failure. Required unless
                         reservoir_area_m2 or storage_table gives it (then it must agree to 1 %).
head_m                   h_w, initial water level minus the breach invert (default h_b) ...
initial_level_m          ... or the initial water level itself (give one of the two)
breach_invert_m          final breach bottom elevation (default 0.0)
reservoir_area_m2        constant surface area A: V = A (H - invert); default V_w / h_w ...
storage_table            ... or a CSV ``elevation_m`` with ``volume_m3`` or ``area_m2`` (linear)
inflow_hydrograph        optional reservoir inflow, CSV ``time_s,discharge_m3s``
progression              ``"linear"`` (default) or ``"sine"`` breach growth over t_f
weir_coefficient         C_w of the breach weir [m^0.5/s], default 1.7 (side parts 2.45/3.1 C_w)
average_width_m          override B_avg (e.g. a Monte-Carlo sample); default Froehlich (2008)
formation_time_s         override t_f; default Froehlich (2008)
start_time_s             breach initiation time on the hydrograph clock (default 0)
duration_s               length of the hydrograph; default: until the outflow falls below
                         1e-4 of the peak after t_f (and after any inflow ends)
dt_s                     output interval of the hydrograph; default min(t_f/200, drainage time/20)
=======================  ==========================================================================

The breach bottom starts at the lower of the dam crest (invert + h_b) and the initial level and
descends to the invert over t_f while the bottom width grows from 0 to B_avg - z h_b.
"""

from floodsph.breach.formulas import (
    froehlich1995_peak,
    froehlich2008_average_width,
    froehlich2008_formation_time,
    macdonald1984_peak,
)
from floodsph.breach.params import BreachParams, load_breach_params
from floodsph.breach.routing import BreachSummary, breach_hydrograph
from floodsph.io.hydrograph import write_hydrograph_csv

__all__ = [
    "BreachParams",
    "BreachSummary",
    "breach_hydrograph",
    "froehlich1995_peak",
    "froehlich2008_average_width",
    "froehlich2008_formation_time",
    "load_breach_params",
    "macdonald1984_peak",
    "write_hydrograph_csv",
]
