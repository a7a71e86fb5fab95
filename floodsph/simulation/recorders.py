"""The run's output recorders as simulation callbacks: map envelopes, gauges, flux lines,
snapshots.

:class:`Recorders` owns the objects of ``floodsph.output`` for one run, hands their
``(callback, schedule)`` pairs to the :class:`~floodsph.simulation.loop.Simulation`, and writes the
final files (:meth:`Recorders.write`) only when the run completes, so a failed or interrupted
run never leaves maps that look finished. Snapshots are appended as the run goes to
``snapshots.nc.part``, moved to ``snapshots.nc`` by :meth:`Recorders.write`.
:meth:`Recorders.state` and :meth:`Recorders.restore` carry everything recorded so far
through a checkpoint.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from floodsph.io.run_names import FLUX_NAME, GAUGES_NAME, SNAPSHOTS_NAME
from floodsph.scenario.config import Scenario
from floodsph.simulation.schedules import TimeInterval, TimeList, time_tolerance
from floodsph.simulation.state_arrays import conform

SNAPSHOTS_PART = SNAPSHOTS_NAME + ".part"


class Recorders:
    """Envelopes (always), gauges (``[gauges]``), flux lines (``flux_lines``, the model's
    ``floodsph.simulation.flux.FluxLines``, which carries its own state through a checkpoint)
    and snapshots (``snapshot_interval_s > 0`` or ``snapshot_times_s``).

    ``state`` (:meth:`state` of an earlier run, as a checkpoint gives it back) continues that
    run's records; its snapshot frames are read from ``snapshots_from`` (default: this run's
    own ``snapshots.nc.part``). ``source``: the file ``state`` was read from, for the
    message of a field missing or ill-formed (``floodsph.errors.InputError``).
    """

    def __init__(self, scenario: Scenario, terrain, gauge_points, out: Path,
                 state: dict | None = None, snapshots_from: Path | None = None,
                 flux_lines=None, source: str | None = None):
        from floodsph.output.envelopes import Envelopes
        from floodsph.output.grid import OutputGrid

        self.scenario = scenario
        self.out = Path(out)
        source = source or "checkpoint"
        frames = 0 if state is None else conform(0, state.get("snapshot_frames"),
                                                 "recorders.snapshot_frames", source)
        wet = scenario.output.wet_threshold_m
        self.grid = OutputGrid.from_terrain(terrain, scenario.output.resolution_m)
        self.envelopes = Envelopes(self.grid, wet_threshold=wet)
        self.gauges = None
        if gauge_points is not None:
            from floodsph.output.gauges import Gauges

            self.gauges = Gauges(gauge_points, scenario.gauges.interval_s, wet_threshold=wet,
                                 start=scenario.start)
        self.flux_lines = flux_lines
        self.snapshots = None
        if scenario.output.snapshot_interval_s > 0 or scenario.output.snapshot_times_s:
            from floodsph.output.netcdf import SnapshotWriter

            self.snapshots = SnapshotWriter(
                self.out / SNAPSHOTS_PART, self.grid, scenario=scenario.to_dict(),
                wet_threshold=wet, keep_frames=frames,
                source=snapshots_from, start=scenario.start,
            )
        if state is not None:
            state = conform(self.state(), state, "recorders", source)
            self.envelopes.restore(state["envelopes"])
            if self.gauges is not None:
                self.gauges.rows = [tuple(row) for row in state["gauge_rows"]]
                self.gauges.t_last = state["gauge_t_last"]

    def state(self) -> dict:
        """Everything recorded so far, for a checkpoint (the ``state`` of the constructor)."""
        return {"envelopes": self.envelopes.state(),
                "gauge_rows": None if self.gauges is None else list(self.gauges.rows),
                "gauge_t_last": None if self.gauges is None else self.gauges.t_last,
                "snapshot_frames": 0 if self.snapshots is None else self.snapshots.frames}

    def callbacks(self) -> list:
        """``(callable, schedule)`` pairs for the simulation."""
        out = [(self.record_envelopes, TimeInterval(self.envelopes.interval_s, align=False))]
        if self.gauges is not None:
            out.append((self.record_gauges, TimeInterval(self.gauges.interval_s)))
        if self.flux_lines is not None:
            out.append((self.record_flux, TimeInterval(self.scenario.flux_interval_s)))
        if self.snapshots is not None:
            out.append((self.record_snapshot, self.snapshot_schedule()))
        return out

    def snapshot_schedule(self):
        """Every ``snapshot_interval_s``, or, with ``snapshot_times_s``, at those times and
        the multiples of the interval (if any) up to the end time."""
        o = self.scenario.output
        if not o.snapshot_times_s:
            return TimeInterval(o.snapshot_interval_s)
        times = set(o.snapshot_times_s)
        if o.snapshot_interval_s > 0:
            end = self.scenario.end_time_s
            count = math.floor(end / o.snapshot_interval_s + time_tolerance(end))
            times.update(k * o.snapshot_interval_s for k in range(1, count + 1))
        return TimeList(sorted(times))

    def snapshot_due(self, t: float) -> bool:
        """False at the start and the end of a run whose snapshots are at listed times only
        (``snapshot_times_s`` without an interval), unless those times are listed."""
        o = self.scenario.output
        if o.snapshot_interval_s > 0 or not o.snapshot_times_s:
            return True
        return any(abs(t - listed) <= time_tolerance(listed) for listed in o.snapshot_times_s)

    def record_envelopes(self, sim) -> None:
        self.envelopes.record(sim.model)

    def record_gauges(self, sim) -> None:
        self.gauges.record(sim.model)

    def record_flux(self, sim) -> None:
        self.flux_lines.record(sim.model.t)

    def record_snapshot(self, sim) -> None:
        from floodsph.output.rasterise import rasterise

        if not self.snapshot_due(sim.model.t):
            return
        p = sim.model.particles
        d, u, v, _ = rasterise(self.grid, p.x, p.y, p.u, p.v, p.m, p.rho, p.h,
                               level=sim.model.surface_levels(), walls=sim.model.map_walls())
        with np.errstate(invalid="ignore"):
            level = np.where(d > self.envelopes.wet_threshold, d + self.grid.bed, np.nan)
        self.snapshots.append(sim.model.t, d, u, v, level)

    def write(self, into: Path) -> list[Path]:
        """Write the maps (formats of ``output.formats``), the gauge table and the snapshots
        into the folder ``into``; return their paths."""
        from floodsph.output import write_maps

        formats = [f.value for f in self.scenario.output.formats]
        written = write_maps(self.envelopes, into, formats, scenario=self.scenario.to_dict(),
                             start=self.scenario.start)
        if self.gauges is not None:
            written.append(self.gauges.write_csv(into / GAUGES_NAME))
        if self.flux_lines is not None:
            written.append(self.flux_lines.write_csv(into / FLUX_NAME, self.scenario.start))
        if self.snapshots is not None:
            self.close()
            os.replace(self.out / SNAPSHOTS_PART, into / SNAPSHOTS_NAME)
            written.append(into / SNAPSHOTS_NAME)
        return written

    def map_features(self, inputs):
        """The walls, sinks and gauges of the run's ``inputs`` in world coordinates, and the
        caption (CRS, period of the maps, calendar start) drawn with every map."""
        from floodsph.output.pictures import MapFeatures, map_caption

        t = inputs.terrain
        origin = np.array([t.x0, t.y0])
        gauges = () if inputs.gauges is None else tuple(
            (gid, float(x + t.x0), float(y + t.y0))
            for gid, x, y in zip(inputs.gauges.ids, inputs.gauges.x, inputs.gauges.y,
                                 strict=True))
        return MapFeatures(walls=tuple(np.asarray(w) + origin for w in inputs.walls),
                           sinks=tuple(np.asarray(s) + origin for s in inputs.sinks),
                           gauges=gauges,
                           caption=map_caption(self.grid.crs_wkt, self.envelopes.t_last,
                                               self.scenario.start))

    def write_pictures(self, features=None, mass_rows=()) -> list[str] | str:
        """Quick-look PNGs of the envelopes (with ``features``), the gauges and the mass
        balance (``mass_rows``); their names, or ``"skipped: <reason>"``."""
        from floodsph.output import write_pictures
        from floodsph.output.pictures import write_series_pictures

        result = write_pictures(self.envelopes, self.out, title=self.scenario.name,
                                features=features)
        if isinstance(result, str):
            return "skipped: " + result.removeprefix("pictures skipped: ")
        result += write_series_pictures(None if self.gauges is None else self.gauges.rows,
                                        mass_rows, self.out, self.scenario.start)
        return [Path(path).name for path in result]

    def write_report(self, manifest: dict, mass_rows, features) -> str:
        """Write ``report.html`` (:mod:`floodsph.output.report`) beside the quick-looks
        listed in ``manifest["pictures"]``; its name, with a note when it has no pictures."""
        from floodsph.io.atomic_files import atomic_path
        from floodsph.io.run_names import REPORT_NAME
        from floodsph.output.report import write_report

        drawn = not isinstance(manifest.get("pictures"), str)
        with atomic_path(self.out / REPORT_NAME) as tmp:
            write_report(tmp, manifest=manifest, envelopes=self.envelopes,
                         caption=features.caption,
                         gauge_rows=() if self.gauges is None else self.gauges.rows,
                         mass_rows=mass_rows, start=self.scenario.start,
                         pictures=self.out if drawn else None)
        return REPORT_NAME if drawn else f"{REPORT_NAME} (tables only: {manifest['pictures']})"

    def close(self) -> None:
        if self.snapshots is not None:
            self.snapshots.close()
            self.snapshots = None
