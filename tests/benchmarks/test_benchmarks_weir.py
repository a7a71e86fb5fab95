"""``benchmarks/weir.py``: steady flow over a crest wall, free and submerged, against the weir
law with Villemonte's submergence (short runs of its cases)."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import load_script

from floodsph.boundaries.weir import unit_discharge
from floodsph.scenario.numerics import Momentum

pytestmark = pytest.mark.benchmark

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
weir = load_script("weir_benchmark", BENCHMARKS / "weir.py")


@pytest.mark.parametrize("momentum", [
    Momentum.VARIATIONAL,
    pytest.param(Momentum.BALANCED, marks=pytest.mark.xfail(
        strict=True, reason="under the balanced momentum the first wall passes 20 % less than "
        "the submerged law at the levels measured 3-7 m either side (0.111 against 0.139 "
        "m2/s at 0.25 m spacing): its pieces pass 1.6 times as much water back"))])
def test_submerged_weir_passes_what_villemonte_says(momentum):
    """A second, lower crest wall holds a tailwater about half the head above the first
    crest: the net volume passed per metre over the first wall over 10-20 s matches the
    submerged law at the levels measured 3-7 m either side within 15 % (the model passes
    5-10 % less: the particles injected into the tailwater raise its level by the wall, and
    some pieces pass water back), and lies below the free law at the upstream level by about
    Villemonte's factor."""
    row = weir.run_case("submerged", 0.5, 0.95, 0.25, 20.0, momentum)
    assert 0.3 < row["submergence"] < 0.8
    assert row["q_model"] == pytest.approx(row["q_law"], rel=0.15)
    free = float(unit_discharge(row["H_u"]))
    factor = (1.0 - row["submergence"] ** 1.5) ** 0.385
    assert row["q_model"] / free == pytest.approx(factor, rel=0.15)
    assert row["q_model"] < 0.95 * free  # the tailwater holds the flow back


def test_the_table_lists_every_row():
    rows = [{"case": "free", "Q_in": 0.5, "q_in": 0.1, "submergence": 0.0, "H_u": 0.15,
             "H_expected": 0.151, "error_H": -0.007, "q_model": 0.1, "q_law": 0.0984,
             "error_q": 0.016, "particles": 1000, "wall_s": 7.0}]
    text = weir.table(rows, 0.25, 30.0)
    assert "| free | 0.5 | 0.100 | 0.00 |" in text and "+1.6 %" in text
