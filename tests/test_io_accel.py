"""Accelerometer columns: found by name or alias when their unit is given, converted to m/s^2, written back.

References: numbers written into small files by the tests themselves, and one g = 9.80665 m/s^2
(standard gravity, the conventional value).
"""

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from cli_runner import invoke, refused

from gyrocal.errors import InputError, UnitError
from gyrocal.io import read_recording, write_recording
from gyrocal.models import ScaleBias
from gyrocal.recording import Recording
from gyrocal.results.calibration import Calibration
from gyrocal.results.files import save

G0 = 9.80665


@pytest.fixture
def imu_csv(tmp_path):
    path = tmp_path / "imu.csv"
    rows = ["time,gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z,note"]
    for i in range(50):
        rows.append(f"{i / 100},{0.01 * i},0.02,-0.01,{0.001 * i},-0.002,1.0,n{i}")
    path.write_text("\n".join(rows) + "\n")
    return path


def test_accelerometer_columns_are_read_only_with_a_unit(imu_csv):
    plain = read_recording(imu_csv, units="rad/s")
    assert plain.accel is None and list(plain.extra) == ["acc_x", "acc_y", "acc_z", "note"]
    rec = read_recording(imu_csv, units="rad/s", accel_units="g")
    assert (rec.accel_units, rec.accel_source_units) == ("m/s^2", "g") and list(rec.extra) == ["note"]
    np.testing.assert_allclose(rec.accel[:, 2], G0)
    np.testing.assert_allclose(rec.accel[:, 0], 0.001 * np.arange(50) * G0)
    other = read_recording(imu_csv, units="rad/s", accel_units="g", gravity=9.81)
    np.testing.assert_allclose(other.accel[:, 2], 9.81)


def test_accelerometer_counts_with_and_without_sensitivity(tmp_path):
    path = tmp_path / "raw.csv"
    path.write_text("t,gx,gy,gz,ax,ay,az\n0,1,2,3,0,0,16384\n0.01,1,2,3,8192,0,16384\n")
    raw = read_recording(path, units="counts", accel_units="counts")
    assert raw.accel_units == "counts" and raw.accel[1, 0] == 8192
    rec = read_recording(path, units="counts", accel_units="counts", accel_sensitivity=16384)
    assert rec.accel_units == "m/s^2" and rec.accel_sensitivity == 16384
    np.testing.assert_allclose(rec.accel[1], [G0 / 2, 0.0, G0])
    with pytest.raises(UnitError, match="accel_sensitivity"):
        read_recording(path, units="counts", accel_units="g", accel_sensitivity=16384)


def test_missing_or_unit_less_accelerometer_columns_say_what_to_give(imu_csv, tmp_path):
    with pytest.raises(InputError, match="accelerometer columns are mapped") as info:
        read_recording(imu_csv, units="rad/s", columns="ax=acc_x,ay=acc_y,az=acc_z")
    assert info.value.param == "accel_units"
    with pytest.raises(InputError, match="unit is not given") as info:
        read_recording(imu_csv, units="rad/s", need_accel=True)
    assert info.value.param == "accel_units"
    gyro_only = tmp_path / "g.csv"
    gyro_only.write_text("t,gx,gy,gz\n0,1,2,3\n0.01,1,2,3\n")
    with pytest.raises(InputError, match="no accelerometer column for ax, ay, az") as info:
        read_recording(gyro_only, units="rad/s", accel_units="g")
    assert info.value.param == "columns"
    with pytest.raises(UnitError, match="furlongs"):
        read_recording(imu_csv, units="rad/s", accel_units="furlongs")


def test_parquet_accelerometer_columns(tmp_path):
    path = tmp_path / "imu.parquet"
    n = 20
    pq.write_table(pa.table({"t": np.arange(n) / 50.0, "gx": np.zeros(n), "gy": np.zeros(n), "gz": np.zeros(n),
                             "accel_x": np.zeros(n), "accel_y": np.zeros(n), "accel_z": np.full(n, 9.8)}), path)
    rec = read_recording(path, units="rad/s", accel_units="m/s^2")
    np.testing.assert_array_equal(rec.accel[:, 2], 9.8)


def test_recordings_with_accelerometer_write_and_read_back(imu_csv, tmp_path):
    rec = read_recording(imu_csv, units="rad/s", accel_units="g")
    out = tmp_path / "out.csv"
    write_recording(out, rec, header_comment="test")
    back = read_recording(out, units="rad/s", accel_units="m/s^2")
    np.testing.assert_array_equal(back.accel, rec.accel)
    np.testing.assert_array_equal(back.gyro, rec.gyro)
    assert list(back.extra["note"][:2]) == ["n0", "n1"]


def test_calibration_with_an_accelerometer_part_corrects_both(imu_csv):
    """a_true = matrix @ (raw - offset) in g, by hand, against Calibration.apply."""
    matrix = np.diag([1.01, 0.99, 1.0])
    offset = np.array([0.01, 0.0, -0.02])
    cal = Calibration(ScaleBias([1.0, 1.0, 1.0], [0.0, 0.0, 0.0]), accelerometer={
        "units": {"input": "g", "output": "m/s^2"},
        "correction": {"matrix": matrix.tolist(), "offset": offset.tolist()}})
    rec = read_recording(imu_csv, units="rad/s", accel_units="g")
    out = cal.apply(rec)
    want = (rec.accel / G0 - offset) @ matrix.T
    np.testing.assert_allclose(out.accel, want, rtol=1e-14)
    assert out.accel_source_units == "m/s^2"
    np.testing.assert_array_equal(out.gyro, rec.gyro)  # k = 1, b = 0
    counts = Recording.from_rate(np.zeros((3, 3)), 10.0, accel=np.zeros((3, 3)), accel_units="counts")
    with pytest.raises(InputError, match="takes g but the recording's accelerometer is in counts"):
        cal.apply(counts)


def test_apply_command_passes_the_accelerometer_through(imu_csv, tmp_path):
    cal_path = tmp_path / "cal.json"
    save(Calibration(ScaleBias([1.0, 1.0, 1.0], [0.0, 0.0, 0.0])), cal_path)
    out = tmp_path / "out.csv"
    code, _, err = invoke("apply", cal_path, imu_csv, "-o", out, "--accel-units", "g")
    assert code == 0, err
    assert out.read_text().splitlines()[0].endswith("ax ay az in m/s^2")
    back = read_recording(out, units="rad/s", accel_units="m/s^2")
    np.testing.assert_allclose(back.accel[:, 2], G0)
    line = refused("apply", cal_path, imu_csv, "-o", tmp_path / "o2.csv", "--columns", "ax=acc_x,ay=acc_y,az=acc_z")
    assert "--accel-units" in line
    line = refused("apply", cal_path, imu_csv, "-o", tmp_path / "o3.csv", "--model", "smooth")
    assert "--model does not apply to a gyrocal.calibration file" in line
