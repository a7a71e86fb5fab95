"""Peer runs of ``benchmarks/pareto.py``: GeoClaw and ANUGA on one analytic case, in their venv.

``pareto.py`` never imports clawpack or anuga: it runs this script with the peers' Python
interpreter (``--peer-python``), one process per run, and reads back JSON. The script needs
only NumPy and the peer package; it does not import floodsph.

* ``python pareto_peers.py check [--claw DIR]`` prints, as JSON, for each peer whether it can
  run here (its version) or why not.
* ``python pareto_peers.py run JOB.json`` runs one job and writes ``result.json`` into the
  job's ``folder``: the depth [m] at the job's sample points at the final time (the value of
  the cell or triangle holding each point), the solver's seconds (the time loop only: no
  imports, mesh or data set-up, compilation or output), its steps and its cell count.

A job is ``{"code": "geoclaw" | "anuga", "case": {...}, "resolution": dx [m], "threads": n,
"gravity": g, "points": [[x...], [y...]], "folder": DIR, "work": DIR, "claw": DIR | null}``;
the case is a dam break (``kind`` ``dam_break``: ``x_dam``, ``d_left``, ``d_right``) or
Thacker's planar oscillation (``kind`` ``thacker``: ``h0``, ``a``, ``eta``), with ``x_range``,
``y_range`` and ``t_end``, flat and frictionless, walls all round.

GeoClaw (clawpack 5.x): one uniform level (``amr_levels_max`` = 1) of square cells, wall
boundaries, second order with the MC limiter and transverse corrections, f-waves, CFL 0.9,
dry tolerance 1 mm (as GeoClaw's ``tests/bowl_slosh``), bed from a topography file (type 3)
at half the cell size, initial state from the ``qinit`` below (its parameters are read from a
data file, so one build serves every case). The executable is built once with ``make .exe``
into ``work`` (cached by the hash of its sources; clawpack's make leaves its library objects
beside the Fortran sources) from GeoClaw's Fortran in the clawpack source tree: ``--claw``,
else ``$CLAW``, else ``<peer venv>/src/clawpack-<version>`` (the unpacked PyPI sdist: pip
installs only the Python part). Solver time = the level-1 integration wall time (stepgrid,
boundary conditions and their overhead) of GeoClaw's ``timing.csv``; steps = level-1 cell
updates / cells.

ANUGA (4.x): ``rectangular_cross_domain`` (four triangles per square of side ``resolution``),
its default flow algorithm, reflective boundaries, bed from the case's function at the
vertices, initial depth and momentum at the centroids; solver time = ``domain.evolve``.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

QINIT_F90 = """\
! Initial state of benchmarks/pareto.py's cases, read from pareto_qinit.data in the run folder:
! kind 1 = dam break (x_dam, d_left, d_right), kind 2 = Thacker's planar oscillation at t = 0
! (h0, a, eta: level h0 + 2 eta h0/a (x/a - eta/(2a)), u = 0, v = -eta omega).
subroutine qinit(meqn, mbc, mx, my, xlower, ylower, dx, dy, q, maux, aux)
    use geoclaw_module, only: grav
    implicit none
    integer, intent(in) :: meqn, mbc, mx, my, maux
    real(kind=8), intent(in) :: xlower, ylower, dx, dy
    real(kind=8), intent(inout) :: q(meqn, 1-mbc:mx+mbc, 1-mbc:my+mbc)
    real(kind=8), intent(inout) :: aux(maux, 1-mbc:mx+mbc, 1-mbc:my+mbc)
    integer :: kind, i, j
    real(kind=8) :: p(3), x, y, omega, level

    open(unit=77, file='pareto_qinit.data', status='old', action='read')
    read(77, *) kind
    read(77, *) p
    close(77)
    omega = 0.d0
    if (kind == 2) omega = sqrt(2.d0 * grav * p(1)) / p(2)
    do j = 1-mbc, my+mbc
        y = ylower + (j - 0.5d0) * dy
        do i = 1-mbc, mx+mbc
            x = xlower + (i - 0.5d0) * dx
            q(2, i, j) = 0.d0
            if (kind == 1) then
                q(1, i, j) = merge(p(2), p(3), x < p(1))
                q(3, i, j) = 0.d0
            else
                level = p(1) + 2.d0 * p(3) * p(1) / p(2) * (x / p(2) - p(3) / (2.d0 * p(2)))
                q(1, i, j) = max(0.d0, level - aux(1, i, j))
                q(3, i, j) = -p(3) * omega * q(1, i, j)
            end if
        end do
    end do
