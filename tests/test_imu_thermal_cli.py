"""``gyrocal imu`` on a chamber log from the command line, then ``apply`` at a temperature between the points.

Reference: the independent generator of :mod:`imu_chamber`; the test log at 30 degC is the truth's
readings of known specific forces, without noise, so what is left after ``apply`` is the model's error.
"""

import ctypes
from dataclasses import replace

import numpy as np
import pytest
from cli_runner import invoke
from imu_chamber import TEMPS, Truth, chamber

from gyrocal import firmware
from gyrocal.imu.accel import model_matrices
from gyrocal.imu.poses import fibonacci_directions
from gyrocal.io import read_recording, write_csv
from gyrocal.results.files import load

BETWEEN_T = 30.0


def _write(path, t, gyro_deg, accel, temp):
    write_csv(path, {"t": t, "gx": gyro_deg[:, 0], "gy": gyro_deg[:, 1], "gz": gyro_deg[:, 2], "ax": accel[:, 0],
                     "ay": accel[:, 1], "az": accel[:, 2], "temp": temp})


@pytest.fixture(scope="module")
def chamber_run(tmp_path_factory):
    """The chamber log (deg/s, m/s^2, temp in degC), `gyrocal imu` on it, and the file it wrote."""
    d = tmp_path_factory.mktemp("chamber")
    truth, _, t, gyro, accel, temp, _ = chamber(7, poses=12)
    log = d / "chamber.csv"
    _write(log, t, np.degrees(gyro), accel, temp)
    cal = d / "cal.json"
    code, out, err = invoke("imu", log, "--units", "deg/s", "--accel-units", "m/s^2", "-o", cal)
    assert code == 0, err
    return truth, d, cal, out


def test_imu_prints_the_points_orders_and_frame_and_writes_the_section(chamber_run):
    truth, _, cal, out = chamber_run
    assert f"across temperature: {len(TEMPS)} points at " in out
    assert "file section accelerometer.thermal" in out
    assert "accelerometer: smooth polynomial orders A_xx " in out and "gyro: smooth polynomial orders " in out
    assert "frame: accelerometer: the 9-parameter model's frame" in out
    section = load(cal).accelerometer["thermal"]
    temps = [p["temperature"] for p in section["points"]]
    np.testing.assert_allclose(temps, TEMPS, atol=0.1)
    assert section["accelerometer"]["model"] == "triangular" and section["gyro"]["model"] == "affine"
    assert len(section["accelerometer"]["smooth"]["coefs"]) == 9
    assert section["internal"] == {"accelerometer": "m/s^2", "gyro": "rad/s"}


def _force_sigma(section, u, temp):
    """1-sigma (N, 3) of the corrected force from the smooth model's coefficient covariance at `temp`."""
    doc = section["accelerometer"]
    sm = doc["smooth"]
    coefs = np.asarray(sm["coefs"], float)
    m, width = coefs.shape
    powers = np.vander([(temp - sm["centre"]) / sm["scale"]], width, increasing=True)[0]
    jp = np.kron(np.eye(m), powers)  # parameters from coefficients, (m, m * width)
    cov_p = jp @ np.asarray(sm["covariance"], float) @ jp.T
    p = coefs @ powers

    def force(q):
        return (u - q[-3:]) @ model_matrices(doc["model"], q)[0].T

    h = 1e-7
    jac = np.stack([(force(p + h * e) - force(p - h * e)) / (2 * h) for e in np.eye(m)], axis=-1)  # (N, 3, m)
    return np.sqrt(np.einsum("nim,mk,nik->ni", jac, cov_p, jac))


