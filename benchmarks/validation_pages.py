"""One validation page per analytic case: Ritter, Stoker and Thacker against their exact solutions.

Each page (``<out>/<case>.md``, default ``docs/validation``) gives the case's set-up, the L1
relative depth error, front error, mass error and solver wall time at three particle spacings
with the default refinement (``floodsph.scenario.numerics.Numerics()``: ``split+coalesce``) and
with refinement ``none``, both with one global time step (``floodsph.verification.cases``),
and a figure beside it (``<case>.png``): the depth profile of each default run at the end
time against the exact solution. The runs are
those of ``floodsph.verification.cases`` (the real solver path on an analytic bed) and the exact
solutions those of ``floodsph.verification.exact``.

    NUMBA_NUM_THREADS=2 python benchmarks/validation_pages.py --case ritter [--out DIR] [--quick]

``--quick`` runs the coarsest spacing only (a check of the page, seconds once compiled). Every
kernel is compiled first by an untimed run of the coarsest spacing in each mode. Wall times
are of the machine and the moment: the page says how loaded the machine was.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import provenance  # noqa: E402

from floodsph.output.tables import markdown  # noqa: E402
from floodsph.scenario.numerics import Numerics, Refinement  # noqa: E402
from floodsph.verification import cases, exact, metrics  # noqa: E402

REPO = Path(__file__).resolve().parents[1]

SPACINGS = {"ritter": (10.0, 5.0, 2.5), "stoker": (10.0, 5.0, 2.5),
            "thacker": (200.0, 100.0, 50.0)}
"""Particle spacings [m] of each case, coarse to fine (those of benchmarks/speed_vs_error.py)."""

DEFAULT = Numerics().refinement
MODES = (DEFAULT, Refinement.NONE)

TITLES = {"ritter": "Ritter: dam break onto a dry bed",
          "stoker": "Stoker: dam break onto a wet bed",
          "thacker": "Thacker: planar oscillation in a paraboloid"}


def setup_text(case: str) -> list[str]:
    """The page's set-up paragraph, from the case's parameters in
    ``floodsph.verification.cases``."""
    kappa = Numerics.kappa
    if case in ("ritter", "stoker"):
        c = cases.RITTER if case == "ritter" else cases.STOKER
        downstream = "a dry bed" if c.d_right == 0.0 else f"still water {c.d_right:g} m deep"
        front = ("front error: last x with d > 0.1 m, run minus exact" if c.d_right == 0.0
                 else "front error: bore position (where d crosses the mean of the middle and "
                 "downstream depths), run minus exact")
        return [
            f"* Domain: a closed, flat, frictionless channel {c.length:g} m x {c.width:g} m "
            f"(bed grid {c.cell:g} m), walls all round.",
            f"* Initial state: still water {c.d_left:g} m deep for x < {c.x_dam:g} m, "
            f"{downstream} beyond; the dam vanishes at t = 0.",
            f"* End time {c.t_end:g} s (no wave has reached a wall). Particles on a square "
            f"lattice at spacing dx, h = {kappa:g} dx.",
            "* Measures: L1 relative error of the Shepard-interpolated depth on 1 m bins, mean "
            f"of four lines along the channel (y = 12.5, 37.5, 62.5, 87.5 m); {front}; mass "
            "error |V(t) - V(0)| / V(0).",
        ]
    b = cases.THACKER
    return [
        f"* Domain: the square |x|, |y| <= {b.half_width:g} m over the frictionless bed "
        f"b = h0 (x^2 + y^2) / a^2 with h0 = {b.h0:g} m, a = {b.a:g} m (bed grid {b.cell:g} m).",
        f"* Initial state: Thacker's planar surface with orbit radius eta = {b.eta:g} m "
        "(exact depth and velocity at t = 0 on the particles).",
        f"* End time: one period, T = {exact.thacker_period(b.h0, b.a):.1f} s. Particles on a "
        f"square lattice at spacing dx, h = {kappa:g} dx.",
        "* Measures: L1 relative depth error over the exact wet disc on a 50 m grid; shore "
        "error: the farthest wet grid node (d > 1 mm) from the exact disc's centre, minus a; "
        "mass error |V(t) - V(0)| / V(0). The figure is the depth along y = 0.",
    ]


@dataclass
class Machine:
    """The machine around one page's runs."""

    load: tuple[float, float]
    wall_s: float

    def note(self) -> str:
        return provenance.machine_note(self.load, self.wall_s, "Wall times are indicative only.")