end subroutine qinit
"""

MAKEFILE = """\
CLAWMAKE = $(CLAW)/clawutil/src/Makefile.common
CLAW_PKG = geoclaw
EXE = xgeoclaw
OUTDIR = _output
GEOLIB = $(CLAW)/geoclaw/src/2d/shallow
include $(GEOLIB)/Makefile.geoclaw
MODULES =
SOURCES = qinit.f90 \\
  $(CLAW)/riemann/src/rpn2_geoclaw.f \\
  $(CLAW)/riemann/src/rpt2_geoclaw.f \\
  $(CLAW)/riemann/src/geoclaw_riemann_utils.f
include $(CLAWMAKE)
"""

GEOCLAW_FFLAGS = "-O2 -fopenmp"
DRY_TOLERANCE_M = 1e-3


# -- the cases: bed, initial state -----------------------------------------------------------
def bed(case: dict, x, y):
    """Bed elevation [m]: flat for a dam break, Thacker's paraboloid h0 r^2 / a^2."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if case["kind"] == "dam_break":
        return np.zeros(np.broadcast(x, y).shape)
    return case["h0"] * (x**2 + y**2) / case["a"] ** 2


def initial_state(case: dict, x, y, b, gravity: float):
    """Depth [m] and velocity [m/s] at t = 0 at points (x, y) over bed ``b``."""
    x = np.asarray(x, dtype=float)
    if case["kind"] == "dam_break":
        d = np.where(x < case["x_dam"], case["d_left"], case["d_right"])
        return d, np.zeros_like(d), np.zeros_like(d)
    h0, a, eta = case["h0"], case["a"], case["eta"]
    level = h0 + 2.0 * eta * h0 / a * (x / a - eta / (2.0 * a))
    d = np.maximum(level - b, 0.0)
    omega = math.sqrt(2.0 * gravity * h0) / a
    return d, np.zeros_like(d), np.where(d > 0.0, -eta * omega, 0.0)


def grid_shape(job: dict) -> tuple[int, int]:
    """(ny, nx) square cells of side ``resolution`` covering the case's rectangle exactly."""
    (x0, x1), (y0, y1) = job["case"]["x_range"], job["case"]["y_range"]
    shape = round((y1 - y0) / job["resolution"]), round((x1 - x0) / job["resolution"])
    if not np.allclose(np.multiply(shape, job["resolution"]), (y1 - y0, x1 - x0)):
        raise ValueError(f"cells of {job['resolution']:g} m do not tile the {x1 - x0:g} m x "
                         f"{y1 - y0:g} m domain")
    return shape


def cell_of(job: dict, x, y) -> tuple[np.ndarray, np.ndarray]:
    """Row and column of the square cell holding each point (points on the outer edge go to the
    last cell)."""
    ny, nx = grid_shape(job)
    dx = job["resolution"]
    j = np.floor((np.asarray(x) - job["case"]["x_range"][0]) / dx).astype(np.int64)
    i = np.floor((np.asarray(y) - job["case"]["y_range"][0]) / dx).astype(np.int64)
    return np.clip(i, 0, ny - 1), np.clip(j, 0, nx - 1)


