"""Inputs that used to slip through or give a confusing message: time units, unit mix-ups,
missing or duplicated headers, UTF-16 text.

References: the numbers and layouts each test writes into its own small files, and the one-line messages
users see.
"""

from __future__ import annotations

import re
from importlib import resources

import numpy as np
import pytest

from gyrocal.errors import GyrocalError, InputError, UnitError
from gyrocal.io import read_recording, write_csv
from gyrocal.io.csvfile import read_csv_columns

DATA = resources.files("gyrocal") / "data"


def bad(path, match, exc=InputError, **kwargs):
    kwargs.setdefault("units", "deg/s")
    with pytest.raises(exc, match=match) as info:
        read_recording(path, **kwargs)
    assert type(info.value) is exc and isinstance(info.value, GyrocalError)
    assert "\n" not in str(info.value)
    return str(info.value)


def table(t_name, t, g):
    return {t_name: t, "gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2]}


# ---------------------------------------------------------------- time column units


@pytest.mark.parametrize(("name", "per_s", "step"), [("t", 1e3, "5"), ("time", 1e6, "5000"), ("timestamp", 1e9, "5e+06")])
def test_time_not_in_seconds_under_a_plain_name_is_refused(tmp_path, rng, name, per_s, step):
    g = rng.normal(0, 2.0, (50, 3))
    stamps = (1000.0 + np.arange(50) * 0.005) * per_s  # 200 Hz, stamped from boot
    write_csv(tmp_path / "r.csv", table(name, stamps, g))
    msg = bad(tmp_path / "r.csv", re.escape(f"nominal time step is {step}, "))
    assert "Hz if the times are seconds" in msg and "time_units ms, us or ns" in msg and "(e.g. time_ms)" in msg
    # the advice works: the unit in the column's name scales the stamps to seconds
    unit = {1e3: "ms", 1e6: "us", 1e9: "ns"}[per_s]
    write_csv(tmp_path / "ok.csv", table(f"time_{unit}", stamps, g))
    assert read_recording(tmp_path / "ok.csv", units="deg/s").sample_rate == pytest.approx(200.0, rel=1e-3)


@pytest.mark.parametrize("rate", [0.5, 100e3])
def test_time_steps_at_the_rate_limits_pass(tmp_path, rng, rate):
    for n in (10, 1000):  # float rounding of the steps differs with the length
        write_csv(tmp_path / "r.csv", table("t", np.arange(n) / rate, rng.normal(0, 2.0, (n, 3))))
        assert read_recording(tmp_path / "r.csv", units="deg/s").sample_rate == pytest.approx(rate)


def test_time_slower_than_half_a_hertz_is_refused(tmp_path, rng):
    write_csv(tmp_path / "r.csv", table("t", np.arange(20) * 2.5, rng.normal(0, 2.0, (20, 3))))
    bad(tmp_path / "r.csv", r"nominal time step is 2\.5, 0\.4 Hz if the times are seconds")


# ---------------------------------------------------------------- deg/s declared as rad/s


def _example(name):
    """A bundled recording [deg/s] as (t, gyro in deg/s)."""
    if name == "servo":
        rec = read_recording(DATA / "example_servo.csv", units="deg/s")
    else:
        rec = read_recording(DATA / "imucal_ferraris" / "example_ferraris_session.csv", units="deg/s", sample_rate=102.4)
    return rec.t, np.degrees(rec.gyro)


@pytest.mark.parametrize("name", ["servo", "imucal"])
def test_real_data_in_rad_s_pass_the_unit_checks_and_in_deg_s_fail(tmp_path, name):
    t, deg = _example(name)
    write_csv(tmp_path / "rad.csv", table("t", t, np.radians(deg)))
    rec = read_recording(tmp_path / "rad.csv", units="rad/s")
    np.testing.assert_allclose(rec.gyro, np.radians(deg), rtol=1e-15)
    write_csv(tmp_path / "deg.csv", table("t", t, deg))
    bad(tmp_path / "deg.csv", "almost surely in deg/s: use units deg/s", UnitError, units="rad/s")


def test_slow_deg_s_data_declared_as_rad_s_are_caught_by_their_noise(tmp_path, rng):
    t, deg = _example("servo")
    still = deg[:200]  # the example's static start: 8 deg/s at most, under the peak check's 34.9
    assert np.abs(still).max() < 34.9
    write_csv(tmp_path / "still.csv", table("t", t[:200], still))
    bad(tmp_path / "still.csv", r"per-sample noise is [12]\.\d+ rad/s.*use units deg/s \(or check_units\)",
        UnitError, units="rad/s")
    assert len(read_recording(tmp_path / "still.csv", units="rad/s", check_units=False)) == 200
    # slow turns, +-20 deg/s, with MEMS noise
    g = 20.0 * np.sin(np.linspace(0.0, 20.0, 2000))[:, None] + rng.normal(0, 1.0, (2000, 3))
    write_csv(tmp_path / "slow.csv", table("t", np.arange(2000) * 0.01, g))
    bad(tmp_path / "slow.csv", "per-sample noise is", UnitError, units="rad/s")


# ---------------------------------------------------------------- headers


@pytest.mark.parametrize(("delimiter", "example"), [(",", "'t,gx,gy,gz'"), (" ", "'t gx gy gz'")])
def test_headerless_file_asks_for_columns_by_number(tmp_path, delimiter, example):
    rows = ["0 -0.21 0.05 0.33", "0.01 -0.2 0.04 0.31", "0.02 -0.22 0.06 0.3"]
    (tmp_path / "h.csv").write_text("\n".join(r.replace(" ", delimiter) for r in rows) + "\n")
    msg = bad(tmp_path / "h.csv", r"the first line \('0.-0\.21.*'\) is data, not a header; say which column holds "
              r"what by number, counting from 1 \(columns t=1,gx=2,gy=3,gz=4\)")
    assert example in msg
    # the advice works: the first column increases, so it is offered as the time
    rec = read_recording(tmp_path / "h.csv", units="deg/s", columns="t=1,gx=2,gy=3,gz=4")
    np.testing.assert_array_equal(rec.t, [0.0, 0.01, 0.02])
    np.testing.assert_allclose(np.degrees(rec.gyro[:, 0]), [-0.21, -0.2, -0.22], rtol=1e-12)


@pytest.mark.parametrize("use_pyarrow", [True, False])
def test_duplicated_column_names_are_refused_when_used(tmp_path, use_pyarrow):
    path = tmp_path / "d.csv"
    path.write_text("t,gx,gy,gz,gx\n0,1,2,3,4\n0.01,1,2,3,4\n")
    with pytest.raises(InputError, match=r"column name 'gx' \(used for gx\) appears 2 times in the header; rename"):
        read_csv_columns(path, use_pyarrow=use_pyarrow)
    path.write_text("t,gx,gy,gz,note,note\n0,1,2,3,a,b\n0.01,1,2,3,a,b\n")  # unused copies are harmless
    data, _ = read_csv_columns(path, use_pyarrow=use_pyarrow)
    np.testing.assert_array_equal(data["gx"], [1.0, 1.0])


@pytest.mark.parametrize("use_pyarrow", [True, False])
@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be", "utf-32"])
def test_utf16_and_utf32_text_with_a_bom_is_decoded(tmp_path, use_pyarrow, encoding):
    # Excel "Unicode text": UTF-16 with a BOM, tabs, CRLF
    text = "t\tgx\tgy\tgz\tnote °C\r\n0\t1.5\t-2\t3\tcafé\r\n0.01\t1.25\t-2\t3\tx\r\n"
    body = text.encode(encoding)
    if encoding == "utf-16-be":
        body = b"\xfe\xff" + body  # the -be codec writes no BOM
    (tmp_path / "u.txt").write_bytes(body)
    data, extra = read_csv_columns(tmp_path / "u.txt", use_pyarrow=use_pyarrow)
    np.testing.assert_array_equal(data["t"], [0.0, 0.01])
    np.testing.assert_array_equal(data["gx"], [1.5, 1.25])
    assert list(extra) == ["note °C"] and list(extra["note °C"]) == ["café", "x"]


def test_cli_refuses_each_in_one_line(tmp_path, rng):
    from cli_runner import refused

    g = rng.normal(0, 2.0, (50, 3))
    write_csv(tmp_path / "ms.csv", table("time", np.arange(50) * 5.0, g))
    (tmp_path / "nohead.csv").write_text("0,1.5,2,3\n0.01,1.5,2,3\n")
    write_csv(tmp_path / "deg.csv", table("t", np.arange(50) * 0.01, g))
    cases = {"ms.csv": ("deg/s", "nominal time step is 5,"), "nohead.csv": ("deg/s", "is data, not a header; say which column"),
             "deg.csv": ("rad/s", "per-sample noise is")}
    for name, (units, expected) in cases.items():
        line = refused("calibrate", tmp_path / name, "--units", units, "--speed", "60", "-o", tmp_path / "c.json")
        assert expected in line, line


def test_numbered_header_of_pandas_is_a_header_and_its_names_win_over_positions(tmp_path):
    path = tmp_path / "frame.csv"
    path.write_text("0,1,2,3\n" + "".join(f"{i / 100},{0.1 * i},0.2,0.3\n" for i in range(50)))
    rec = read_recording(path, units="deg/s", columns="t=0,gx=1,gy=2,gz=3")
    assert len(rec) == 50 and rec.sample_rate == pytest.approx(100.0)
    np.testing.assert_allclose(np.degrees(rec.gyro[:3, 0]), [0.0, 0.1, 0.2], rtol=1e-12)
    bad(path, r"the header \('0,1,2,3'\) numbers the columns from 0, as pandas writes them; say which column holds "
        r"what by those names, e.g. columns t=0,gx=1,gy=2,gz=3")
    # positions counted from 1 would collide with the names: refused, never read shifted
    bad(path, r"column '3' is given for both gy and gz", columns="t=1,gx=2,gy=3,gz=4")
