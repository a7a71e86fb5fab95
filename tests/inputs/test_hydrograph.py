"""Hydrograph CSV reading, interpolation and exact volumes."""

import numpy as np
import pytest

from floodsph.errors import InputError
from floodsph.inputs.hydrograph import Hydrograph, read_hydrograph, write_hydrograph_csv


def _csv(tmp_path, text, name="q.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.fixture
def triangle():
    # Q rises 0 -> 100 m3/s over 10 s, falls to 20 m3/s at 30 s.
    return Hydrograph([0.0, 10.0, 30.0], [0.0, 100.0, 20.0])


def test_discharge_is_linear_inside_and_zero_outside(triangle):
    assert triangle.discharge(5.0) == pytest.approx(50.0, rel=1e-15)
    assert triangle.discharge(20.0) == pytest.approx(60.0, rel=1e-15)
    assert triangle.discharge(30.0) == 20.0
    assert triangle.discharge(-1.0) == 0.0
    assert triangle.discharge(30.5) == 0.0


def test_volume_is_the_exact_integral_of_the_linear_pieces(triangle):
    # 5..10 s: mean of 50 and 100 over 5 s = 375; 10..20 s: mean of 100 and 60 over 10 s = 800.
    assert triangle.volume(5.0, 20.0) == pytest.approx(1175.0, rel=1e-14)
    # Over and beyond the table: 0.5*100*10 + 0.5*(100+20)*20 = 1700; nothing outside.
    assert triangle.volume(-50.0, 99.0) == pytest.approx(1700.0, rel=1e-14)
    assert triangle.total_volume() == pytest.approx(1700.0, rel=1e-14)
    # Inside one segment the integrand is linear, so the midpoint rule is exact.
    assert triangle.volume(12.0, 17.0) == pytest.approx(5.0 * triangle.discharge(14.5), rel=1e-14)
    assert triangle.volume(20.0, 5.0) == pytest.approx(-1175.0, rel=1e-14)


def test_columns_in_any_order_with_extra_columns(tmp_path):
    path = _csv(tmp_path, "note,discharge_m3s,time_s\na,0,0\nb,4.5,60\n\nc,1.5,120\n")
    hydrograph = read_hydrograph(path)
    np.testing.assert_array_equal(hydrograph.t, [0.0, 60.0, 120.0])
    np.testing.assert_array_equal(hydrograph.Q, [0.0, 4.5, 1.5])
    assert hydrograph.t.dtype == np.float64


def test_write_then_read_is_exact(tmp_path):
    t = np.linspace(0.0, 1.0, 7) ** 2 * 1000.0
    Q = np.sqrt(t) * np.pi
    write_hydrograph_csv(tmp_path / "h.csv", t, Q)
    back = read_hydrograph(tmp_path / "h.csv")
    np.testing.assert_array_equal(back.t, t)
    np.testing.assert_array_equal(back.Q, Q)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["h.csv"]  # no temporary left


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("time_s,discharge_m3s\n0,1\n20,2\n10,3\n",
         "line 4: time_s = 10 is not greater than the previous time 20 "
         "(times must increase strictly)"),
        ("time_s,discharge_m3s\n0,1\n10,1\n10,3\n",
         "line 4: time_s = 10 is not greater than the previous time 10 "
         "(times must increase strictly)"),
        ("time_s,discharge_m3s\n0,1\n10,-2.5\n", "line 3: discharge_m3s = -2.5 is negative"),
        ("time_s,discharge_m3s\n0,1\n10,nan\n", "line 3: discharge_m3s is NaN"),
        ("time_s,discharge_m3s\n0,1\nten,1\n", "line 3: time_s = 'ten' is not a number"),
        ("time_s,discharge_m3s\n0,1\n10\n", "line 3: no value in column 'discharge_m3s'"),
        ("time_s,flow\n0,1\n10,2\n",
         "line 1: missing column 'discharge_m3s' (found: time_s, flow)"),
        ("time_s,discharge_m3s\n0,1\n", "needs at least 2 data rows, found 1"),
    ],
)
def test_errors_name_key_file_and_line(tmp_path, text, message):
    path = _csv(tmp_path, text)
    with pytest.raises(InputError) as err:
        read_hydrograph(path, name="inflows[2].hydrograph")
    assert str(err.value) == f"inflows[2].hydrograph: {path}, {message}" or (
        "line" not in message and str(err.value) == f"inflows[2].hydrograph: {path}: {message}")


def test_missing_file(tmp_path):
    pattern = r"^inflows\[0\]\.hydrograph: .*nope\.csv: file not found$"
    with pytest.raises(InputError, match=pattern):
        read_hydrograph(tmp_path / "nope.csv")