# -- GeoClaw ---------------------------------------------------------------------------------
def claw_sources(claw: str | None) -> Path:
    """The clawpack source tree holding GeoClaw's Fortran (see the module docstring)."""
    import clawpack

    candidates = [claw, os.environ.get("CLAW"),
                  Path(sys.prefix) / "src" / f"clawpack-{clawpack.__version__}"]
    for c in candidates:
        if c and (Path(c) / "geoclaw" / "src" / "2d" / "shallow" / "Makefile.geoclaw").exists():
            return Path(c).resolve()
    raise FileNotFoundError("GeoClaw's Fortran sources not found: unpack the clawpack sdist "
                            "(pip download --no-deps clawpack==<version>) into <peer venv>/src "
                            "or pass --claw / set CLAW")


def geoclaw_status(claw: str | None) -> dict:
    try:
        import clawpack.clawutil.data  # noqa: F401
        import clawpack.geoclaw.topotools  # noqa: F401
        from clawpack import __version__
    except ImportError as err:
        return {"ok": False, "why": f"clawpack not importable ({err})"}
    try:
        source = claw_sources(claw)
    except FileNotFoundError as err:
        return {"ok": False, "why": str(err)}
    compiler = os.environ.get("FC", "gfortran")
    if shutil.which(compiler) is None:
        return {"ok": False, "why": f"no Fortran compiler {compiler!r} (apt-get install gfortran)"}
    return {"ok": True, "version": __version__, "claw": str(source)}


def geoclaw_executable(work: Path, claw: Path) -> Path:
    """``xgeoclaw`` built with ``make .exe`` in a cache folder named by the sources' hash."""
    key = hashlib.sha256((QINIT_F90 + MAKEFILE + GEOCLAW_FFLAGS + str(claw)).encode())
    folder = work / f"geoclaw-build-{key.hexdigest()[:12]}"
    exe = folder / "xgeoclaw"
    if exe.exists():
        return exe
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "qinit.f90").write_text(QINIT_F90)
    (folder / "Makefile").write_text(MAKEFILE)
    env = dict(os.environ, CLAW=str(claw), FC=os.environ.get("FC", "gfortran"),
               FFLAGS=GEOCLAW_FFLAGS, CLAW_PYTHON=sys.executable)
    print(f"building GeoClaw in {folder}", file=sys.stderr, flush=True)
    done = subprocess.run(["make", ".exe"], cwd=folder, env=env, capture_output=True, text=True)
    if done.returncode != 0 or not exe.exists():
        raise RuntimeError(f"make .exe failed in {folder}:\n{done.stdout[-2000:]}"
                           f"\n{done.stderr[-2000:]}")
    return exe


def write_topography(job: dict, path: Path) -> None:
    """The bed as a type-3 topography file at half the cell size, two cells beyond the
    domain."""
    from clawpack.geoclaw.topotools import Topography

    (x0, x1), (y0, y1) = job["case"]["x_range"], job["case"]["y_range"]
    step, margin = 0.5 * job["resolution"], 2.0 * job["resolution"]
    topo = Topography()
    topo.x = np.arange(x0 - margin, x1 + margin + 0.5 * step, step)
    topo.y = np.arange(y0 - margin, y1 + margin + 0.5 * step, step)
    X, Y = np.meshgrid(topo.x, topo.y)
    topo.Z = bed(job["case"], X, Y)
    topo.write(str(path), topo_type=3)


