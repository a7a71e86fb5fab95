"""``benchmarks/validation_pages.py --quick``: each analytic page at its coarsest spacing.

The page's table is read back and its errors against the exact solutions checked with generous
bounds, stated in terms of the physics and the spacing rather than of an earlier run:

* Ritter at 10 m (a tenth of the 100 m channel width, 1/100 of the dam's reach): L1 < 5 %,
  the front within 50 m (5 spacings) of 2 sqrt(g d0) t = 990 m beyond the dam;
* Stoker at 10 m: L1 < 3 % (the bore carries most of the error, the rest is still water),
  the bore within 20 m (2 spacings);
* Thacker at 200 m (15 spacings across the wet disc's radius of 3 km): L1 < 6 %, the shore
  within 300 m.

The mass of a closed domain is kept to round-off in every mode.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import load_script

pytestmark = pytest.mark.benchmark

pages = load_script("validation_pages", Path(__file__).resolve().parents[2] / "benchmarks"
                      / "validation_pages.py")

BOUNDS = {"ritter": (0.05, 50.0), "stoker": (0.03, 20.0), "thacker": (0.06, 300.0)}
COARSE = {"ritter": "10", "stoker": "10", "thacker": "200"}


def _table(text: str) -> list[dict]:
    """The rows of the page's error table (the first markdown table)."""
    lines = [line for line in text.splitlines() if line.startswith("|")]
    head = [c.strip() for c in lines[0].strip("|").split("|")]
    return [dict(zip(head, (c.strip() for c in line.strip("|").split("|")), strict=True))
            for line in lines[2:]]


@pytest.mark.parametrize("case", sorted(BOUNDS))
def test_quick_page_has_both_modes_within_physical_bounds(case, tmp_path):
    pages.main(["--case", case, "--quick", "--out", str(tmp_path)])
    text = (tmp_path / f"{case}.md").read_text()
    rows = _table(text)
    assert [(r["refinement"], r["spacing m"]) for r in rows] == [
        ("split+coalesce", COARSE[case]), ("none", COARSE[case])]
    l1_max, front_max = BOUNDS[case]
    front = "shore error m" if case == "thacker" else "front error m"
    for r in rows:
        assert 0.0 < float(r["L1"]) < l1_max, r
        assert float(r["mass error"]) < 1e-12, r
        assert int(r["peak particles"]) >= int(r["particles at the end"]) > 0
    # the default numerics: the front where the exact solution has it
    assert abs(float(rows[0][front])) < front_max, rows[0]
    assert f"python benchmarks/validation_pages.py --case {case} --quick" in text
    assert "at commit `" in text and "numba thread(s)" in text
    assert (tmp_path / f"{case}.png").stat().st_size > 10_000
    assert f"]({case}.png)" in text


def test_setup_states_the_exact_solutions_parameters():
    ritter = "\n".join(pages.setup_text("ritter"))
    assert "2000 m x 100 m" in ritter and "10 m deep for x < 1000 m" in ritter
    assert "a dry bed" in ritter and "End time 50 s" in ritter
    assert "still water 2 m deep" in "\n".join(pages.setup_text("stoker"))
    # Thacker's period 2 pi a / sqrt(2 g h0) = 2 pi 3000 / sqrt(2 9.81 10) = 1345.7 s
    assert "T = 1345.7 s" in "\n".join(pages.setup_text("thacker"))
