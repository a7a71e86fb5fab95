"""Parametric breach: regressions, level-pool routing volume balance, parameters, CLI."""

import math

import numpy as np
import pytest
from click.testing import CliRunner

from floodsph.breach import (
    BreachParams,
    breach_hydrograph,
    froehlich1995_peak,
    froehlich2008_average_width,
    froehlich2008_formation_time,
    load_breach_params,
    macdonald1984_peak,
)
from floodsph.breach.storage import Storage, read_storage_table
from floodsph.cli.breach import command
from floodsph.errors import InputError
from floodsph.io.hydrograph import Hydrograph, read_hydrograph

# Documented example: V_w = 1e7 m3, h_b = h_w = 20 m (SI), g = 9.81 m/s2.
V_W, H_B = 1.0e7, 20.0


def test_froehlich2008_width_and_time_match_the_formulas():
    # B_avg = 0.27 k0 V^0.32 h^0.04 written in log form; t_f = 63.2 sqrt(V / (g h^2)).
    expected_width = 0.27 * 1.3 * math.exp(0.32 * math.log(V_W) + 0.04 * math.log(H_B))
    assert froehlich2008_average_width(V_W, H_B, "overtopping") == pytest.approx(
        expected_width, rel=1e-9)
    assert froehlich2008_average_width(V_W, H_B, "piping") == pytest.approx(
        expected_width / 1.3, rel=1e-9)
    assert froehlich2008_formation_time(V_W, H_B) == pytest.approx(
        63.2 * (V_W / 9.81) ** 0.5 / H_B, rel=1e-9)
    # By hand (4 digits): 10^(0.32*7) = 173.78, 20^0.04 = 1.1273 -> 0.351*173.78*1.1273 = 68.76 m;
    # sqrt(1e7 / 3924) = 50.48 -> t_f = 3190 s.
    assert froehlich2008_average_width(V_W, H_B, "overtopping") == pytest.approx(68.76, rel=1e-3)
    assert froehlich2008_formation_time(V_W, H_B) == pytest.approx(3190.5, rel=1e-3)


def test_peak_regressions_match_the_formulas():
    assert froehlich1995_peak(V_W, H_B) == pytest.approx(
        0.607 * math.exp(0.295 * math.log(V_W) + 1.24 * math.log(H_B)), rel=1e-9)
    assert macdonald1984_peak(V_W, H_B) == pytest.approx(
        1.154 * math.exp(0.412 * math.log(V_W * H_B)), rel=1e-9)
    # By hand: 0.607 * 116.1 * 41.06 = 2894 m3/s; 1.154 * (2e8)^0.412 = 1.154 * 2630 = 3035 m3/s.
    assert froehlich1995_peak(V_W, H_B) == pytest.approx(2894.0, rel=1e-3)
    assert macdonald1984_peak(V_W, H_B) == pytest.approx(3035.5, rel=1e-3)


@pytest.mark.parametrize(("mode", "slope"), [("overtopping", 1.0), ("piping", 0.7)])
def test_breach_geometry_in_summary(mode, slope):
    _, _, s = breach_hydrograph(BreachParams.from_mapping(
        {"reservoir_volume_m3": V_W, "breach_height_m": H_B, "mode": mode}))
    assert s.side_slope == slope
    # Average width of the trapezoid = bottom width + z h_b.
    assert s.bottom_width_m + slope * H_B == pytest.approx(s.average_width_m, rel=1e-12)
    assert s.average_width_m == pytest.approx(
        froehlich2008_average_width(V_W, H_B, mode), rel=1e-12)


def test_full_breach_on_a_huge_reservoir_follows_the_weir_equation():
    # Level stays ~constant (A = 1e12 m2), so after t_f: Q = C (b y^1.5 + (2.45/3.1) z y^2.5).
    h, width, c = 10.0, 50.0, 1.7
    params = BreachParams.from_mapping({
        "reservoir_area_m2": 1e12, "breach_height_m": h, "average_width_m": width,
        "formation_time_s": 600.0, "duration_s": 900.0, "dt_s": 5.0, "weir_coefficient": c})
    t, Q, s = breach_hydrograph(params)
    b = width - 1.0 * h
    expected = c * (b * h**1.5 + 2.45 / 3.1 * 1.0 * h**2.5)
    assert Q[-1] == pytest.approx(expected, rel=1e-4)
    assert Q[0] == 0.0  # breach not yet open at t = 0 with the level at the crest


def _balance(params, initial):
    t, Q, s = breach_hydrograph(params)
    assert np.all(Q >= 0.0)
    released = Hydrograph(t, Q).total_volume()
    assert released == pytest.approx(s.released_volume_m3, rel=1e-12)
    assert s.initial_storage_m3 == pytest.approx(initial, rel=1e-12)
    assert abs(initial - released - s.remaining_storage_m3) < 1e-3 * initial
    return t, Q, s


