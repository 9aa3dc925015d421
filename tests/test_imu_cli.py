"""``gyrocal imu`` from end to end: simulate a hand session, calibrate both sensors, apply, export.

References: the truth sidecar of ``gyrocal simulate --protocol multi-position`` (independent of the
fit), imucal's own loader and correction for the imucal export, and the C library for the header.
"""

import ctypes
import json

import numpy as np
import pytest
from cli_runner import invoke, refused

from gyrocal import firmware
from gyrocal.io import read_recording
from gyrocal.results.files import load


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    """A simulated 20-pose session (deg/s, m/s^2) and its calibration file."""
    d = tmp_path_factory.mktemp("imu")
    rec = d / "hand.csv"
    code, out, err = invoke("simulate", "--protocol", "multi-position", "-o", rec, "--poses", "20", "--still", "2.5",
                            "--sample-rate", "100", "--noise", "0.002", "--misalignment", "1", "--k", "1.01,0.99,1.02",
                            "--b", "0.01,-0.02,0.005", "--seed", "5")
    assert code == 0, err
    cal = d / "imu.json"
    code, out, err = invoke("imu", rec, "--units", "deg/s", "--accel-units", "m/s^2", "-o", cal, "--plot",
                            d / "poses.png")
    assert code == 0, err
    return rec, cal, out, d


def test_prints_both_sensors_and_the_poses(session):
    _, _, out, d = session
    assert "20 still poses detected (20 distinct orientations), a multi-position session" in out
    assert "accelerometer: triangular model" in out and "gyro: affine model" in out
    assert "turns between poses: 19" in out
    assert (d / "poses.png").stat().st_size > 10_000


def test_file_recovers_the_simulated_truth_within_its_uncertainty(session):
    """Reference: the truth sidecar. Both sensors' canonical corrections, entry by entry, within 4.5 sigma."""
    rec, cal_path, _, _ = session
    truth = json.loads(rec.with_name("hand.truth.json").read_text())
    cal = load(cal_path)
    part = cal.accelerometer
    acc = np.array(part["parameters"]["values"])
    names = part["parameters"]["names"]
    true_a, true_o = np.array(truth["accelerometer"]["matrix"]), np.array(truth["accelerometer"]["offset"])
    want = [true_a["xyz".index(n[2]), "xyz".index(n[3])] if n.startswith("A_") else true_o["xyz".index(n[2])]
            for n in names]
    std = np.array([part["std"][n] for n in names])
    assert np.all(np.abs(acc - want) < 4.5 * std)
    # gyro: w = matrix (raw - offset) in rad/s internally; the file's K = matrix^-1 (the full-temperature-range
    # method's eq. 12) and its std are in the Kg order
    true_k = np.linalg.inv(np.array(truth["gyro_correction"]["matrix"]))
    kg = np.array(cal.model.kg)
    from gyrocal.models import KG_INDEX

    want_kg = np.concatenate([[true_k[r, c] for r, c in KG_INDEX], truth["gyro_correction"]["offset"]])
    assert np.all(np.abs(kg - want_kg) < 4.5 * cal.std)


def test_apply_corrects_accelerometer_and_gyro_by_default(session, tmp_path):
    """Reference: at rest the corrected specific force has the local gravity's size (to its noise)."""
    rec, cal_path, _, _ = session
    out = tmp_path / "corrected.csv"
    code, stdout, err = invoke("apply", cal_path, rec, "-o", out)
    assert code == 0, err
    corrected = read_recording(out, units="deg/s", accel_units="m/s^2")
    truth = json.loads(rec.with_name("hand.truth.json").read_text())
    a, b = truth["still"][3]
    norm = np.linalg.norm(corrected.accel[a + 30:b - 30], axis=1).mean()
    assert abs(norm - 9.80665) < 0.01  # pose mean of ~200 samples of 0.02 m/s^2 noise, plus 1e-3 calibration
    assert np.abs(np.degrees(corrected.gyro[a + 30:b - 30]).mean(axis=0)).max() < 0.02  # bias removed


def test_imucal_export_loads_in_imucal_and_corrects_the_same(session, tmp_path):
    """Reference: imucal's own loader and correction (CalibrationInfo.from_json_file, calibrate)."""
    from imucal import CalibrationInfo

    rec, cal_path, _, _ = session
    out = tmp_path / "imucal.json"
    code, _, err = invoke("export", cal_path, "--format", "imucal", "-o", out)
    assert code == 0, err
    info = CalibrationInfo.from_json_file(out)
    data = read_recording(rec, units="deg/s", accel_units="m/s^2")
    acc, gyr = info.calibrate(data.accel, np.degrees(data.gyro), "m/s^2", "deg/s")
    ours = load(cal_path).apply(data)
    np.testing.assert_allclose(acc, ours.accel, atol=1e-10)
    np.testing.assert_allclose(gyr, np.degrees(ours.gyro), atol=1e-9)


