"""Hydrograph CSV reading, interpolation and exact volumes."""

import numpy as np
import pytest

from floodsph.errors import InputError
from floodsph.io.hydrograph import Hydrograph, read_hydrograph, write_hydrograph_csv


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
         "line 1: missing discharge column: one of 'discharge_m3s', 'discharge_cfs' "
         "(found: time_s, flow)"),
        ("t,discharge_m3s\n0,1\n10,2\n",
         "line 1: missing time column: one of 'time_s', 'time_min', 'time_h', 'time' "
         "(found: t, discharge_m3s)"),
        ("time_s,time_h,discharge_m3s\n0,0,1\n3600,1,2\n",
         "line 1: 2 time columns ('time_s', 'time_h'); keep one"),
        ("time,discharge_m3s\n2024-05-01T06:00Z,1\n2024-05-01T05:00Z,2\n",
         "line 3: time = 2024-05-01T05:00Z is not later than the previous time "
         "2024-05-01T06:00Z (times must increase strictly)"),
        ("time,discharge_m3s\n2024-05-01T06:00+02:00,1\n2024-05-01T07:00,2\n",
         "line 3: time = 2024-05-01T07:00 has no UTC offset, but line 2 "
         "(2024-05-01T06:00+02:00) has a UTC offset; give every date an offset, or none "
         "(then all are UTC)"),
        ("time,discharge_m3s\n2024-05-01T06:00Z,1\n1 May 2024 07:00,2\n",
         "line 3: time = '1 May 2024 07:00' is not an ISO 8601 date and time "
         "(e.g. 2024-05-01T06:00:00Z)"),
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


SECONDS = "time_s,discharge_m3s\n0,0\n1800,250.5\n5400,120.25\n12600,0\n"


def test_hours_minutes_and_dates_inject_the_volume_of_seconds(tmp_path):
    reference = read_hydrograph(_csv(tmp_path, SECONDS, "s.csv")).volume(0.0, 20_000.0)
    # Trapezoids by hand: 225,450 + 667,350 + 432,900 m3.
    assert reference == pytest.approx(1_325_700.0, rel=1e-12)
    hours = "time_h,discharge_m3s\n0,0\n0.5,250.5\n1.5,120.25\n3.5,0\n"
    minutes = "discharge_m3s,time_min\n0,0\n250.5,30\n120.25,90\n0,210\n"
    dates = ("time,discharge_m3s\n2024-05-01T06:00:00+02:00,0\n2024-05-01T06:30:00+02:00,250.5\n"
             "2024-05-01T06:30:00+01:00,120.25\n2024-05-01T09:30:00+02:00,0\n")
    for name, text in (("h.csv", hours), ("min.csv", minutes), ("dates.csv", dates)):
        hg = read_hydrograph(_csv(tmp_path, text, name))
        np.testing.assert_allclose(hg.t, [0.0, 1800.0, 5400.0, 12600.0], rtol=0, atol=1e-9)
        assert abs(hg.volume(0.0, 20_000.0) - reference) <= 1e-9


def test_dates_count_from_scenario_start(tmp_path):
    from datetime import UTC, datetime

    text = "time,discharge_m3s\n2024-05-01T06:00:00,10\n2024-05-01T07:00:00,20\n"
    start = datetime(2024, 5, 1, 5, 30, tzinfo=UTC)  # dates without an offset are UTC
    notes = []
    hg = read_hydrograph(_csv(tmp_path, text), start=start, conversions=notes)
    np.testing.assert_array_equal(hg.t, [1800.0, 5400.0])
    assert notes == ["inflows[0].hydrograph: q.csv: time from the ISO 8601 dates of column "
                     "'time', in seconds from scenario.start (2024-05-01T05:30:00+00:00)"]


def test_cubic_feet_per_second_converted_and_reported(tmp_path):
    notes = []
    hg = read_hydrograph(_csv(tmp_path, "time_h,discharge_cfs\n0,0\n1,35314.6667\n"),
                         conversions=notes)
    assert hg.Q[1] == pytest.approx(1000.0, rel=1e-8)  # 1 m3/s = 35.3146667 cfs
    assert notes == ["inflows[0].hydrograph: q.csv: time from column 'time_h' in hours "
                     "(x 3600 s); discharge from column 'discharge_cfs' in cubic feet per "
                     "second (x 0.028316846592 m3/s)"]
    read_hydrograph(_csv(tmp_path, SECONDS, "s.csv"), conversions=notes)
    assert len(notes) == 1  # seconds and m3/s: nothing converted, nothing said
