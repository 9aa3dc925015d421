"""PX4 ULog and ArduPilot DataFlash readers.

References: a real ULog written by PX4 (tests/data/px4_ulog, with its licence), checked against
pyulog's own reading and the log's own CAL_GYRO{n}_ID parameters; DataFlash logs written here to
ArduPilot's documented format (``dataflash_writer.py``), corrected the way ArduPilot corrects
logged IMU data (``firmware_models.py``), so the reader must undo exactly that.
"""

from pathlib import Path

import numpy as np
import pytest
from dataflash_writer import imu_log  # noqa: E402
from firmware_models import ardupilot_correct  # noqa: E402

from gyrocal.errors import InputError, UnitError
from gyrocal.io import read_flight_log, read_recording
from gyrocal.io.dataflash import DataFlashWarning

ULOG = Path(__file__).parent / "data" / "px4_ulog" / "sample_log_small.ulg"


def test_real_ulog_holds_three_gyros_by_device_id():
    from pyulog import ULog

    with pytest.raises(InputError, match=r"3 IMUs in this log \(0 \(device id 2424842\), 1 .*choose one with imu N"):
        read_flight_log(ULOG)
    log = ULog(str(ULOG))
    for inst in range(3):
        rec, info = read_flight_log(ULOG, imu=inst)
        topic = next(d for d in log.data_list if d.name == "sensor_gyro" and d.multi_id == inst)
        assert info["format"] == "ulog" and info["device_id"] == log.initial_parameters[f"CAL_GYRO{inst}_ID"]
        np.testing.assert_array_equal(rec.gyro[:, 0], topic.data["x"].astype(float))
        np.testing.assert_array_equal(rec.t, topic.data["timestamp_sample"] * 1e-6)
        np.testing.assert_array_equal(rec.temp, topic.data["temperature"].astype(float))
        assert len(rec) == 6 and rec.units == "rad/s"
    assert 39 < read_flight_log(ULOG, imu=0)[0].temp.mean() < 41  # the first IMU runs hot (heater)


def test_ulog_accelerometer_of_the_same_device():
    from pyulog import ULog

    rec, info = read_flight_log(ULOG, imu=1, accel_units="m/s^2")
    topic = next(d for d in ULog(str(ULOG)).data_list if d.name == "sensor_accel" and d.multi_id == 1)
    assert info["accel_device_id"] == info["device_id"] == 3670050
    # the sample logs accel and gyro of one IMU at the same stamps: the values come through as they are
    np.testing.assert_allclose(rec.accel[:, 2], topic.data["z"].astype(float))
    assert rec.accel_source_units == "m/s^2" and 9 < np.abs(rec.accel).max() < 11  # gravity
    with pytest.raises(UnitError, match="m/s\\^2"):
        read_flight_log(ULOG, imu=1, accel_units="g")


def test_ulog_through_read_recording():
    rec = read_recording(ULOG, units="rad/s", imu=2)
    assert len(rec) == 6 and rec.has_time
    with pytest.raises(UnitError, match="rad/s"):
        read_recording(ULOG, units="deg/s", imu=2)
    with pytest.raises(InputError, match="no IMU 5; the log holds 0, 1, 2"):
        read_recording(ULOG, units="rad/s", imu=5)


TCAL = {"INS_TCAL1_ENABLE": 1.0, "INS_TCAL1_TMIN": 5.0, "INS_TCAL1_TMAX": 55.0, "INS_TCAL1_GYR1_X": 150.0,
        "INS_TCAL1_GYR1_Y": -80.0, "INS_TCAL1_GYR1_Z": 20.0, "INS_TCAL1_GYR2_X": -1.5, "INS_TCAL1_GYR2_Y": 0.7,
        "INS_TCAL1_GYR2_Z": 0.0, "INS_TCAL1_GYR3_X": 0.02, "INS_TCAL1_GYR3_Y": 0.0, "INS_TCAL1_GYR3_Z": -0.01,
        "INS_GYR1_CALTEMP": 28.0, "INS_GYROFFS_X": 0.011, "INS_GYROFFS_Y": -0.007, "INS_GYROFFS_Z": 0.003}