def run_case(case: str, quick: bool) -> tuple[list[cases.CaseResult], Machine]:
    """Every run of a page, the default numerics first at each spacing."""
    for mode in MODES:  # compile every kernel the case uses outside the timings
        cases.CASES[case](SPACINGS[case][0], refinement=mode)
    t0, load0 = time.perf_counter(), os.getloadavg()[0]
    rows = []
    for dx in SPACINGS[case][:1] if quick else SPACINGS[case]:
        for mode in MODES:
            rows.append(cases.CASES[case](dx, refinement=mode))
            r = rows[-1]
            print(f"{case} {r.refinement} dx={dx:g}: L1={r.l1:.4f} "
                  f"front={r.front_error_m:.1f} m wall={r.wall_s:.1f} s", flush=True)
    return rows, Machine((load0, os.getloadavg()[0]), time.perf_counter() - t0)


def table(rows: list[cases.CaseResult]) -> str:
    front = "shore error m" if rows[0].case == "thacker" else "front error m"
    return markdown([{
        "refinement": r.refinement, "spacing m": f"{r.spacing:g}",
        "particles at the end": r.particles, "peak particles": r.particles_max,
        "steps": r.steps, "solver wall s": f"{r.wall_s:.3g}",
        "L1": f"{r.l1:.4f}", front: f"{r.front_error_m:.3g}",
        "mass error": f"{r.mass_error_rel:.1e}"} for r in rows])


def order_text(rows: list[cases.CaseResult]) -> str:
    """Observed orders of the L1 error in the spacing, one per refinement mode."""
    parts = []
    for mode in MODES:
        sel = [r for r in rows if r.refinement == mode.value]
        if len(sel) > 1:
            p = metrics.observed_order([r.l1 for r in sel], [r.spacing for r in sel])
            parts.append(f"{mode.value} {p:.2f}")
    return ("Observed order of the L1 error in the spacing (least-squares slope of log L1 "
            f"against log dx): {', '.join(parts)}.") if parts else ""


def plot(path: Path, rows: list[cases.CaseResult]) -> Path | None:
    """Depth profiles of the default runs against the exact solution; None without
    matplotlib."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("figure skipped: matplotlib not installed")
        return None
    default = [r for r in rows if r.refinement == DEFAULT.value]
    fig, ax = plt.subplots(figsize=(8.0, 3.6))
    first = default[0].profile
    ax.plot(first.x, first.d_exact, "k-", lw=2.0, label="exact")
    for r in default:
        ax.plot(r.profile.x, r.profile.d, lw=1.0, label=f"{r.refinement}, dx = {r.spacing:g} m")
    if rows[0].case == "thacker":  # the wet disc and its surroundings
        wet = first.x[first.d_exact > 0]
        ax.set_xlim(wet.min() - 500.0, wet.max() + 500.0)
    ax.set_xlabel("x [m]" + (" along y = 0" if rows[0].case == "thacker" else ""))
    ax.set_ylabel("depth [m]")
    ax.set_title(f"{TITLES[rows[0].case]}, depth at the end time ({first.line})", fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def page(case: str, rows, machine: Machine, picture: Path | None, command: str) -> str:
    lines = [f"# {TITLES[case]}", "",
             f"Made by `{command}` on {time.strftime('%Y-%m-%d')} at commit "
             f"`{provenance.commit(REPO)}`; "
             f"{machine.note()}", "",
             "## Set-up", "", *setup_text(case), "",
             "## Error against the exact solution", "",
             f"Default refinement (`{DEFAULT.value}`) beside uniform resolution (refinement "
             "`none`), both with one global time step (scenarios default to local steps; "
             "[local time steps](../local_steps/speed_vs_error.md) has these cases with "
             "them). Solver wall time is the stepping loop only (the kernels compiled "
             "before).", "",
             table(rows), ""]
    order = order_text(rows)
    lines += [order, ""] if order else []
    if picture is not None:
        lines += [f"![depth profile against the exact solution]({picture.name})", ""]
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", required=True, choices=sorted(SPACINGS))
    ap.add_argument("--out", type=Path, default=REPO / "docs" / "validation")
    ap.add_argument("--quick", action="store_true", help="the coarsest spacing only")
    args = ap.parse_args(argv)
    argv = sys.argv[1:] if argv is None else argv
    args.out.mkdir(parents=True, exist_ok=True)
    rows, machine = run_case(args.case, args.quick)
    picture = plot(args.out / f"{args.case}.png", rows)
    command = " ".join(["NUMBA_NUM_THREADS=" + os.environ.get("NUMBA_NUM_THREADS", "(all)"),
                        "python benchmarks/validation_pages.py", *argv])
    path = args.out / f"{args.case}.md"
    path.write_text(page(args.case, rows, machine, picture, command))
    print(f"page: {path}")


if __name__ == "__main__":
    main()