def test_yaml_export_carries_the_accelerometer(session, tmp_path):
    import yaml

    _, cal_path, _, _ = session
    code, out, err = invoke("export", cal_path, "--format", "yaml", "-o", tmp_path / "imu.yaml")
    assert code == 0, err
    doc = yaml.safe_load((tmp_path / "imu.yaml").read_text())
    assert doc["accelerometer"]["correction"]["matrix"] == load(cal_path).accelerometer.to_document()["correction"][
        "matrix"]


def test_c_header_imu_table_matches_python(session, tmp_path):
    """Reference: Python's Calibration.apply; the C library reads the exported header (float32)."""
    rec, cal_path, _, _ = session
    cal = load(cal_path)
    header = tmp_path / "imu_cal.h"
    header.write_text(cal.c_header())
    src = tmp_path / "driver.c"
    src.write_text('#include "imu_cal.h"\nint drive(const float g[3], const float a[3], float w[3], float f[3])\n'
                   "{ return gyrocal_imu_correct(&GYROCAL_IMU, g, a, w, f); }\n")
    dll = firmware.load_library(tmp_path / "build", extra_sources=[src], include_dirs=[tmp_path]).dll
    data = read_recording(rec, units="deg/s", accel_units="m/s^2")
    g_raw = np.ascontiguousarray(np.degrees(data.gyro[::97]), dtype=np.float32)
    a_raw = np.ascontiguousarray(data.accel[::97], dtype=np.float32)
    w, f = np.empty_like(g_raw), np.empty_like(a_raw)
    ptr = ctypes.POINTER(ctypes.c_float)
    for i in range(len(g_raw)):
        assert dll.drive(*(x[i].ctypes.data_as(ptr) for x in (g_raw, a_raw, w, f))) == 0
    ours = cal.apply(data)
    eps = np.finfo(np.float32).eps
    # float32: a few roundings of terms the size of the readings and offsets
    np.testing.assert_allclose(f, ours.accel[::97], atol=40 * eps * 10.0)
    np.testing.assert_allclose(w, np.degrees(ours.gyro[::97]), atol=40 * eps * 200.0)


def test_ferraris_session_with_imucal_section_list(tmp_path):
    """imucal's example (six faces and three turns): the accelerometer takes the box's frame."""
    from importlib import resources

    data = resources.files("gyrocal") / "data" / "imucal_ferraris"
    out = tmp_path / "ferraris.json"
    code, stdout, err = invoke("imu", data / "example_ferraris_session.csv", "--columns",
                               "gx=gyr_x,gy=gyr_y,gz=gyr_z,ax=acc_x,ay=acc_y,az=acc_z", "--sample-rate", "102.4",
                               "--units", "deg/s", "--accel-units", "m/s^2", "--gravity", "9.81", "--windows",
                               data / "example_ferraris_session_list.json", "-o", out)
    assert code == 0, err
    assert "6 still poses from --windows (6 distinct orientations), a ferraris session" in stdout
    cal = load(out)
    assert cal.method == "ferraris" and cal.accelerometer["model"] == "affine"
    assert "warning: accelerometer fit: residuals are" in err  # hand-placed faces: it says so


def test_refusals_are_one_line(tmp_path):
    code, _, err = invoke("simulate", "--protocol", "multi-position", "-o", tmp_path / "few.csv", "--poses", "4",
                          "--sample-rate", "50", "--noise", "0.002")
    assert code == 0, err
    line = refused("imu", tmp_path / "few.csv", "--units", "deg/s", "--accel-units", "m/s^2")
    assert "at least 6 distinct orientations" in line and "2 more orientation" in line
    line = refused("imu", tmp_path / "few.csv", "--units", "deg/s")
    assert "--accel-units is required" in line
    gyro_only = tmp_path / "gyro.csv"
    gyro_only.write_text("t,gx,gy,gz\n" + "".join(f"{i / 100},0.1,0.2,0.3\n" for i in range(500)))
    line = refused("imu", gyro_only, "--units", "deg/s", "--accel-units", "m/s^2")
    assert "accelerometer" in line


