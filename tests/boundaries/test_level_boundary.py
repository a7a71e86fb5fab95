"""Level boundaries (``floodsph.boundaries.level``): the water level imposed on a section.

Physical facts asserted: the boundary state keeps the outgoing Riemann invariant; water at
rest at the imposed level stays at rest; a raised level fills a basin to it; every volume
that crosses the section is counted, so the volume balance closes to round-off while the
level rises and falls; the level series is read and refused as documented.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from sph_cases import lattice, particles_with_depth, run_until

from floodsph.boundaries import LevelBoundary
from floodsph.boundaries.riemann import level_state
from floodsph.checks.levels import SIDE_NORMALS, check_level_boundaries, level_section, side_line
from floodsph.constants import GRAVITY
from floodsph.errors import InputError
from floodsph.io.level_series import LevelSeries, read_level_series
from floodsph.model.builder import set_up_model
from floodsph.model.terrain import Terrain
from floodsph.scenario.config import LevelBoundary as LevelEntry
from floodsph.scenario.numerics import Momentum, Numerics

KAPPA = Numerics.kappa
DX = 2.0


# -- the boundary state --------------------------------------------------------------------------
def test_subcritical_state_imposes_the_level_and_keeps_the_outgoing_invariant():
    d_0 = np.array([1.5, 1.0, 2.0])
    d_i = np.array([1.0, 1.0, 2.2])
    w_i = np.array([0.1, 0.0, -0.3])
    d_b, w_b = level_state(d_0, d_i, w_i)
    assert d_b == pytest.approx(d_0)
    invariant = w_i - 2.0 * np.sqrt(GRAVITY * d_i)
    assert w_b - 2.0 * np.sqrt(GRAVITY * d_b) == pytest.approx(invariant, rel=1e-12)
    assert w_b[0] > 0.0 and w_b[1] == 0.0 and w_b[2] < 0.0  # in where higher, out where lower


def test_dry_interior_takes_the_critical_dam_break_state_and_a_dry_boundary_none():
    d_b, w_b = level_state(np.array([0.9, 0.0]), np.array([0.0, 0.5]), np.array([0.0, -0.2]))
    assert d_b[0] == pytest.approx(0.4)  # 4/9 d_0 (Ritter at the dam)
    assert w_b[0] == pytest.approx(math.sqrt(GRAVITY * d_b[0]))  # Froude number 1
    assert (d_b[1], w_b[1]) == (0.0, 0.0)


# -- the level series ----------------------------------------------------------------------------
def test_level_series_is_linear_between_rows_and_held_beyond_them(tmp_path):
    path = tmp_path / "tide.csv"
    path.write_text("level_m,time_s,note\n1.0,0,low\n2.0,100,high\n\n1.5,300,\n")
    series = read_level_series(path, "level_boundaries[0].file")
    assert series.at(50.0) == pytest.approx(1.5)
    assert series.at(200.0) == pytest.approx(1.75)
    assert series.at(-10.0) == 1.0 and series.at(1e6) == 1.5
    assert LevelSeries.constant(3.0).at(1e3) == 3.0


@pytest.mark.parametrize("text, match", [
    ("time_s,level_m\n0,1\n10,1.2\n10,1.3\n", r"line 4: time_s = 10 does not follow 10"),
    ("time_s,stage\n0,1\n", r"missing column 'level_m'"),
    ("time_s,level_m\n", r"no rows"),
    ("time_s,level_m\n0,1\nten,2\n", r"line 3: time_s = 'ten' is not a number"),
])
def test_level_series_refuses_bad_files(tmp_path, text, match):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(InputError, match=r"level_boundaries\[1\]\.file: .*" + match):
        read_level_series(path, "level_boundaries[1].file")


# -- sections ------------------------------------------------------------------------------------
def _flat(width, height, manning=0.03):
    return Terrain.from_function(lambda x, y: 0 * x, (0, width), (0, height), DX,
                                 manning=manning)


def test_a_line_off_the_dem_is_refused_and_a_border_line_faces_the_dem():
    terrain = _flat(40, 10)
    off = LevelEntry(name="sea", line=((40.0, 0.0), (41.0, 10.0)))
    with pytest.raises(InputError, match=r"level_boundaries\[0\]\.line: the point \[41.0, "
                                         r"10.0\] lies off the DEM"):
        level_section(off, terrain, DX, "level_boundaries[0]")
    border = LevelEntry(name="sea", line=((40.0, 0.0), (40.0, 10.0)))
    _, normal = level_section(border, terrain, DX, "level_boundaries[0]")
    assert normal == pytest.approx([-1.0, 0.0])


def test_a_level_beyond_any_water_surface_is_refused():
    class Entries:
        level_boundaries = (LevelEntry(name="sea", side="east", file=Path("tide.csv")),)

    with pytest.raises(InputError, match=r"level_boundaries\[0\]\.file: tide\.csv: level_m = "
                                         r"20000 m \(at time_s = 5\) is beyond"):
        check_level_boundaries(Entries, _flat(40, 10), [LevelSeries([0.0, 5.0], [1.0, 2e4])],
                               DX, "s.toml", None)


def test_a_level_below_the_bed_all_along_is_warned_of():
    class Entries:
        level_boundaries = (LevelEntry(name="river", side="west"),)

    terrain = Terrain.from_function(lambda x, y: 5.0 + 0 * x, (0, 40), (0, 10), DX)
    warnings: list[str] = []
    check_level_boundaries(Entries, terrain, [LevelSeries([0.0, 9.0], [4.0, 4.5])], DX,
                           "s.toml", warnings)
    assert len(warnings) == 1 and "level_boundaries[0] (river)" in warnings[0]
    assert "4.5 m, is at or below the bed" in warnings[0]
    check_level_boundaries(Entries, terrain, [LevelSeries([0.0, 9.0], [4.0, 5.5])], DX,
                           "s.toml", warnings)
    assert len(warnings) == 1


# -- a basin open at its east side ---------------------------------------------------------------
def basin(series, width=40.0, height=10.0, depth=1.0, manning=0.03, momentum="variational"):
    """A flat basin, closed but for its east side where ``series`` is imposed."""
    terrain = _flat(width, height, manning)
    x, y = lattice(0, width, 0, height, DX)
    particles = particles_with_depth(x, y, np.full(x.shape, depth), DX, KAPPA)
    boundary = LevelBoundary(side_line("east", width, height), SIDE_NORMALS["east"], series,
                             DX, KAPPA, terrain, name="sea")
    model = set_up_model(terrain, particles,
                         Numerics(particle_spacing_m=DX, momentum=Momentum(momentum)),
                         closed_sides=("west", "south", "north"), level_sides=("east",),
                         boundaries=[boundary])
    return model, boundary


@pytest.mark.parametrize("momentum", ["variational", "balanced"])
def test_water_at_rest_at_the_boundary_level_stays_at_rest(momentum):
    model, boundary = basin(LevelSeries.constant(1.0), momentum=momentum)
    v0 = model.volume()
    run_until(model, 60.0)
    p = model.particles
    assert np.hypot(p.u, p.v).max() < 1e-3
    assert model.volume() == pytest.approx(v0, rel=1e-12)
    assert boundary.volume_in == boundary.volume_out == 0.0


def test_volume_balance_closes_while_the_level_rises_and_falls():
    """1 m -> 1.3 m in 60 s, then down to 0.6 m by 180 s: water enters, then leaves; the
    initial volume plus what entered less what left is the final volume to round-off, and
    the basin's mean level follows the boundary's within the seiche the change excites."""
    model, boundary = basin(LevelSeries([0.0, 60.0, 180.0], [1.0, 1.3, 0.6]))
    v0 = model.volume()
    for t in (30.0, 60.0, 120.0, 180.0, 200.0):
        run_until(model, t)
        balance = v0 + model.state.volume_in - model.state.volume_out - model.volume()
        assert abs(balance) <= 1e-12 * v0, t
        assert model.volume() / (40.0 * 10.0) == pytest.approx(boundary.level, abs=0.1), t
    assert boundary.volume_in > 0.25 * v0 and boundary.volume_out > 0.6 * v0
    assert ((model.state.volume_in, model.state.volume_out)
            == (boundary.volume_in, boundary.volume_out))


def test_a_level_raised_half_a_metre_fills_the_basin_to_it():
    """1 m -> 1.5 m over 200 s, slow against the basin's quarter-wave seiche (4 L / c, about
    40 s): from 220 s to 300 s the mean level of the basin (its volume over its area) stays
    within 5 cm of 1.5 m (a particle that enters or leaves moves it by 1.5 cm) and averages
    within 1.5 cm of it; the level at the closed far end, which a seiche of about 10 cm
    still moves, averages within 3 cm of it."""
    model, _ = basin(LevelSeries([0.0, 200.0], [1.0, 1.5]), manning=0.05)
    mean, far = [], []
    for t in np.arange(220.0, 301.0, 5.0):
        run_until(model, t)
        p = model.particles
        mean.append(model.volume() / (40.0 * 10.0))
        far.append(model.depth()[p.x < 2.0 * DX].mean())
    assert np.abs(np.array(mean) - 1.5).max() < 0.05
    assert abs(np.mean(mean) - 1.5) < 0.015
    assert abs(np.mean(far) - 1.5) < 0.03
