"""The reconstructed dissipation ("muscl") against the Lax-Friedrichs term: analytic errors,
still water and, given two runs, the Malpasset maps.

What it measures, for ``numerics.stabilisation`` = "lax-friedrichs" (the default) and "muscl"
(``floodsph.sph.forces.reconstructed_jump``), both with ``numerics.momentum = "variational"``
(which "muscl" needs):

* the analytic cases of ``floodsph.verification.cases`` (Ritter and Stoker at 10 and 5 m,
  Thacker at 200 and 100 m) in four modes: no refinement or split+coalesce, each with one
  global step or local steps; the L1 error against the exact solution, the front (or bore,
  or shore) error and the solver's wall time;
* with ``--still-water``, the quick still-water benchmark (``still_water.py --quick``) with
  each stabilisation: the worst speeds of each case over 60 s and its small dam breaks;
* with ``--malpasset LF_DIR MUSCL_DIR``, two results folders of
  ``malpasset/run_malpasset.py --sea sink --momentum variational`` (the second run with
  ``--stabilisation muscl``):
  the maximum-depth maps compared with ``floodsph.output.compare`` (CSI, depth RMSE and bias
  over the cells wet in both, wet = depth > 0.1 m), the arrival times at S6-S14 and the wall
  times of the two runs.

Writes ``docs/reconstruction.md`` (``--out``). The runs go one at a time on ``--threads``
threads; the kernels are compiled (or loaded) by a first small run of each mode.

Usage: ``python benchmarks/reconstruction.py [--threads 1] [--still-water]
[--malpasset LF_DIR MUSCL_DIR] [--out docs/reconstruction.md]``
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import provenance  # noqa: E402

from floodsph.output.tables import markdown  # noqa: E402
from floodsph.run.pipeline import set_threads  # noqa: E402
from floodsph.scenario.numerics import (  # noqa: E402
    Momentum,
    Refinement,
    Stabilisation,
    TimeStepping,
)
from floodsph.verification import cases  # noqa: E402

REPO = Path(__file__).resolve().parent.parent
RESOLUTIONS = {"ritter": (10.0, 5.0), "stoker": (10.0, 5.0), "thacker": (200.0, 100.0)}
MODES = ((Refinement.NONE, TimeStepping.GLOBAL), (Refinement.NONE, TimeStepping.LOCAL),
         (Refinement.SPLIT_COALESCE, TimeStepping.GLOBAL),
         (Refinement.SPLIT_COALESCE, TimeStepping.LOCAL))
SCHEMES = {Stabilisation.LAX_FRIEDRICHS: "LF", Stabilisation.MUSCL: "muscl"}
"""The two stabilisations compared, with their tags in the tables' columns."""
STILL_CASES = ("rectangle 15 deg", "rectangle 30 deg", "rectangle 45 deg", "nodata staircase",
               "parabolic bowl", "building 30 deg")
GAUGES = tuple(f"S{k}" for k in range(6, 15))


def analytic_rows() -> list[dict]:
    """One row per case, resolution and mode: both schemes' L1, front error and wall time."""
    for name in RESOLUTIONS:  # compile or load every mode's kernels first
        for refinement, stepping in MODES:
            for scheme in SCHEMES:
                cases.CASES[name](40.0 if name != "thacker" else 400.0, refinement=refinement,
                                  time_stepping=stepping, stabilisation=scheme,
                                  momentum=Momentum.VARIATIONAL)
    rows = []
    for name, spacings in RESOLUTIONS.items():
        for dx in spacings:
            for refinement, stepping in MODES:
                row = {"case": name, "spacing m": dx,
                       "mode": f"{refinement.value}, {stepping.value}"}
                for scheme, tag in SCHEMES.items():
                    r = cases.CASES[name](dx, refinement=refinement, time_stepping=stepping,
                                          stabilisation=scheme, momentum=Momentum.VARIATIONAL)
                    row[f"L1 % {tag}"] = 100.0 * r.l1
                    row[f"front m {tag}"] = r.front_error_m
                    row[f"wall s {tag}"] = r.wall_s
                row["L1 muscl / LF"] = row["L1 % muscl"] / row["L1 % LF"]
                print(" ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}"
                               for k, v in row.items()), flush=True)
                rows.append(row)
    return rows


def still_water_rows(folder: Path) -> tuple[list[dict], list[dict]]:
    """The quick still-water benchmark once per scheme: worst max / p95 speed per case, and
    the small dam breaks' L1 and front error."""
    import still_water

    out = {}
    for scheme in SCHEMES:
        bench = still_water.run_benchmark(still_water.parse_args(
            ["--quick", "--stabilisation", scheme.value, "--momentum", "variational", "--out",
             str(folder / scheme.value)]))
        out[scheme] = ({r.case.label: still_water.still_row(r) for r in bench.still},
                       {row["case"]: row for row in still_water.dam_break_rows(bench.dam_break)})
    rows = []
    for label in STILL_CASES:
        row = {"case": label}
        for scheme, tag in SCHEMES.items():
            still = out[scheme][0][label]
            row[f"max cm/s {tag}"] = still["max speed cm/s"]
            row[f"p95 cm/s {tag}"] = still["p95 speed cm/s"]
        rows.append(row)
    breaks = []
    for label in out[Stabilisation.LAX_FRIEDRICHS][1]:
        row = {"case": label}
        for scheme, tag in SCHEMES.items():
            row[f"L1 % {tag}"] = out[scheme][1][label]["L1 %"]
            row[f"front m {tag}"] = out[scheme][1][label]["front error m"]
        breaks.append(row)
    return rows, breaks


