"""``workflows/ensemble_convergence.py`` on the tiny dam break at 2 and 4 members.

The table's rows must say what the two probability maps say: the 4-member reference differs
from itself by nothing, and the 2-member row's differences and area are those of the files.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
from conftest import load_script
from ensemble_cases import ensemble_text, write_case

REPO = Path(__file__).resolve().parents[2]
convergence = load_script("ensemble_convergence",
                            REPO / "workflows" / "ensemble_convergence.py")


def read(path):
    import rasterio

    with rasterio.open(path) as src:
        return src.read(1).astype(np.float64), abs(src.transform.a * src.transform.e)


def test_convergence_table_states_the_maps(tmp_path):
    path = write_case(tmp_path, ensemble_text(members=4))
    out, doc = tmp_path / "study", tmp_path / "convergence.md"
    rows = convergence.main(["--ensemble", str(path), "--sizes", "2", "4", "--out", str(out),
                             "--doc", str(doc), "--workers", "2", "--threads-per-worker", "1"])
    assert [r["members"] for r in rows] == [2, 4]
    small, reference = rows
    assert (reference["max_abs_diff"], reference["mean_abs_diff"],
            reference["area_p50_change_pct"]) == (0.0, 0.0, 0.0)
    p2, cell = read(out / "n2" / "p_depth_gt_0.1m.tif")
    p4, _ = read(out / "n4" / "p_depth_gt_0.1m.tif")
    assert small["max_abs_diff"] == np.abs(p2 - p4).max()
    assert small["area_p50_km2"] == np.count_nonzero(p2 > 0.5) * cell / 1e6
    assert small["std_error_max"] == 0.5 / math.sqrt(2)
    for n in (2, 4):
        manifest = json.loads((out / f"n{n}" / "ensemble.json").read_text())
        assert manifest["members_completed"] == n
        assert manifest["scheduler"].startswith("tcp://127.0.0.1:")  # one cluster for both
    text = doc.read_text()
    assert "| members | members_completed | max_abs_diff |" in text
    assert "`python workflows/ensemble_convergence.py --ensemble" in text
