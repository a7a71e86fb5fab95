"""Level-pool routing of a reservoir through a growing trapezoidal breach.

The reservoir storage V obeys dV/dt = Q_in(t) - Q_b(H(V), t) (HEC-RAS level-pool practice,
``docs/breach.md`` §2), with H(V) the storage-elevation curve and Q_b the free broad-crested
weir flow through the breach (:func:`floodsph.breach.formulas.trapezoid_weir_discharge`).
From initiation at ``start_time_s`` the breach grows over the formation time t_f by the fraction
r(tau) (linear or sine progression): bottom width b = r B, bottom elevation
z_b = z_top - r (z_top - z_invert), side slopes z constant. The equation is integrated with
``scipy.integrate.solve_ivp`` (adaptive Dormand-Prince between the kinks of the right-hand side,
an event for the end of the outflow), sampled every ``dt`` (:func:`route`).

Volume check: the released volume is the exact integral of the piecewise-linear output
hydrograph (what a model interpolating the CSV injects), and the initial storage plus inflow
must equal released plus remaining storage; the relative mismatch is reported in the summary.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from floodsph.breach import formulas
from floodsph.breach.params import BreachParams, BreachSetup, resolve
from floodsph.io.hydrograph import Hydrograph

#: Without duration_s, the routing stops once the breach has formed and the outflow has fallen
#: below this fraction of the peak (and the reservoir inflow has ended) ...
STOP_FRACTION = 1e-4
#: ... or at start_time_s + this many formation times, whichever comes first.
MAX_FORMATION_TIMES = 1000.0


@dataclass(frozen=True)
class BreachSummary:
    """Key numbers of a routed breach (SI units; times from the start of the hydrograph)."""

    average_width_m: float  # B_avg, Froehlich (2008) unless given
    bottom_width_m: float  # final breach bottom width
    side_slope: float  # H:V
    formation_time_s: float  # t_f
    peak_discharge_m3s: float  # routed peak outflow
    time_to_peak_s: float
    reservoir_volume_m3: float  # V_w used by the regressions
    head_m: float  # h_w
    initial_storage_m3: float  # storage above the breach invert at t = 0
    inflow_volume_m3: float  # reservoir inflow over the hydrograph
    released_volume_m3: float  # integral of the output hydrograph
    remaining_storage_m3: float  # storage above the breach invert at the end
    volume_error_rel: float  # (initial + inflow - released - remaining) / (initial + inflow)
    final_level_m: float
    duration_s: float
    froehlich1995_peak_m3s: float  # regression cross-checks
    macdonald1984_peak_m3s: float


def _auto_dt(setup: BreachSetup):
    """Sampling interval of the hydrograph: t_f / 200, and at most 1/20 of the drainage time
    scale of the full breach, tau = A / (dQ_b/dH), with the mean surface area A = stored / h_w
    and the weir derivative at head h_w, so that linear interpolation between samples follows
    the outflow closely."""
    p = setup.params
    y = setup.head_m
    area = setup.volume_m3 / y
    dq_dh = p.weir_coefficient * (1.5 * setup.bottom_width_m * math.sqrt(y)
                                  + 2.5 * formulas.SIDE_TO_WEIR_RATIO * setup.side_slope * y**1.5)
    return min(setup.formation_time_s / 200.0, area / dq_dh / 20.0)


def _outflow_function(setup: BreachSetup):
    p = setup.params
    t0, t_f = p.start_time_s, setup.formation_time_s
    drop = setup.top_m - setup.invert_m
    level = setup.storage.level

    def outflow(t, volume):
        r = formulas.progression((t - t0) / t_f, p.progression)
        if r <= 0.0:  # no breach before initiation (overflow of the intact crest not modelled)
            return 0.0
        return formulas.trapezoid_weir_discharge(
            level(volume), setup.top_m - r * drop, r * setup.bottom_width_m,
            setup.side_slope, p.weir_coefficient)

    return outflow


#: Relative tolerance of the adaptive integration (the absolute one scales with the storage).
RTOL = 1e-9


def route(setup: BreachSetup):
    """Integrate the level-pool equation; return sample times [s], outflow [m3/s], final storage.

    ``scipy.integrate.solve_ivp`` (Dormand-Prince 5(4), adaptive, relative tolerance
    :data:`RTOL`) integrates between the breakpoints of the right-hand side (breach initiation,
    end of formation, end of the reservoir inflow), where it has kinks; the hydrograph is
    sampled every ``dt`` from its dense output. Without ``duration_s`` the last piece ends
    at the event "outflow falls to :data:`STOP_FRACTION` of the peak so far" (once the breach
    has formed and the inflow ended the outflow only falls), which is the last sample.
    """
    from scipy.integrate import solve_ivp

    p = setup.params
    dt = p.dt_s if p.dt_s is not None else _auto_dt(setup)
    outflow = _outflow_function(setup)
    inflow = setup.inflow.discharge if setup.inflow is not None else (lambda t: 0.0)
    inflow_end = setup.inflow.t[-1] if setup.inflow is not None else -math.inf
    formed = p.start_time_s + setup.formation_time_s
    end = p.duration_s if p.duration_s is not None else (
        p.start_time_s + MAX_FORMATION_TIMES * setup.formation_time_s)
    volume = setup.storage.volume(setup.initial_level_m)
    atol = RTOL * max(abs(volume), 1.0)

    def rate(t, v):
        return [float(inflow(t)) - outflow(t, v[0])]

    breaks = sorted({0.0, end, *(x for x in (p.start_time_s, formed, inflow_end) if 0 < x < end)})
    grid = np.arange(0.0, end, dt)
    times, flows = [0.0], [outflow(0.0, volume)]
    for a, b in zip(breaks, breaks[1:], strict=False):
        samples = grid[(grid > a) & (grid < b)]
        samples = np.append(samples, b)
        events = None
        if p.duration_s is None and a >= max(formed, inflow_end):
            threshold = STOP_FRACTION * max(flows)

            def faded(t, v, threshold=threshold):
                return outflow(t, v[0]) - threshold

            # solve_ivp reads an event's attributes off the function
            faded.terminal, faded.direction = True, -1.0  # type: ignore[attr-defined]
            events = faded
        sol = solve_ivp(rate, (a, b), [volume], t_eval=samples, events=events, rtol=RTOL,
                        atol=atol, max_step=max(b - a, dt))
        if not sol.success:  # pragma: no cover - the right-hand side is smooth between breaks
            raise RuntimeError(f"breach routing failed at t = {sol.t[-1]:g} s: {sol.message}")
        ts, vs = list(sol.t), list(sol.y[0])
        if events is not None and sol.t_events[0].size:
            ts.append(float(sol.t_events[0][0]))
            vs.append(float(sol.y_events[0][0][0]))
        times += ts
        flows += [outflow(t, v) for t, v in zip(ts, vs, strict=True)]
        volume = vs[-1]
        if sol.status == 1:  # the outflow has faded
            break
    return np.array(times), np.array(flows), volume


def breach_hydrograph(params: BreachParams):
    """Route a parametric breach and return its outflow hydrograph.

    Returns
    -------
    t : numpy.ndarray
        Sample times [s] from 0 (``start_time_s`` is the breach initiation on this clock).
    Q : numpy.ndarray
        Breach outflow [m3/s], >= 0.
    summary : BreachSummary
    """
    setup = resolve(params)
    t, Q, volume_end = route(setup)
    storage = setup.storage
    base = storage.volume(setup.invert_m)
    initial = storage.volume(setup.initial_level_m) - base
    remaining = volume_end - base
    released = Hydrograph(t, Q).total_volume()
    inflow = float(setup.inflow.volume(t[0], t[-1])) if setup.inflow is not None else 0.0
    k = int(np.argmax(Q))
    summary = BreachSummary(
        average_width_m=setup.average_width_m, bottom_width_m=setup.bottom_width_m,
        side_slope=setup.side_slope, formation_time_s=setup.formation_time_s,
        peak_discharge_m3s=float(Q[k]), time_to_peak_s=float(t[k]),
        reservoir_volume_m3=setup.volume_m3, head_m=setup.head_m,
        initial_storage_m3=initial, inflow_volume_m3=inflow, released_volume_m3=released,
        remaining_storage_m3=remaining,
        volume_error_rel=(initial + inflow - released - remaining) / (initial + inflow),
        final_level_m=storage.level(volume_end), duration_s=float(t[-1]),
        froehlich1995_peak_m3s=formulas.froehlich1995_peak(setup.volume_m3, setup.head_m),
        macdonald1984_peak_m3s=formulas.macdonald1984_peak(setup.volume_m3, setup.head_m))
    return t, Q, summary