def geoclaw_rundata(job: dict):
    """GeoClaw's run data for one uniform level (see the module docstring)."""
    from clawpack.clawutil.data import ClawRunData

    case = job["case"]
    ny, nx = grid_shape(job)
    rd = ClawRunData("geoclaw", 2)
    cd = rd.clawdata
    cd.lower[:] = [case["x_range"][0], case["y_range"][0]]
    cd.upper[:] = [case["x_range"][1], case["y_range"][1]]
    cd.num_cells[:] = [nx, ny]
    cd.num_eqn, cd.num_aux, cd.capa_index = 3, 1, 0
    cd.t0, cd.output_style, cd.num_output_times = 0.0, 1, 1
    cd.tfinal, cd.output_t0, cd.output_format = case["t_end"], False, "ascii"
    cd.output_q_components, cd.output_aux_components = "all", "none"
    cd.verbosity = 0
    cd.dt_variable, cd.dt_initial, cd.dt_max = True, 1e-3, 1e99
    cd.cfl_desired, cd.cfl_max, cd.steps_max = 0.9, 1.0, 10**7
    cd.order, cd.dimensional_split, cd.transverse_waves = 2, "unsplit", 2
    cd.num_waves, cd.limiter, cd.use_fwaves = 3, ["mc", "mc", "mc"], True
    cd.source_split = "godunov"
    cd.num_ghost = 2
    cd.bc_lower[:] = ["wall", "wall"]
    cd.bc_upper[:] = ["wall", "wall"]
    cd.checkpt_style = 0
    amr = rd.amrdata
    amr.amr_levels_max = 1
    amr.refinement_ratios_x, amr.refinement_ratios_y, amr.refinement_ratios_t = [2], [2], [2]
    amr.aux_type = ["center"]
    amr.flag_richardson, amr.flag2refine = False, False
    geo = rd.geo_data
    geo.gravity, geo.coordinate_system, geo.coriolis_forcing = job["gravity"], 1, False
    geo.sea_level, geo.dry_tolerance = 0.0, DRY_TOLERANCE_M
    geo.friction_forcing, geo.manning_coefficient = False, 0.0
    rd.topo_data.topofiles.append([3, "bed.tt3"])
    rd.qinit_data.qinit_type = 0
    return rd


def qinit_parameters(case: dict) -> str:
    if case["kind"] == "dam_break":
        return f"1\n{case['x_dam']!r} {case['d_left']!r} {case['d_right']!r}\n"
    return f"2\n{case['h0']!r} {case['a']!r} {case['eta']!r}\n"


def geoclaw_timing(path: Path) -> tuple[float, float]:
    """(level-1 integration wall time [s], level-1 cell updates) at the last output time, from
    GeoClaw's timing.csv (six digits; timing.txt rounds to 1 ms)."""
    last = path.read_text().strip().splitlines()[-1].split(",")
    return float(last[3]), float(last[5])


def geoclaw_depth(folder: Path, job: dict) -> np.ndarray:
    """The final depth on the (ny, nx) grid, assembled from the output patches."""
    from clawpack.pyclaw.solution import Solution

    sol = Solution(1, path=str(folder), file_format="ascii")
    depth = np.full(grid_shape(job), np.nan)
    x0, y0 = job["case"]["x_range"][0], job["case"]["y_range"][0]
    for state in sol.states:
        dims = state.patch.dimensions
        j0 = round((dims[0].lower - x0) / job["resolution"])
        i0 = round((dims[1].lower - y0) / job["resolution"])
        h = state.q[0]  # (mx, my)
        depth[i0:i0 + h.shape[1], j0:j0 + h.shape[0]] = h.T
    if np.isnan(depth).any():
        raise ValueError("GeoClaw's output does not cover the grid")
    return depth


def run_geoclaw(job: dict) -> dict:
    from clawpack import __version__

    folder = Path(job["folder"])
    exe = geoclaw_executable(Path(job["work"]), claw_sources(job.get("claw")))
    geoclaw_rundata(job).write(out_dir=str(folder))
    write_topography(job, folder / "bed.tt3")
    (folder / "pareto_qinit.data").write_text(qinit_parameters(job["case"]))
    env = dict(os.environ, OMP_NUM_THREADS=str(job["threads"]))
    with open(folder / "xgeoclaw.log", "w") as log:
        subprocess.run([str(exe)], cwd=folder, env=env, stdout=log, stderr=subprocess.STDOUT,
                       check=True)
    solver_s, updates = geoclaw_timing(folder / "timing.csv")
    depth = geoclaw_depth(folder, job)
    i, j = cell_of(job, *job["points"])
    ny, nx = depth.shape
    return {"version": __version__, "solver_s": solver_s,
            "steps": round(updates / (nx * ny)), "cells": nx * ny,
            "depth": depth[i, j].tolist()}