def test_volume_balance_constant_area():
    area = 2.0e5
    params = BreachParams.from_mapping({
        "reservoir_area_m2": area, "breach_height_m": 15.0, "breach_invert_m": 230.0})
    t, Q, s = _balance(params, area * 15.0)
    # Remaining storage from the final level, independently of the routing bookkeeping.
    assert s.remaining_storage_m3 == pytest.approx(area * (s.final_level_m - 230.0), rel=1e-9)
    assert s.released_volume_m3 > 0.99 * area * 15.0


@pytest.mark.parametrize("column", ["area_m2", "volume_m3"])
def test_volume_balance_storage_table(tmp_path, column):
    # Area grows linearly 1e5 -> 5e5 m2 from 100 m to 120 m: 6e6 m3 above the invert at 100 m.
    z = np.linspace(95.0, 125.0, 7)
    area = 1e5 + 2e4 * (z - 100.0)
    volume = 1e5 * (z - 95.0) + 1e4 * ((z - 100.0) ** 2 - 25.0)  # exact integral of the area
    values = area if column == "area_m2" else volume
    rows = "\n".join(f"{a},{b}" for a, b in zip(z, values, strict=True))
    (tmp_path / "storage.csv").write_text(f"elevation_m,{column}\n{rows}\n")
    params = BreachParams.from_mapping(
        {"storage_table": "storage.csv", "breach_height_m": 20.0, "breach_invert_m": 100.0,
         "initial_level_m": 120.0, "mode": "piping"}, base_dir=tmp_path)
    # The volume table interpolates linearly between 5 m steps; at the nodes it is exact.
    _balance(params, 6.0e6)


def test_area_table_level_inverts_volume(tmp_path):
    (tmp_path / "s.csv").write_text("elevation_m,area_m2\n0,0\n4,400\n10,1000\n")
    storage = read_storage_table(tmp_path / "s.csv", "breach.storage_table")
    # A = 100 z on [0, 10]: V = 50 z^2.
    for level in (0.5, 3.0, 4.0, 7.5, 10.0):
        assert storage.volume(level) == pytest.approx(50.0 * level**2, rel=1e-12)
        assert storage.level(50.0 * level**2) == pytest.approx(level, rel=1e-12)
    assert Storage.constant_area(10.0, 2.0).level(30.0) == pytest.approx(5.0, rel=1e-15)


def test_sine_progression_peaks_differently_but_releases_the_same_volume():
    base = {"reservoir_volume_m3": V_W, "breach_height_m": H_B, "duration_s": 60000.0}
    _, _, linear = breach_hydrograph(BreachParams.from_mapping(base))
    _, _, sine = breach_hydrograph(BreachParams.from_mapping({**base, "progression": "sine"}))
    difference = abs(sine.peak_discharge_m3s - linear.peak_discharge_m3s)
    assert difference > 0.02 * linear.peak_discharge_m3s
    assert sine.time_to_peak_s != pytest.approx(linear.time_to_peak_s, rel=0.05)
    assert sine.released_volume_m3 == pytest.approx(linear.released_volume_m3, rel=1e-3)
    assert linear.released_volume_m3 > 0.99 * V_W


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ({"reservoir_volume_m3": -1.0, "breach_height_m": 20.0},
         "inflows[0].breach.reservoir_volume_m3: must be > 0, got -1"),
        ({"reservoir_volume_m3": 1e6},
         "inflows[0].breach.breach_height_m: required key missing"),
        ({"reservoir_volume_m3": 1e6, "breach_height_m": 20.0, "mode": "collapse"},
         "inflows[0].breach.mode: 'collapse' is not one of 'overtopping', 'piping'"),
        ({"reservoir_volume_m3": 1e6, "breach_height_m": "20"},
         "inflows[0].breach.breach_height_m: expected a number, got '20'"),
        ({"reservoir_volume_m3": 1e6, "breach_height_m": 20.0, "head_m": 5.0,
          "initial_level_m": 5.0},
         "inflows[0].breach: give head_m or initial_level_m, not both"),
    ],
)
def test_parameter_errors_name_the_key(table, message):
    with pytest.raises(InputError) as err:
        BreachParams.from_mapping(table, key="inflows[0].breach")
    assert str(err.value) == message


def test_unknown_key_and_inconsistent_volume():
    with pytest.raises(InputError, match=r"^inflows\[1\]\.breach\.volume: unknown key"):
        BreachParams.from_mapping({"volume": 1.0}, key="inflows[1].breach")
    params = BreachParams.from_mapping(
        {"reservoir_volume_m3": 2e6, "reservoir_area_m2": 1e5, "breach_height_m": 10.0})
    with pytest.raises(InputError, match=r"^breach\.reservoir_volume_m3: 2e\+06 m3 disagrees "
                                         r"with the 1e\+06 m3 that reservoir_area_m2 holds"):
        breach_hydrograph(params)