def test_raw_counts_with_an_unsigned_offset_metadata_lines_and_no_header(tmp_path):
    """A logger's file: three metadata lines, whitespace columns without names, raw unsigned 16-bit counts
    around 32768 (131 LSB per deg/s, 16384 LSB per g). Reference: those sensitivities, which the fit does not
    know and reports back."""
    from gyrocal.models import Affine
    from gyrocal.simulation.gyro import VirtualGyro
    from gyrocal.simulation.multiposition import MultiPositionProtocol, VirtualImu, simulate_multi_position

    rng = np.random.default_rng(12)
    imu = VirtualImu(VirtualGyro(Affine(np.eye(3), np.radians([0.3, -0.2, 0.1])), noise_std=np.radians(0.05)),
                     accel_noise_std=0.02)
    s = simulate_multi_position(imu, MultiPositionProtocol(poses=16, static_duration=(2.0, 3.0), uneven_steps=0.01),
                                rng=rng)
    g = np.clip(np.round(np.degrees(s.gyro) * 131.0 + 32768), 0, 65535).astype(int)
    a = np.clip(np.round(s.accel / 9.80665 * 16384.0 + 32768), 0, 65535).astype(int)
    path = tmp_path / "logger.txt"
    lines = ["# logger v1.2", "# board MPU-6050", "# 100 Hz"]
    lines += [f"{t:.4f} " + " ".join(str(v) for v in (*gi, *ai)) for t, gi, ai in zip(s.t, g, a)]
    path.write_text("\n".join(lines) + "\n")
    out = tmp_path / "cal.json"
    code, stdout, err = invoke("imu", path, "--skip-rows", "3", "--columns", "t=1,gx=2,gy=3,gz=4,ax=5,ay=6,az=7",
                               "--units", "counts", "--accel-units", "counts", "-o", out)
    assert code == 0, err
    assert "nearest setting: ±250 °/s (131 LSB)" in stdout and "nearest setting: ±2 g (16384 LSB)" in stdout
    cal = load(out)
    # gyro: rad/s per count; the truth is 1/131 deg/s per count on every axis
    k = np.diag(cal.model.matrix)  # the affine model's K^-1 [rad/s per count]
    std_k = cal.std[:3] * k**2  # Kxx, Kyy, Kzz first in the Kg order; d(1/K) = -dK / K^2
    assert np.all(np.abs(k - np.radians(1 / 131.0)) < 4.5 * std_k)
    offset = np.array(cal.accelerometer["correction"]["offset"])
    assert np.all(np.abs(offset - 32768) < 4.5 * np.array([cal.accelerometer["std"][f"o_{c}"] for c in "xyz"]))


def test_accelerometer_in_a_log_of_its_own(session, tmp_path):
    """imu_tk's layout: gyro and accelerometer in two headerless files of 'time x y z'. Reference: the same
    session with both sensors in one file gives the same calibration (to rounding of the written digits)."""
    rec, cal_path, _, _ = session
    data = read_recording(rec, units="deg/s", accel_units="m/s^2")
    gyro_file, acc_file = tmp_path / "gyro.mat", tmp_path / "acc.mat"
    gyro_file.write_text("".join(f"  {t:.6f}  {x:.9f}  {y:.9f}  {z:.9f}\n" for t, (x, y, z) in
                                 zip(data.t, np.degrees(data.gyro))))
    acc_file.write_text("".join(f"  {t:.6f}  {x:.9f}  {y:.9f}  {z:.9f}\n" for t, (x, y, z) in zip(data.t, data.accel)))
    out = tmp_path / "two.json"
    code, _, err = invoke("imu", gyro_file, "--columns", "t=1,gx=2,gy=3,gz=4", "--units", "deg/s", "--accel-log",
                          acc_file, "--accel-columns", "t=1,ax=2,ay=3,az=4", "--accel-units", "m/s^2", "-o", out)
    assert code == 0, err
    one, two = load(cal_path), load(out)
    np.testing.assert_allclose(two.correction[0], one.correction[0], atol=1e-6)
    np.testing.assert_allclose(two.accelerometer["correction"]["matrix"], one.accelerometer["correction"]["matrix"],
                               atol=1e-6)
    line = refused("imu", gyro_file, "--columns", "t=1,gx=2,gy=3,gz=4", "--units", "deg/s", "--accel-units",
                   "m/s^2", "--accel-columns", "t=1,ax=2,ay=3,az=4")
    assert "--accel-columns is for --accel-log" in line


