"""Cost and agreement of the refinement modes on the sample valley and on Malpasset.

Runs each scenario with ``numerics.refinement`` = "none", "split" and "split+coalesce"
through the real run chain (``floodsph.run.pipeline.run_scenario``: run folder, maps, run.json) and
reports, per run: wall time, steps, peak and final particle counts, particle-steps (the sum
over steps of the particle count, the solver's work measure), splits, merges and the mass
error; and, for each pair of modes, the agreement of their ``max_depth.tif`` maps
(``floodsph.output.compare``: CSI with wet = depth > 0.1 m, and RMSE / bias over cells wet in both).

Scenarios: ``data_samples/valley/scenario.toml`` (its own end time, 600 s) and Malpasset
(the scenario of ``benchmarks/malpasset``, the sea as particles, cut to 1000 s), written from
the third-party data read from ``$FLOODSPH_BENCHMARKS/malpasset`` or
``<repo>/../shared/benchmarks/malpasset``; the case is skipped with a message when it is
absent.

Writes ``refinement_benchmark.csv`` and ``agreement.csv`` into ``--out`` and prints both as
markdown tables. Wall times depend on the machine's load: compare the ratios within one run.

    python benchmarks/refinement_benchmark.py [--out results/refinement_benchmark]
        [--cases valley malpasset] [--modes none split split+coalesce] [--max-steps N]
        [--malpasset-spacing 40] [--malpasset-end-time 1000] [--set refine_area_min=0.5 ...]
        [--time-stepping global|local]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent / "malpasset"))

import malpasset_setup as mp_setup  # noqa: E402
import scenario_runs as runs  # noqa: E402

from floodsph.output.tables import markdown, write_csv  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
MODES = ("none", "split", "split+coalesce")
CASES = {"valley": REPO / "data_samples" / "valley" / "scenario.toml", "malpasset": None}
MALPASSET_END_S = 1000.0


def scenario_for(case: str, mode: str, out: Path, spacing: float | None = None,
                 end_time: float | None = None, settings: dict | None = None,
                 time_stepping: str | None = None):
    """The case's scenario with ``mode`` and ``out`` as the run folder.

    ``spacing`` [m], ``end_time`` [s] and ``time_stepping`` override the scenario's particle
    spacing, end time and time stepping. Malpasset's scenario is written next to ``out``
    from the benchmark data found by ``malpasset_setup.data_folder`` (the sea as particles,
    20 m spacing and 1000 s unless overridden). Returns None (after printing why) when the
    case's data is missing.
    """
    path = CASES[case]
    if case == "malpasset":
        folder = mp_setup.data_folder()
        if folder is None:
            print("malpasset: skipped, benchmark data not found (set FLOODSPH_BENCHMARKS)")
            return None
        end_time = end_time or MALPASSET_END_S
        path = mp_setup.write_scenario(folder, out.parent / f"{out.name}_inputs", "particles",
                                       end_time, spacing or 20.0)
    return runs.variant(path, out, mode, spacing, end_time, settings, time_stepping)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("results/refinement_benchmark"))
    ap.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES))
    ap.add_argument("--modes", nargs="+", choices=MODES, default=list(MODES))
    ap.add_argument("--max-steps", type=int, default=None, help="trial runs: stop early")
    ap.add_argument("--malpasset-spacing", type=float, default=None,
                    help="particle spacing [m] for Malpasset (default: the scenario's 20 m)")
    ap.add_argument("--malpasset-end-time", type=float, default=None,
                    help="simulated time [s] for Malpasset (default 1000 s)")
    ap.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE",
                    help="[numerics] refinement keys, e.g. refine_area_min=0.5")
    ap.add_argument("--time-stepping", choices=("global", "local"), default=None,
                    help="numerics.time_stepping of every run (default: the scenario's)")
    args = ap.parse_args(argv)
    out = args.out.resolve()
    settings = {}
    for item in args.set:
        key, _, value = item.partition("=")
        if key not in runs.REFINE_KEYS:
            ap.error(f"--set {item}: key must be one of {runs.REFINE_KEYS}")
        try:
            settings[key] = int(value) if key == "refine_max_level" else float(value)
        except ValueError:
            ap.error(f"--set {item}: {value!r} is not a number")
    rows, pairs = [], []
    for case in args.cases:
        done = []
        for mode in args.modes:
            mp = case == "malpasset"
            scenario = scenario_for(case, mode, out / case / mode,
                                    args.malpasset_spacing if mp else None,
                                    args.malpasset_end_time if mp else None, settings,
                                    args.time_stepping)
            if scenario is not None:
                rows.append(runs.run(scenario, out / case / mode, args.max_steps, case=case))
                done.append(mode)
        for i, a in enumerate(done):
            for b in done[i + 1:]:
                pairs.append({"case": case, "mode": b, "against": a,
                              **runs.agreement(out / case / b, out / case / a)})
    if not rows:
        return
    out.mkdir(parents=True, exist_ok=True)
    write_csv(out / "refinement_benchmark.csv", rows)
    print("\n" + markdown(rows))
    if pairs:
        write_csv(out / "agreement.csv", pairs)
        print("\n" + markdown(pairs))


if __name__ == "__main__":
    main()