def test_storage_table_error_names_file_and_line(tmp_path):
    path = tmp_path / "s.csv"
    path.write_text("elevation_m,volume_m3\n0,0\n5,100\n4,200\n")
    params = BreachParams.from_mapping(
        {"storage_table": "s.csv", "breach_height_m": 4.0}, base_dir=tmp_path)
    with pytest.raises(InputError) as err:
        breach_hydrograph(params)
    assert str(err.value) == (f"breach.storage_table: {path}, line 4: elevation_m = 4 is not "
                              "greater than the previous elevation 5")


def test_params_file_errors_name_the_file(tmp_path):
    path = tmp_path / "b.toml"
    path.write_text("[breach]\nreservoir_volume_m3 = 0\nbreach_height_m = 3\n")
    with pytest.raises(InputError) as err:
        load_breach_params(path)
    assert str(err.value) == f"{path}: breach.reservoir_volume_m3: must be > 0, got 0"


def test_cli_writes_a_readable_csv_with_the_released_volume(tmp_path):
    params_file = tmp_path / "b.toml"
    params_file.write_text('[breach]\nreservoir_volume_m3 = 2.0e6\nbreach_height_m = 12.0\n'
                           'progression = "sine"\n')
    out = tmp_path / "breach.csv"
    result = CliRunner().invoke(command, [str(params_file), "-o", str(out), "--mode", "piping"])
    assert result.exit_code == 0, result.output
    hydrograph = read_hydrograph(out)
    _, _, s = breach_hydrograph(load_breach_params(params_file, {"mode": "piping"}))
    assert hydrograph.total_volume() == pytest.approx(s.released_volume_m3, rel=1e-12)
    assert hydrograph.total_volume() == pytest.approx(2.0e6 - s.remaining_storage_m3, rel=1e-3)
    assert f"{s.macdonald1984_peak_m3s:.1f} m3/s" in result.output
    assert f"{s.froehlich1995_peak_m3s:.1f} m3/s" in result.output


def test_cli_bad_input_exits_2_with_one_message(tmp_path):
    result = CliRunner().invoke(command, ["--volume", "1e6", "--height", "-3",
                                          "-o", str(tmp_path / "x.csv")])
    assert result.exit_code == 2
    assert result.output == "Error: breach.breach_height_m: must be > 0, got -3\n"
    assert not (tmp_path / "x.csv").exists()


def test_no_outflow_before_initiation_even_when_overtopped():
    params = BreachParams.from_mapping({"reservoir_volume_m3": 1e6, "breach_height_m": 10.0,
                                        "head_m": 11.0, "start_time_s": 300.0})
    t, Q, s = _balance(params, 1e6)
    assert np.all(Q[t <= 300.0] == 0.0)
    assert Q[t > 300.0][0] > 0.0
    assert s.time_to_peak_s > 300.0


def test_routing_after_formation_follows_the_exact_level_time_relation():
    """Constant area A, the breach formed at t_f with bottom at the invert: the head y obeys
    A dy/dt = -C (b y^1.5 + k z y^2.5), so t - t_f = (A / C) int_y^{y_f} dh / (b h^1.5 + k z h^2.5),
    integrated here by quadrature, independently of the routing's ODE solver."""
    from scipy.integrate import quad
    from scipy.optimize import brentq

    from floodsph.breach.formulas import SIDE_TO_WEIR_RATIO, WEIR_COEFFICIENT

    area = 2.0e5
    t, Q, s = breach_hydrograph(BreachParams.from_mapping(
        {"reservoir_area_m2": area, "breach_height_m": 15.0, "breach_invert_m": 230.0}))
    b, k = s.bottom_width_m, SIDE_TO_WEIR_RATIO * s.side_slope

    def weir(y):
        return b * y**1.5 + k * y**2.5

    def head(q):
        return brentq(lambda y: WEIR_COEFFICIENT * weir(y) - q, 0.0, 20.0, xtol=1e-14)

    formed = int(np.flatnonzero(np.isclose(t, s.formation_time_s, rtol=1e-12))[0])
    y_f = head(Q[formed])
    for i in np.linspace(formed + 1, len(t) - 2, 25).astype(int):
        exact = area / WEIR_COEFFICIENT * quad(lambda h: 1.0 / weir(h), head(Q[i]), y_f,
                                                epsabs=0.0, epsrel=1e-12)[0]
        assert t[i] - t[formed] == pytest.approx(exact, rel=1e-6, abs=1e-3)
    # The routing stops where the outflow has fallen to 1e-4 of its peak.
    assert Q[-1] == pytest.approx(1e-4 * Q.max(), rel=1e-6)