def test_accelerometer_log_on_other_stamps_is_interpolated_onto_the_gyro(tmp_path):
    """Reference: a linear signal, which linear interpolation reproduces exactly; logs that barely overlap are
    refused."""
    from gyrocal.errors import InputError
    from gyrocal.io import attach_accelerometer
    from gyrocal.recording import Recording

    t = np.arange(1000) / 100.0
    rec = Recording(t=t, gyro=np.zeros((1000, 3)))
    ta = t[:900] + 0.005
    acc = tmp_path / "acc.txt"
    acc.write_text("".join(f"{x:.4f} {1 + x:.6f} {2 * x:.6f} {0.5:.6f}\n" for x in ta))
    joined = attach_accelerometer(rec, acc, accel_units="g", columns="t=1,ax=2,ay=3,az=4", gravity=9.8)
    assert joined.t[0] >= ta[0] and joined.t[-1] <= ta[-1] and len(joined) == 899
    np.testing.assert_allclose(joined.accel[:, 0], 9.8 * (1 + joined.t), atol=1e-9)
    np.testing.assert_allclose(joined.accel[:, 1], 9.8 * 2 * joined.t, atol=1e-9)
    acc.write_text("".join(f"{x:.4f} 0 0 1\n" for x in ta[:300]))
    with pytest.raises(InputError, match="share less than half the session"):
        attach_accelerometer(rec, acc, accel_units="g", columns="t=1,ax=2,ay=3,az=4")


def test_a_wrong_declared_unit_is_pointed_out(session, tmp_path):
    """deg/s data declared as rad/s and m/s^2 data declared as g: the fit still closes, with scale factors near
    1/57.3 and 1/9.8; the result is refused (exit 2, nothing written) naming each unit, as calibrate refuses it,
    and written with the warning in the file under --accept-implausible."""
    rec, _, _, _ = session
    out = tmp_path / "wrong.json"
    line = refused("imu", rec, "--units", "rad/s", "--no-unit-check", "--accel-units", "g", "-o", out)
    assert "implausible result, nothing written" in line and "--accept-implausible" in line and not out.exists()
    assert "is --units rad/s right? (a factor 1/57.3: data in deg/s read as rad/s)" in line
    assert "is --accel-units g right? (a factor 1/9.81: data in m/s^2 read as g)" in line
    code, _, err = invoke("imu", rec, "--units", "rad/s", "--no-unit-check", "--accel-units", "g", "-o", out,
                          "--accept-implausible")
    assert code == 0, err
    assert "is --units rad/s right? (a factor 1/57.3: data in deg/s read as rad/s)" in err
    assert any(w.startswith("written with --accept-implausible: ") and "a factor 1/57.3" in w
               for w in json.loads(out.read_text())["fit"]["warnings"])
    # the units right and an output unit of its own: the correction is 57.3 deg/s per rad/s, and no warning
    data = read_recording(rec, units="deg/s", accel_units="m/s^2")
    as_rad = tmp_path / "rad.csv"
    as_rad.write_text("t,gx,gy,gz,ax,ay,az\n" + "".join(
        f"{t:.6f},{x:.9f},{y:.9f},{z:.9f},{a:.6f},{b:.6f},{c:.6f}\n" for t, (x, y, z), (a, b, c) in
        zip(data.t, data.gyro, data.accel)))
    code, _, err = invoke("imu", as_rad, "--units", "rad/s", "--output-units", "deg/s", "--accel-units", "m/s^2")
    assert code == 0, err
    assert "right?" not in err


def test_a_model_taken_with_too_few_poses_to_check_it_warns(tmp_path):
    """8 poses: the accelerometer falls back to scale and offset with 2 spare equations, which cannot show the
    non-orthogonality it leaves out (the simulator's truth has it): a warning says so and how to fix it; 20 poses
    check the full model and do not warn. Reference: the model choice the fit prints."""
    for poses, warned in ((8, True), (20, False)):
        rec = tmp_path / f"p{poses}.csv"
        assert invoke("simulate", "--protocol", "multi-position", "-o", rec, "--poses", str(poses), "--sample-rate",
                      "100", "--seed", "2", "--force")[0] == 0
        code, out, err = invoke("imu", rec, "--units", "deg/s", "--accel-units", "m/s^2")
        assert code == 0, err
        assert ("accelerometer model was fitted with too few spare equations" in err) == warned
        assert ("too few to check it" in out) == warned


