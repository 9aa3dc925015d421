"""Reading text recordings: layouts real logs come in, and every bad input.

References: the numbers each test writes into its own small files.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gyrocal.errors import GyrocalError, InputError, NonFiniteInputError, SaturationError, UnitError
from gyrocal.io import read_recording, write_csv
from gyrocal.io.csvfile import read_csv_columns


def rates(rng, n=200, scale=30.0):
    """Readings [deg/s] like a slow turn with noise: no run is stuck at the extreme."""
    return rng.normal(0.0, scale, (n, 3))


def write_table(path, header, rows, delimiter=",", lead=""):
    text = lead + delimiter.join(header) + "\n" + "\n".join(delimiter.join(map(str, r)) for r in rows) + "\n"
    path.write_text(text)
    return path


@pytest.mark.parametrize("use_pyarrow", [True, False])
@pytest.mark.parametrize("delimiter", [",", ";", "\t", " "])
def test_delimiters_and_readers_agree(tmp_path, rng, delimiter, use_pyarrow):
    g = rates(rng)
    t = np.arange(len(g)) * 0.01
    rows = np.column_stack([t, g]).tolist()
    path = write_table(tmp_path / "rec.txt", ["t", "gx", "gy", "gz"], [[repr(v) for v in r] for r in rows], delimiter)
    data, extra = read_csv_columns(path, use_pyarrow=use_pyarrow)
    np.testing.assert_array_equal(data["t"], t)
    np.testing.assert_array_equal(np.column_stack([data["gx"], data["gy"], data["gz"]]), g)
    assert extra == {}


def test_deg_s_and_rad_s_give_the_same_recording(tmp_path, rng):
    # turns with MEMS-like noise: iid 30 deg/s "noise" in rad/s would fail the unit check
    g = 60.0 * np.sin(np.linspace(0.0, 6.0, 200))[:, None] + rates(rng, scale=2.0)
    t = np.arange(len(g)) * 0.005
    write_csv(tmp_path / "deg.csv", {"t": t, "gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2]})
    r = np.radians(g)
    write_csv(tmp_path / "rad.csv", {"t": t, "gx": r[:, 0], "gy": r[:, 1], "gz": r[:, 2]})
    deg = read_recording(tmp_path / "deg.csv", units="deg/s")
    rad = read_recording(tmp_path / "rad.csv", units="rad/s")
    np.testing.assert_allclose(deg.gyro, rad.gyro, rtol=1e-14)
    assert (deg.units, deg.source_units, rad.source_units) == ("rad/s", "deg/s", "rad/s")
    assert deg.has_time and deg.sample_rate == pytest.approx(200.0)


def test_ground_station_log_blank_first_line_30_columns_no_time(tmp_path, rng):
    n = 120
    g = rates(rng, n)
    header = [f"field{i}" for i in range(27)]
    header[5:5] = ["gyroX", "gyroY", "gyroZ"]
    rows = []
    for i in range(n):
        row = [f"v{i}_{j}" for j in range(27)]
        row[5:5] = [repr(float(x)) for x in g[i]]
        rows.append(row)
    path = write_table(tmp_path / "log.csv", header, rows, lead="\n")
    rec = read_recording(path, units="deg/s", columns="gx=gyroX,gy=gyroY,gz=gyroZ", sample_rate=20)
    np.testing.assert_allclose(rec.gyro, np.radians(g), rtol=1e-15)
    assert not rec.has_time and rec.sample_rate == 20.0
    np.testing.assert_allclose(rec.t, np.arange(n) / 20.0)
    assert list(rec.extra) == [h for h in header if not h.startswith("gyro")]
    assert rec.extra["field26"][7] == "v7_26"


def test_aliases_are_found_case_insensitively(tmp_path, rng):
    g = rates(rng, 50)
    path = write_table(
        tmp_path / "a.csv",
        ["Timestamp", "Gyr_X", "GYRO_Y [deg/s]", "wz", "Temperature"],
        [[i * 0.1, *g[i], 25.0] for i in range(50)],
    )
    rec = read_recording(path, units="deg/s")
    np.testing.assert_allclose(rec.gyro, np.radians(g))
    np.testing.assert_allclose(rec.temp, 25.0)
    assert rec.extra == {}


@pytest.mark.parametrize(
    "header",
    [
        ["Time (s)", "gyro_x_rad_s", "GyroY(deg/s)", "angular_velocity.z", "acc_x"],
        ["elapsed_time", "x_gyro", "y_gyro", "z_gyro", "acc_x"],
        ["timestamp", "omega_x", "omega_y", "omega_z", "acc_x"],
    ],
)
def test_common_logger_headers(tmp_path, rng, header):
    g = rates(rng, 10)
    path = write_table(tmp_path / "h.csv", header, [[i * 0.1, *g[i], 9.81] for i in range(10)])
    rec = read_recording(path, units="deg/s")
    np.testing.assert_allclose(rec.gyro, np.radians(g))
    assert list(rec.extra) == ["acc_x"] and rec.has_time


def test_time_wins_over_sample_rate(tmp_path, rng):
    g = rates(rng, 40)
    t = np.cumsum(rng.uniform(0.005, 0.015, 40))  # bursty, jittered stamps are fine
    write_csv(tmp_path / "r.csv", {"t": t, "gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2]})
    rec = read_recording(tmp_path / "r.csv", units="deg/s", sample_rate=1000.0)
    np.testing.assert_array_equal(rec.t, t)
    assert rec.has_time
    # The nominal rate is the sensor clock's, 100 Hz (steps U(5, 15) ms): the median of nine 4-step
    # block means scatters by about 1.25 * 2.9 ms / sqrt(4 * 9) = 0.6 ms; 4 sigma of that.
    assert abs(1.0 / rec.sample_rate - 0.010) < 4 * 0.6e-3


def test_counts_with_and_without_sensitivity(tmp_path, rng):
    counts = np.round(rng.normal(0, 500, (80, 3)))
    table = counts[:, 0] / 10.0  # a table reports a physical rate in output units
    write_csv(tmp_path / "raw.csv", {"gx": counts[:, 0], "gy": counts[:, 1], "gz": counts[:, 2], "table_rate": table})
    raw = read_recording(tmp_path / "raw.csv", units="counts", sample_rate=100)
    assert raw.units == "counts" and raw.source_units == "counts" and raw.sensitivity is None
    np.testing.assert_array_equal(raw.gyro, counts)
    conv = read_recording(tmp_path / "raw.csv", units="counts", sample_rate=100, sensitivity=16.4, output_units="deg/s")
    assert conv.units == "rad/s" and conv.source_units == "counts" and conv.sensitivity == 16.4
    np.testing.assert_allclose(conv.gyro, np.radians(counts / 16.4))
    np.testing.assert_allclose(conv.table_rate, np.radians(table))


def test_table_rate_and_axis_convert_with_the_rates(tmp_path, rng):
    g = rates(rng, 30)
    path = write_table(tmp_path / "tt.csv", ["gx", "gy", "gz", "table_rate", "axis"], [[*g[i], -60.0, " Z"] for i in range(30)])
    rec = read_recording(path, units="deg/s", sample_rate=10)
    np.testing.assert_allclose(rec.table_rate, math.radians(-60.0))
    assert set(rec.axis) == {"z"}


def test_own_output_with_comment_header_reads_back(tmp_path, rng):
    g = rates(rng, 25)
    cols = {"t": np.arange(25) * 0.1, "gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2], "note": np.array(["a,b"] * 25)}
    write_csv(tmp_path / "o.csv", cols, header_comment="made by a test\nsecond line")
    assert (tmp_path / "o.csv").read_text().startswith("# made by a test\n# second line\n")
    rec = read_recording(tmp_path / "o.csv", units="deg/s")
    np.testing.assert_array_equal(rec.gyro, np.radians(g))
    assert list(rec.extra["note"]) == ["a,b"] * 25


# ---------------------------------------------------------------- bad input


def bad(path, match, exc=InputError, **kwargs):
    kwargs.setdefault("units", "deg/s")
    with pytest.raises(exc, match=match) as info:
        read_recording(path, **kwargs)
    assert isinstance(info.value, GyrocalError)
    assert "\n" not in str(info.value)
    return str(info.value)


def test_missing_file(tmp_path):
    bad(tmp_path / "nope.csv", "does not exist")


def test_missing_column_lists_columns_and_suggests_mapping(tmp_path):
    path = write_table(tmp_path / "m.csv", ["t", "gyroA", "gyroB", "gyroC"], [[0, 1, 2, 3]])
    msg = bad(path, "no column for gx, gy, gz")
    assert "'gyroA'" in msg and "map them with columns gx=NAME" in msg
    with pytest.raises(InputError) as info:
        read_recording(path, units="deg/s")
    assert info.value.param == "columns"
    bad(path, r"column 'gyroQ' \(given for gx\) is not in the file", columns={"gx": "gyroQ"})


def test_ambiguous_alias_asks_for_mapping(tmp_path):
    path = write_table(tmp_path / "amb.csv", ["t", "gyr_x", "gyro_x", "gy", "gz"], [[0, 1, 2, 3, 4]])
    bad(path, "several columns could be gx .*say which with columns gx=gyr_x")


@pytest.mark.parametrize("use_pyarrow", [True, False])
def test_non_numeric_cell_names_column_and_row(tmp_path, use_pyarrow):
    path = write_table(tmp_path / "nn.csv", ["t", "gx", "gy", "gz"], [[0, 1, 2, 3], [1, 1, "oops", 3], [2, 1, 2, 3]])
    with pytest.raises(InputError, match="column 'gy' holds non-numeric cell 'oops' at data row 2"):
        read_csv_columns(path, use_pyarrow=use_pyarrow)


@pytest.mark.parametrize("cell", ["nan", "inf", "", "-Infinity"])
def test_non_finite_rows_are_counted(tmp_path, cell):
    rows = [[i, 1, 2, 3] for i in range(6)]
    rows[2][1] = cell
    rows[4][3] = cell
    bad(write_table(tmp_path / "nf.csv", ["t", "gx", "gy", "gz"], rows), r"2 row\(s\) hold NaN.*data row 3 \(column gx\)", NonFiniteInputError)


def test_time_must_increase(tmp_path):
    rows = [[0, 1, 2, 3], [0.1, 1, 2, 3], [0.1, 1, 2, 3], [0.3, 1, 2, 3]]
    msg = bad(write_table(tmp_path / "dup.csv", ["t", "gx", "gy", "gz"], rows), "duplicated timestamp at data row 3")
    assert "(t=0.1 then 0.1)" in msg  # plain numbers, not np.float64(...) reprs
    rows[2][0] = 0.05
    msg = bad(write_table(tmp_path / "back.csv", ["t", "gx", "gy", "gz"], rows), "time going backwards at data row 3")
    assert "(t=0.1 then 0.05)" in msg and "np." not in msg


def test_missing_time_needs_sample_rate(tmp_path):
    bad(write_table(tmp_path / "nt.csv", ["gx", "gy", "gz"], [[1, 2, 3], [1, 2, 3]]), "no time column.*give the sample rate \\(sample_rate HZ\\)")


def test_saturated_samples(tmp_path, rng):
    g = rates(rng, 300)
    g[100:140, 2] = 2000.0  # stuck at +full scale during a fast turn
    g[200:230, 2] = -2000.0
    write_csv(tmp_path / "sat.csv", {"t": np.arange(300) * 0.01, "gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2]})
    bad(tmp_path / "sat.csv", r"axis z is stuck at full scale \(\+-2000\) in 70 sample\(s\), first at data rows 101-140", SaturationError)
    dropped = read_recording(tmp_path / "sat.csv", units="deg/s", saturation="drop")
    assert len(dropped) == 230 and dropped.t[100] == pytest.approx(1.4)
    assert len(read_recording(tmp_path / "sat.csv", units="deg/s", saturation="ignore")) == 300


def test_deg_s_declared_as_rad_s(tmp_path, rng):
    g = rates(rng, 100, scale=300.0)
    write_csv(tmp_path / "u.csv", {"t": np.arange(100) * 0.01, "gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2]})
    bad(tmp_path / "u.csv", "almost surely in deg/s: use units deg/s", UnitError, units="rad/s")
    assert len(read_recording(tmp_path / "u.csv", units="rad/s", check_units=False)) == 100


def test_counts_must_be_integers_and_counts_are_not_deg_s(tmp_path, rng):
    g = rates(rng, 50)
    write_csv(tmp_path / "f.csv", {"gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2]})
    bad(tmp_path / "f.csv", "units are counts but data row 1 holds non-integer", UnitError, units="counts", sample_rate=10)
    c = np.round(g * 400)
    write_csv(tmp_path / "c.csv", {"gx": c[:, 0], "gy": c[:, 1], "gz": c[:, 2]})
    bad(tmp_path / "c.csv", "look like raw counts: use units counts", UnitError, sample_rate=10)


def test_bad_arguments(tmp_path):
    path = write_table(tmp_path / "ok.csv", ["gx", "gy", "gz"], [[1, 2, 3], [1, 2, 4]])
    bad(path, "units 'furlongs' is not a known unit", UnitError, units="furlongs", sample_rate=1)
    bad(path, "sensitivity applies only to units counts, not deg/s", UnitError, sample_rate=1, sensitivity=16.4)
    bad(path, "sample_rate must be finite and > 0", sample_rate=-5)
    bad(path, "saturation 'keep' is not accepted", sample_rate=1, saturation="keep")
    bad(path, "columns key 'gq' is not a known quantity", columns="gq=gx")
    bad(path, "columns entry 'gx' is not NAME=COLUMN", columns="gx")


def test_time_column_named_with_a_unit_is_scaled(tmp_path, rng):
    g = rates(rng, 20)
    stamps = 1_700_000_000_000 + 5 * np.arange(20)  # epoch milliseconds, 200 Hz
    write_csv(tmp_path / "ms.csv", {"time_ms": stamps, "gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2]})
    rec = read_recording(tmp_path / "ms.csv", units="deg/s")
    # float64 seconds at today's epoch resolve 0.24 us: 5e-5 of a 5 ms step
    assert rec.sample_rate == pytest.approx(200.0, rel=1e-4)
    np.testing.assert_allclose(rec.t, stamps * 1e-3, rtol=1e-15)


def test_iso_date_time_column(tmp_path):
    path = write_table(
        tmp_path / "dt.csv",
        ["time", "gx", "gy", "gz"],
        [["2024-05-01T12:00:00.000Z", 1, 2, 3], ["2024-05-01T12:00:00.004Z", 1, 2, 3], ["2024-05-01T12:00:00.008Z", 1, 2, 3]],
    )
    rec = read_recording(path, units="deg/s")
    assert rec.t[0] == pytest.approx(1714564800.0)
    np.testing.assert_allclose(np.diff(rec.t), 0.004, rtol=1e-4)  # float64 epoch seconds: 0.24 us resolution
    write_table(tmp_path / "bad.csv", ["time", "gx", "gy", "gz"], [["2024-05-01", 1, 2, 3], ["soon", 1, 2, 3]])
    bad(tmp_path / "bad.csv", "column 'time' holds non-numeric cell '2024-05-01' at data row 1")


def test_header_only_and_ragged_rows(tmp_path):
    bad(write_table(tmp_path / "h.csv", ["t", "gx", "gy", "gz"], []), "no data rows")
    bad(write_table(tmp_path / "one.csv", ["t", "gx", "gy", "gz"], [[0, 1, 2, 3]]), "a single data row; a recording needs at least two")
    (tmp_path / "r.csv").write_text("t,gx,gy,gz\n0,1,2,3\n1,1,2\n")
    bad(tmp_path / "r.csv", "cannot parse the table")


@pytest.mark.parametrize("use_pyarrow", [True, False])
def test_bom_crlf_and_latin1_text_columns(tmp_path, use_pyarrow):
    path = tmp_path / "old.csv"
    path.write_bytes(b"\xef\xbb\xbft,gx,gy,gz,note\r\n0,1,2,3,caf\xe9\r\n0.1,1,2,3,x\r\n")
    data, extra = read_csv_columns(path, use_pyarrow=use_pyarrow)
    np.testing.assert_array_equal(data["t"], [0.0, 0.1])
    assert extra["note"][1] == "x" and extra["note"][0].startswith("caf")


def test_empty_file(tmp_path):
    (tmp_path / "e.csv").write_text("\n# only a comment\n\n")
    bad(tmp_path / "e.csv", "e.csv: no header row")