def malpasset_rows(lf_dir: Path, muscl_dir: Path) -> tuple[list[str], list[dict]]:
    """Map agreement and gauge arrivals of two ``run_malpasset.py --sea sink`` folders."""
    from floodsph.output.compare import compare

    runs = {tag: Path(d) / "sink" for tag, d in (("LF", lf_dir), ("muscl", muscl_dir))}
    c = compare(runs["muscl"] / "run" / "max_depth.tif", runs["LF"] / "run" / "max_depth.tif",
                threshold=0.1).summary
    walls = {tag: json.loads((run / "cost.json").read_text())["wall_time_s"]
             for tag, run in runs.items()}
    text = [f"Maximum-depth maps, muscl against Lax-Friedrichs (wet > 0.1 m): CSI "
            f"{c['csi']:.3f}, hit rate {c['hit_rate']:.3f}, false-alarm ratio "
            f"{c['false_alarm_ratio']:.3f}; depth RMSE {c['depth']['rmse']:.2f} m and bias "
            f"{c['depth']['bias']:+.2f} m over the cells wet in both. Wall times: "
            f"{walls['LF']:.0f} s (Lax-Friedrichs) and {walls['muscl']:.0f} s (muscl)."]
    points = {}
    for tag, run in runs.items():
        with open(run / "points.csv", newline="") as f:
            points[tag] = {p["id"]: p for p in csv.DictReader(f)}
    rows = [{"gauge": g,
             **{f"max level m {tag}": float(points[tag][g]["max_level_m"]) for tag in runs},
             **{f"arrival s {tag}": float(points[tag][g]["arrival_time_s"]) for tag in runs}}
            for g in GAUGES]
    return text, rows


def ratio_summary(analytic: list[dict]) -> list[str]:
    """Per case: the range of muscl's L1 over Lax-Friedrichs's, and the cost ratio."""
    lines = []
    for name in RESOLUTIONS:
        rows = [r for r in analytic if r["case"] == name]
        ratios = sorted(r["L1 muscl / LF"] for r in rows)
        cost = sorted(r["wall s muscl"] / r["wall s LF"] for r in rows)
        better = sum(x < 1.0 for x in ratios)
        lines.append(f"* {name}: muscl's L1 is {ratios[0]:.2f}-{ratios[-1]:.2f} times the "
                     f"default's (lower in {better} of {len(rows)} runs), for "
                     f"{cost[0]:.2f}-{cost[-1]:.2f} times the wall time.")
    return lines


def page(analytic, still, malpasset, command: str, note: str) -> str:
    lines = ["# Reconstructed dissipation (\"muscl\") against Lax-Friedrichs", "",
             f"Made by `{command}` at commit `{provenance.commit(REPO)}`; {note}", "",
             "`numerics.stabilisation = \"muscl\"` applies the Lax-Friedrichs-type term to every "
             "pair, on the velocity jump left once both velocities are carried to the pair's "
             "midpoint along their renormalised gradients, limited by van Leer's limiter "
             "(`docs/method.md`). The default, \"lax-friedrichs\", applies it to approaching "
             "pairs on the raw jump.", "",
             "## Analytic cases", "",
             "L1 of the depth against the exact solution (`floodsph.verification.cases`), the "
             "front error (Ritter's dry front, Stoker's bore, Thacker's shore) and the solver's "
             "wall time.", "", markdown(analytic, spec=".3g"), "", *ratio_summary(analytic), ""]
    if still:
        lines += ["## Still water (quick cases, 60 s)", "",
                  "Worst particle speed over the report times (`still_water.py --quick`), and "
                  "the L1 of its small dam breaks (300 particles, split+coalesce, local steps).",
                  "", markdown(still[0], spec=".3g"), "", markdown(still[1], spec=".3g"), ""]
    if malpasset:
        text, rows = malpasset
        lines += ["## Malpasset", "", "Two runs of `benchmarks/malpasset/run_malpasset.py "
                  "--sea sink --threads 1` (20 m, default refinement and local steps, 4000 s), "
                  "the second with `--stabilisation muscl`.", "", *text, "",
                  markdown(rows, spec=".4g"), ""]
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--still-water", action="store_true")
    ap.add_argument("--malpasset", nargs=2, type=Path, metavar=("LF_DIR", "MUSCL_DIR"))
    ap.add_argument("--out", type=Path, default=REPO / "docs" / "reconstruction.md")
    args = ap.parse_args(argv)
    set_threads(args.threads)
    t0, load0 = time.perf_counter(), os.getloadavg()[0]
    analytic = analytic_rows()
    with tempfile.TemporaryDirectory() as tmp:
        still = still_water_rows(Path(tmp)) if args.still_water else None
    malpasset = malpasset_rows(*args.malpasset) if args.malpasset else None
    command = "python benchmarks/reconstruction.py " + " ".join(sys.argv[1:] if argv is None
                                                                else argv)
    note = provenance.machine_note((load0, os.getloadavg()[0]), time.perf_counter() - t0,
                                   "Wall times are of this machine and this run.")
    args.out.write_text(page(analytic, still, malpasset, command.strip(), note) + "\n",
                        encoding="utf-8")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