def test_apply_between_the_points_is_the_truth_within_the_models_sigma(chamber_run):
    """Poses at 30 degC, between the points at 20 and 40: the corrected force is the true one to its 1-sigma."""
    truth, d, cal, _ = chamber_run
    assert isinstance(truth, Truth)
    f = 9.80665 * np.repeat(fibonacci_directions(24), 20, axis=0)
    a, o = truth.accel(BETWEEN_T)
    u = f @ np.linalg.inv(a).T + o
    n = len(u)
    log2 = d / "at30.csv"
    _write(log2, np.arange(n) * 0.01, np.zeros((n, 3)), u, np.full(n, BETWEEN_T))
    out = d / "out.csv"
    code, _, err = invoke("apply", cal, log2, "-o", out)
    assert code == 0, err
    corrected = read_recording(out, units="deg/s", accel_units="m/s^2").accel
    sigma = _force_sigma(load(cal).accelerometer["thermal"], u, BETWEEN_T)
    z = (corrected - f) / sigma
    rms_z = float(np.sqrt(np.mean(z**2)))
    err_rms = float(np.sqrt(np.mean(np.sum((corrected - f) ** 2, axis=1))))
    print(f"apply at {BETWEEN_T} degC: RMS error {err_rms:.2e} m/s^2, RMS z {rms_z:.2f}")
    assert rms_z < 2.5  # one board: the model's error is one draw, shared by every direction
    assert err_rms < 0.01


def test_thermal_report_evaluates_an_imu_thermal_calibration_against_the_baseline(chamber_run, tmp_path):
    """thermal-report on an IMU file: the still poses of the chamber log corrected by the point at 20 degC at every
    temperature (the baseline) are off by the truth's drift (offsets about 0.1 g over the range), those corrected
    by the model in temperature by its noise only."""
    _, d, cal, _ = chamber_run
    code, out, err = invoke("thermal-report", cal, d / "chamber.csv", "-o", tmp_path / "report")
    assert code == 0, err
    rows = {r["scheme"]: r for r in np.genfromtxt(tmp_path / "report" / "summary.csv", delimiter=",", names=True,
                                                  dtype=None, encoding=None)}
    assert rows["single"]["accel_rms_m_s2"] > 0.05
    assert rows["smooth"]["accel_rms_m_s2"] < 0.01 and rows["smooth"]["accel_factor"] > 10


def test_c_header_imu_thermal_table_matches_python_apply(chamber_run, tmp_path):
    """Reference: Python's Calibration.apply with the temperature column; the C library reads the header that
    ``export --format c-header`` writes and corrects each sample at its temperature (float32)."""
    _, d, cal_path, _ = chamber_run
    header = tmp_path / "imu_cal.h"
    code, _, err = invoke("export", cal_path, "--format", "c-header", "-o", header)
    assert code == 0, err
    assert "GYROCAL_IMU_THERMAL" in header.read_text()
    src = tmp_path / "driver.c"
    src.write_text('#include "imu_cal.h"\nint drive(float temp, const float g[3], const float a[3], float w[3], '
                   "float f[3])\n{ return gyrocal_imu_thermal_correct(&GYROCAL_IMU_THERMAL, temp, g, a, w, f); }\n")
    dll = firmware.load_library(tmp_path / "build", extra_sources=[src], include_dirs=[tmp_path]).dll
    dll.drive.argtypes = [ctypes.c_float] + [ctypes.POINTER(ctypes.c_float)] * 4
    data = read_recording(d / "chamber.csv", units="deg/s", accel_units="m/s^2")
    step = slice(None, None, 53)
    g_raw = np.ascontiguousarray(data.gyro[step], dtype=np.float32)  # rad/s: the section's internal unit
    a_raw = np.ascontiguousarray(data.accel[step], dtype=np.float32)
    temp = data.temp[step].astype(np.float32)
    temp[:5] = [-40.0, 0.0, 30.0, 55.0, 80.0]  # between the points and beyond them (clamped)
    w, f = np.empty_like(g_raw), np.empty_like(a_raw)
    ptr = ctypes.POINTER(ctypes.c_float)
    for i in range(len(g_raw)):
        assert dll.drive(float(temp[i]), *(x[i].ctypes.data_as(ptr) for x in (g_raw, a_raw, w, f))) == 0
    sub = replace(data, t=data.t[step], gyro=g_raw.astype(float), accel=a_raw.astype(float), temp=temp.astype(float))
    ours = load(cal_path).apply(sub)
    eps = np.finfo(np.float32).eps
    # float32: a few roundings of terms the size of the readings, offsets and polynomial terms (u up to 1)
    np.testing.assert_allclose(f, ours.accel, atol=40 * eps * 10.0)
    np.testing.assert_allclose(w, ours.gyro, atol=40 * eps * (1.0 + np.abs(g_raw).max()))
