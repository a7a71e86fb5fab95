"""``benchmarks/step_cost.py`` and the model's stage timer: the cost of a step, by stage."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import load_script

from floodsph.model.stage_timer import STAGES, StageTimer

pytestmark = pytest.mark.benchmark

REPO = Path(__file__).resolve().parents[2]
step_cost = load_script("step_cost", REPO / "benchmarks" / "step_cost.py")


def table_rows(text: str, first_column: str) -> list[dict]:
    """The rows of the markdown table whose header starts with ``first_column``."""
    lines = text.splitlines()
    top = next(k for k, line in enumerate(lines) if line.startswith(f"| {first_column} |"))
    header = [c.strip() for c in lines[top].strip("|").split("|")]
    rows = []
    for line in lines[top + 2:]:
        if not line.startswith("|"):
            break
        rows.append(dict(zip(header, (c.strip() for c in line.strip("|").split("|")),
                             strict=True)))
    return rows


def test_the_quick_form_reports_both_sizes_with_stages_that_add_up_to_the_step(tmp_path):
    """The 10 m and 5 m dam breaks seed 100 x 10 and 200 x 20 particles; every figure is
    positive, and the stages (exclusive, covering the whole step) add up to the time per
    step, as the timer marks every stage of it."""
    out = tmp_path / "step-cost.md"
    assert step_cost.main(["--quick", "--out", str(out)]) == 0
    text = out.read_text()
    assert "python benchmarks/step_cost.py --quick" in text
    rows = table_rows(text, "checkout")
    assert [int(r["particles"]) for r in rows] == [1000, 4000]
    for r in rows:
        stages = [float(r[f"us_{s}"]) for s in STAGES]
        assert float(r["particle_steps_per_s"]) > 0 and float(r["ms_per_step"]) > 0
        assert min(stages) >= 0 and min(float(r[f"us_{s}"]) for s in
                                        ("neighbours", "density", "forces")) > 0
        assert sum(stages) == pytest.approx(1e3 * float(r["ms_per_step"]), rel=0.02)
    assert [r["checkout"] for r in rows] == ["this", "this"]


def test_the_stage_timer_counts_only_the_steps_taken_while_it_is_set():
    model = step_cost.dam_break(10.0)
    model.step()
    timer = model.stage_timer = StageTimer()
    for _ in range(3):
        model.step()
    assert timer.steps == 3 and set(timer.seconds) == set(STAGES)
    spent = dict(timer.seconds)
    model.stage_timer = None
    model.step()
    assert timer.seconds == spent and timer.steps == 3


def test_a_compare_reference_that_is_neither_a_checkout_nor_a_commit_is_named(tmp_path):
    with pytest.raises(SystemExit, match="no-such-ref"):
        step_cost.reference_root("no-such-ref", tmp_path)


def test_the_balanced_form_measures_the_balanced_momentum_and_counts_the_list_builds(tmp_path):
    """``--momentum balanced`` builds the dam break under the balanced momentum (its lake
    at rest has levels to balance), and every row says how often the lists were built: at
    least once in the run's steps and at most twice a step (the build at the step and the
    one repeat of a capped density solve)."""
    assert step_cost.dam_break(10.0, "balanced").domain.balanced
    assert not step_cost.dam_break(10.0, "variational").domain.balanced
    assert step_cost.dam_break(10.0).domain.balanced  # the checkout's default
    out = tmp_path / "step-cost.md"
    assert step_cost.main(["--quick", "--momentum", "balanced", "--out", str(out)]) == 0
    text = out.read_text()
    assert "--momentum balanced" in text
    for r in table_rows(text, "checkout"):
        assert 0.0 < float(r["list_builds_per_step"]) <= 2.0


def test_scaling_measures_two_threads_against_one_on_the_same_particles(tmp_path):
    """``--scaling``: each size measured on two threads and on one in the same process, the
    ratio being that of the two rows' particle-steps/s; one thread alone is refused."""
    import numba

    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one numba thread available")
    out = tmp_path / "scaling.md"
    assert step_cost.main(["--quick", "--scaling", "--threads", "2", "--out", str(out)]) == 0
    text = out.read_text()
    rows = table_rows(text, "checkout")
    assert [r["checkout"] for r in rows] == ["2 threads", "2 threads", "1 thread", "1 thread"]
    speed = {(r["checkout"], int(r["particles"])): float(r["particle_steps_per_s"])
             for r in rows}
    for r in table_rows(text, "particles"):
        n = int(r["particles"])
        assert float(r["speed 2 threads / 1 thread"]) == pytest.approx(
            speed["2 threads", n] / speed["1 thread", n], rel=2e-3)
    assert step_cost.main(["--quick", "--scaling", "--threads", "1",
                           "--out", str(tmp_path / "no.md")]) == 2
    assert not (tmp_path / "no.md").exists()