# -- ANUGA -----------------------------------------------------------------------------------
def anuga_status() -> dict:
    try:
        import anuga
    except ImportError as err:
        return {"ok": False, "why": f"anuga not importable ({err})"}
    return {"ok": True, "version": anuga.__version__}


def cross_quarter(job: dict, x, y) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Row, column and quarter (0 right, 1 top, 2 left, 3 bottom) of the triangle of the cross
    mesh holding each point: the quarter is cut by the square's diagonals."""
    i, j = cell_of(job, x, y)
    dx = job["resolution"]
    u = np.asarray(x) - (job["case"]["x_range"][0] + (j + 0.5) * dx)
    v = np.asarray(y) - (job["case"]["y_range"][0] + (i + 0.5) * dx)
    quarter = np.where(np.abs(u) >= np.abs(v), np.where(u >= 0, 0, 2), np.where(v >= 0, 1, 3))
    return i, j, quarter


def triangles_holding(job: dict, centroids: np.ndarray, x, y) -> np.ndarray:
    """Index of the triangle holding each point (x, y), from the triangles' centroids."""
    table = np.full((*grid_shape(job), 4), -1, dtype=np.int64)
    table[cross_quarter(job, centroids[:, 0], centroids[:, 1])] = np.arange(len(centroids))
    if (table < 0).any():
        raise ValueError("the mesh is not a cross mesh of the job's squares")
    return table[cross_quarter(job, x, y)]


def run_anuga(job: dict) -> dict:
    import anuga

    case, folder = job["case"], Path(job["folder"])
    (x0, x1), (y0, y1) = case["x_range"], case["y_range"]
    ny, nx = grid_shape(job)
    anuga.set_omp_num_threads(job["threads"], verbose=False)
    domain = anuga.rectangular_cross_domain(nx, ny, x1 - x0, y1 - y0, origin=(x0, y0))
    domain.set_name("anuga")
    domain.set_datadir(str(folder))
    domain.set_store(False)
    domain.g = job["gravity"]
    domain.set_quantity("elevation", lambda x, y: bed(case, x, y))
    xy = domain.centroid_coordinates
    b = domain.quantities["elevation"].centroid_values.copy()
    d, u, v = initial_state(case, xy[:, 0], xy[:, 1], b, job["gravity"])
    domain.set_quantity("stage", b + d, location="centroids")
    domain.set_quantity("xmomentum", d * u, location="centroids")
    domain.set_quantity("ymomentum", d * v, location="centroids")
    wall = anuga.Reflective_boundary(domain)
    domain.set_boundary({tag: wall for tag in ("left", "right", "top", "bottom")})
    steps, start = 0, time.perf_counter()
    for _ in domain.evolve(yieldstep=case["t_end"], finaltime=case["t_end"]):
        steps += domain.number_of_steps
    solver_s = time.perf_counter() - start
    depth = np.maximum(domain.quantities["stage"].centroid_values - b, 0.0)
    tri = triangles_holding(job, xy, *job["points"])
    return {"version": anuga.__version__, "solver_s": solver_s, "steps": steps,
            "cells": len(b), "flow_algorithm": domain.get_flow_algorithm(),
            "depth": depth[tri].tolist()}


# -- command line ----------------------------------------------------------------------------
RUNNERS = {"geoclaw": run_geoclaw, "anuga": run_anuga}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    check = sub.add_parser("check", help="print which peers can run, as JSON")
    check.add_argument("--claw", default=None, help="clawpack source tree (GeoClaw's Fortran)")
    run = sub.add_parser("run", help="run one job and write result.json into its folder")
    run.add_argument("job", type=Path)
    args = ap.parse_args(argv)
    if args.command == "check":
        print(json.dumps({"geoclaw": geoclaw_status(args.claw), "anuga": anuga_status()}))
        return 0
    job = json.loads(args.job.read_text())
    Path(job["folder"]).mkdir(parents=True, exist_ok=True)
    result = RUNNERS[job["code"]](job) | {"threads": job["threads"]}
    (Path(job["folder"]) / "result.json").write_text(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