def _write_log(path, raw, temp, params, orientation=0):
    """An IMU log of raw readings, corrected and rotated as ArduPilot logs them (two IMUs)."""
    from pymavlink.rotmat import Vector3

    w = imu_log()
    for name, value in {**params, "AHRS_ORIENTATION": float(orientation)}.items():
        w.write("PARM", 1000, name, value)
    corrected = ardupilot_correct(params, 1, temp, raw).astype(float) if params else raw
    logged = np.array([[v.x, v.y, v.z] for v in (Vector3(*row).rotate_by_id(orientation) for row in corrected)])
    for k, (g, t) in enumerate(zip(logged, temp)):
        for inst in (0, 1):
            w.write("IMU", 2000 + 40_000 * k, inst, *g, 0.0, 0.0, 9.81, 0, 0, float(t), 1, 1, 25, 25)
    path.write_bytes(bytes(w))


def test_dataflash_reader_undoes_orientation_temperature_correction_and_offsets(tmp_path, rng):
    n = 200
    temp = np.linspace(0.0, 60.0, n)  # beyond TMIN and TMAX at both ends: the clipping is undone too
    raw = rng.standard_normal((n, 3)) * 0.01 + [0.02, -0.01, 0.005]
    path = tmp_path / "warm.bin"
    _write_log(path, raw, temp, TCAL, orientation=2)  # ROTATION_YAW_90
    with pytest.raises(InputError, match="2 IMUs in this log"):
        read_flight_log(path)
    rec, info = read_flight_log(path, imu=0)
    assert info["format"] == "dataflash" and info["instance"] == 0 and info["imu_number"] == 1
    assert info["undone"] == ["AHRS_ORIENTATION 2", "INS_TCAL1 temperature correction", "INS_GYROFFS"]
    np.testing.assert_allclose(rec.t, 2e-3 + 0.04 * np.arange(n))
    # logged as float32: the raw readings come back within float32 rounding of the sizes involved
    np.testing.assert_allclose(rec.gyro, raw, rtol=0, atol=3e-7)
    np.testing.assert_allclose(rec.temp, temp, atol=1e-5)


def test_dataflash_without_corrections_and_a_changed_parameter(tmp_path, rng):
    raw = rng.standard_normal((50, 3)) * 0.01
    path = tmp_path / "plain.bin"
    _write_log(path, raw, np.full(50, 30.0), {})
    rec, info = read_flight_log(path, imu=1)
    assert info["undone"] == []
    np.testing.assert_allclose(rec.gyro, raw, atol=1e-8)
    extra = imu_log()
    extra.write("PARM", 9_999_999, "INS_GYROFFS_X", 0.5)  # recalibrated after logging started
    path.write_bytes(path.read_bytes() + bytes(extra)[len(bytes(imu_log())):])
    with pytest.warns(DataFlashWarning, match="INS_GYROFFS_X changed during the log"):
        read_flight_log(path, imu=0)


def test_not_a_flight_log(tmp_path):
    bad = tmp_path / "x.bin"
    bad.write_bytes(b"\x00" * 64)
    with pytest.raises(InputError, match="x.bin: .*DataFlash"):
        read_flight_log(bad)


@pytest.mark.parametrize("command", [["calibrate"], ["segments"], ["imu", "--accel-units", "m/s^2"],
                                     ["apply", "CAL", "LOG", "-o", "OUT"],
                                     ["verify", "CAL", "LOG", "--reference", "REF", "--ref-units", "deg/s", "-o", "DIR"]])
def test_every_reading_command_takes_imu_for_a_log_of_several(command, tmp_path):
    """PX4's sample log holds three IMUs: the refusal names --imu, and every command that reads a recording takes
    it (before, only noise and thermal-bias did, so the advice could not be followed). Reference: the log's three
    instances, read by pyulog."""
    from cli_runner import invoke, refused

    assert invoke("calibrate", "--example", "-o", tmp_path / "cal.json")[0] == 0
    assert invoke("simulate", "-o", tmp_path / "ref.csv")[0] == 0
    names = {"CAL": tmp_path / "cal.json", "LOG": ULOG, "REF": tmp_path / "ref.csv", "OUT": tmp_path / "o.csv",
             "DIR": tmp_path / "v"}
    args = [names.get(a, a) for a in command]
    if "LOG" not in command:
        args.insert(1, ULOG)
    args += ["--units", "rad/s", "--no-unit-check"]
    line = refused(*args)
    assert "3 IMUs in this log" in line and "--imu N" in line
    code, out, err = invoke(*args, "--imu", "0")
    assert "IMUs in this log" not in err and "no such option" not in err
