"""The summary page of floodsph against ANUGA: the sample valley, EA test 4 and Malpasset.

Writes ``docs/validation/against-anuga.md``: one row per case with the maximum-depth scores of
``floodsph.output.compare`` (floodsph = model, ANUGA = reference, wet = depth > 0.1 m: CSI, hit
rate,
false-alarm ratio, depth RMSE and bias over the cells wet in both) and the wall time of each
code on the same thread count, read from the results folders of

* the sample valley (``data_samples/valley/scenario.toml``): ``versus_grid_code.py``, run here
  when ``--valley DIR`` holds no result yet;
* EA test 4 at 10 m: the ``versus_grid_code.py`` folder that ``ea_test4/ea_test4_page.py``
  made (``--ea4 DIR``);
* Malpasset at 20 m: ``summary.json`` of ``malpasset/malpasset_page.py`` (``--malpasset DIR``,
  its ``--work`` folder).

A case whose folder holds no result is listed as not run. No analytic-case table: neither
``versus_grid_code.py`` nor ``speed_vs_error.py`` runs ANUGA on Ritter.

Usage: ``python benchmarks/against_anuga_page.py [--valley DIR] [--ea4 DIR] [--malpasset DIR]
[--threads 1] [--out docs/validation]``
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import provenance  # noqa: E402
import run_record  # noqa: E402
import versus_grid_code as grid_code  # noqa: E402

from floodsph.output.tables import markdown  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
CASES = (("valley", "valley-breach", "sample valley dam break, 10 m, 600 s",
          "[versus_grid_code.py](../../benchmarks/versus_grid_code.py)"),
         ("ea4", "ea_test4", "EA test 4, 10 m DEM", "[EA test 4](ea-test4.md)"),
         ("malpasset", "malpasset", "Malpasset, 20 m DEM, 4000 s", "[Malpasset](malpasset.md)"))


def versus_row(folder: Path, scenario: str) -> dict | None:
    """The ``versus_grid_code.csv`` row of ``scenario`` in ``folder``, numbers as floats."""
    path = folder / "versus_grid_code.csv"
    if not path.is_file():
        return None
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["scenario"] == scenario:
                return {k: v if k == "scenario" else float(v) for k, v in row.items()}
    return None


def malpasset_row(folder: Path) -> dict | None:
    path = folder / "summary.json"
    return json.loads(path.read_text()) if path.is_file() else None


def valley_run(folder: Path, threads: int) -> None:
    cmd = [sys.executable, str(REPO / "benchmarks" / "versus_grid_code.py"), "--threads",
           str(threads), "--out", str(folder), "--quiet"]
    env = dict(os.environ, NUMBA_NUM_THREADS=str(threads), OMP_NUM_THREADS=str(threads))
    run_record.run_recorded(cmd, folder, REPO, env)


def table(rows: dict) -> str:
    out = []
    for key, _, title, link in CASES:
        r = rows.get(key)
        if r is None:
            out.append({"case": f"{title} ({link})", "CSI": "not run", "hit rate": "",
                        "false-alarm ratio": "", "depth RMSE m": "", "depth bias m": "",
                        "threads": "", "floodsph wall s": "", "ANUGA wall s": "",
                        "floodsph / ANUGA": ""})
            continue
        ratio = r["floodsph_wall_s"] / r["anuga_wall_s"]
        out.append({"case": f"{title} ({link})", "CSI": f"{r['csi']:.3f}",
                    "hit rate": f"{r['hit_rate']:.3f}",
                    "false-alarm ratio": f"{r['false_alarm_ratio']:.3f}",
                    "depth RMSE m": f"{r['depth_rmse_m']:.3f}",
                    "depth bias m": f"{r['depth_bias_m']:+.3f}", "threads": f"{r['threads']:.0f}",
                    "floodsph wall s": f"{r['floodsph_wall_s']:.0f}",
                    "ANUGA wall s": f"{r['anuga_wall_s']:.0f}",
                    "floodsph / ANUGA": f"{ratio:.2f}"})
    return markdown(out)


def verdicts(rows: dict) -> list[str]:
    """One plain sentence per case: faster or slower, and by how much; the depth bias."""
    lines = []
    for key, _, title, _ in CASES:
        r = rows.get(key)
        if r is None:
            continue
        ratio = r["floodsph_wall_s"] / r["anuga_wall_s"]
        speed = (f"floodsph is {ratio:.1f} times slower than ANUGA" if ratio > 1 else
                 f"floodsph is {1 / ratio:.1f} times faster than ANUGA")
        side = "deeper" if r["depth_bias_m"] > 0 else "shallower"
        lines.append(f"* {title}: {speed} on {r['threads']:.0f} thread(s); the maps agree "
                     f"to CSI {r['csi']:.3f}, and floodsph's maximum depth is "
                     f"{abs(r['depth_bias_m']):.2f} m {side} on average (RMSE "
                     f"{r['depth_rmse_m']:.2f} m) where both are wet.")
    return lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--valley", type=Path, default=RESULTS / "versus_grid_code_valley",
                        help="versus_grid_code.py folder of the sample valley (run if empty)")
    parser.add_argument("--ea4", type=Path, default=RESULTS / "ea_test4_anuga" / "versus_anuga",
                        help="versus_grid_code.py folder of EA test 4")
    parser.add_argument("--malpasset", type=Path, default=RESULTS / "malpasset_anuga",
                        help="the --work folder of malpasset_page.py")
    parser.add_argument("--threads", type=int, default=1, help="threads of a new valley run")
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "validation")
    args = parser.parse_args(argv)
    argv = sys.argv[1:] if argv is None else argv
    t0, load0 = time.perf_counter(), os.getloadavg()[0]
    valley = args.valley.resolve()
    if versus_row(valley, CASES[0][1]) is None:
        if not grid_code.anuga_available():
            print("ANUGA is not installed (pip install anuga) and --valley holds no result: "
                  "the page is not made.", file=sys.stderr)
            return 0
        valley_run(valley, args.threads)
    rows = {"valley": versus_row(valley, CASES[0][1]),
            "ea4": versus_row(args.ea4.resolve(), CASES[1][1]),
            "malpasset": malpasset_row(args.malpasset.resolve())}
    rows = {k: v for k, v in rows.items() if v is not None}
    records = {"valley": run_record.read(valley), "ea4": run_record.read(args.ea4.resolve())}
    machine = provenance.machine_note((load0, os.getloadavg()[0]), time.perf_counter() - t0,
                                      "The wall times in the table are those of the runs.")
    command = " ".join(["python benchmarks/against_anuga_page.py", *argv])
    text = "\n".join([
        "# floodsph against ANUGA", "",
        f"Made by `{command}` on {time.strftime('%Y-%m-%d')} at commit "
        f"`{provenance.commit(REPO)}`; {machine}", "",
        f"* Sample valley run: {run_record.note(records['valley'])}.",
        f"* EA test 4 runs: {run_record.note(records['ea4'])}; Malpasset: see its page.", "",
        "ANUGA 4 (Geoscience Australia; flow algorithm DE0, a second-order finite-volume "
        "scheme on triangles) is the reference here, not the truth: both codes solve the "
        "shallow-water equations on the same DEM with the same Manning n, initial water, "
        "inflows and end time, and each page gives the set-up. Maximum-depth maps are "
        "compared with `floodsph compare` (floodsph = model, ANUGA = reference, wet = "
        "maximum depth > 0.1 m); RMSE and bias of the maximum depth are over the cells wet in "
        "both. Wall times: floodsph's `run.json` `wall_time_s` (inputs, solver, output maps), "
        "ANUGA's set-up and `evolve`, both on the same number of threads, on a shared 2-core "
        "machine (indicative only). ANUGA's meshes: four triangles per DEM cell (valley, EA "
        "test 4); the benchmark's 26 000-triangle mesh, the bed from the 20 m DEM "
        "(Malpasset).", "",
        table(rows), "",
        *verdicts(rows), "",
        "Malpasset: the sea cells are left out of its map comparison (floodsph's sea is a "
        "sink, ANUGA's still water at 0 m); see its page. The analytic cases (Ritter, Stoker, "
        "Thacker) have their own pages against the exact solutions; no workflow here runs "
        "ANUGA on them.", "",
    ])
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "against-anuga.md"
    path.write_text(text)
    print(f"page: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