def test_g_sensitivity_flag_and_its_place_in_the_file(session, tmp_path):
    """The simulated gyro has no g-sensitivity: the fitted one is zero within its 1-sigma (4.5 sigma), and the
    file carries it where apply and the exports find it."""
    rec, _, _, _ = session
    out = tmp_path / "g.json"
    code, stdout, err = invoke("imu", rec, "--units", "deg/s", "--accel-units", "m/s^2", "--g-sensitivity", "-o", out)
    assert code == 0, err
    assert "g-sensitivity: fitted from the still poses" in stdout
    part = load(out).accelerometer["gyro_g_sensitivity"]
    g, std = np.array(part["matrix"]), np.array(part["std"])
    assert part["units"] == "deg/s per m/s^2" and np.all(np.abs(g) < 4.5 * std)


def test_imucal_export_needs_both_sensors(tmp_path):
    code, _, err = invoke("calibrate", "--example", "-o", tmp_path / "gyro.json")
    assert code == 0, err
    line = refused("export", tmp_path / "gyro.json", "--format", "imucal", "-o", tmp_path / "x.json")
    assert "imucal's format holds the accelerometer and the gyro" in line and "gyrocal imu" in line


def test_a_simulated_hand_session_with_receive_stamps_and_gaps_keeps_its_accelerometer(tmp_path):
    """``simulate --protocol multi-position --stamps receive --gaps 2``: the log a PC's USB reader makes, lost
    packets included, still has ax ay az (they were dropped before), and ``gyrocal imu`` calibrates it. Reference:
    the rows the gyro keeps are the accelerometer's (same count)."""
    rec = tmp_path / "recv.csv"
    code, _, err = invoke("simulate", "--protocol", "multi-position", "-o", rec, "--sample-rate", "100", "--seed", "3",
                          "--stamps", "receive", "--late-per-minute", "5", "--gaps", "2")
    assert code == 0, err
    data = read_recording(rec, units="deg/s", accel_units="m/s^2")
    assert data.accel is not None and len(data.accel) == len(data.gyro)
    code, _, err = invoke("imu", rec, "--units", "deg/s", "--accel-units", "m/s^2")
    assert code == 0, err


def test_apply_an_imu_calibration_to_a_gyro_only_log(session, tmp_path):
    """A flight log of the same gyro without accelerometer columns: the calibration has no g-sensitivity, so its
    gyro correction needs no accelerometer; apply corrects the gyro and says the accelerometer part is unused.
    Reference: the gyro columns of the same log applied with its accelerometer (identical)."""
    rec, cal, _, _ = session
    lines = rec.read_text().splitlines()
    head = next(i for i, ln in enumerate(lines) if not ln.startswith("#"))
    gyro_only = tmp_path / "gyro.csv"
    gyro_only.write_text("\n".join(",".join(ln.split(",")[:4]) for ln in lines[head:]) + "\n")
    code, out, err = invoke("apply", cal, gyro_only, "-o", tmp_path / "a.csv")
    assert code == 0, err
    assert "has no ax ay az: the gyro is corrected" in out
    assert invoke("apply", cal, rec, "-o", tmp_path / "b.csv")[0] == 0
    a = np.loadtxt(tmp_path / "a.csv", delimiter=",", comments="#", skiprows=2)[:, 1:4]
    b = np.loadtxt(tmp_path / "b.csv", delimiter=",", comments="#", skiprows=2)[:, 1:4]
    np.testing.assert_array_equal(a, b)
    # asked for explicitly, the accelerometer must be there
    assert "no accelerometer column" in refused("apply", cal, gyro_only, "-o", tmp_path / "c.csv", "--accel-units",
                                                "m/s^2")


def test_a_headerless_imu_log_is_told_the_accelerometer_columns_too(session, tmp_path):
    """The refusal of a headerless 7-column log names ax ay az as well, so the mapping it suggests reads it."""
    rec = session[0]
    lines = [ln for ln in rec.read_text().splitlines() if not ln.startswith("#")][1:]
    bare = tmp_path / "bare.txt"
    bare.write_text("\n".join(ln.replace(",", " ") for ln in lines) + "\n")
    line = refused("imu", bare, "--units", "deg/s", "--accel-units", "m/s^2")
    assert "--columns t=1,gx=2,gy=3,gz=4,ax=5,ay=6,az=7" in line
    code, _, err = invoke("imu", bare, "--units", "deg/s", "--accel-units", "m/s^2", "--columns",
                          "t=1,gx=2,gy=3,gz=4,ax=5,ay=6,az=7")
    assert code == 0, err
