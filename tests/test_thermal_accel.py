"""The accelerometer's offset change against temperature from simulated warming logs, into PX4 and ArduPilot.

Independent references: the generator below (written here, sharing nothing with gyrocal's simulator):
a still board, gravity on z, accelerometer offsets that drift as a known cubic in temperature, white
noise, temperature read in whole degrees; the truth is that cubic's change from the reference
temperature. The firmware parameters are evaluated by the float32 models of ``firmware_models.py``,
written from the PX4 and ArduPilot sources. Tolerances are the fit's own reported 1-sigma.
"""

import math

import numpy as np
import pytest
from cli_runner import invoke, refused  # noqa: E402
from dataflash_writer import imu_log  # noqa: E402
from firmware_models import ardupilot_correct, parse_ardupilot, parse_px4, px4_offsets  # noqa: E402

from gyrocal.flight import ThermalBiasWarning, ardupilot_params, fit_thermal_bias, px4_params
from gyrocal.results.files import load

FS = 50.0
T0 = 25.0
#: Truth about T0 [m/s^2/degC^n]: a cubic on x (0.9 m/s^2, about 0.09 g, over the warm-up), a line on y,
#: a parabola on z; the constant is the offset at T0, which one orientation cannot tell from gravity.
OFFSET = np.array([[0.15, 0.02, -1e-4, 1e-6], [-0.3, -3e-3, 0.0, 0.0], [0.05, 0.0, 6e-5, 0.0]])
GRAVITY = np.array([0.0, 0.0, 9.80665])
NOISE = 0.02  # m/s^2 per sample


def offset(temp) -> np.ndarray:
    """The true accelerometer offsets (N, 3) [m/s^2] at temperatures (N,)."""
    d = np.atleast_1d(np.asarray(temp, float)) - T0
    return np.stack([sum(OFFSET[a, n] * d**n for n in range(4)) for a in range(3)], axis=1)


def warming_log(seed: int, duration: float = 1800.0, wander: float = 0.0, quantum: float = 1.0,
                noise: float = NOISE):
    """t, gyro [rad/s], accel [m/s^2] (white `noise` per sample), readings in steps of `quantum` degC, true temp."""
    rng = np.random.default_rng(seed)
    n = int(duration * FS)
    t = np.arange(n) / FS
    temp = 48.0 - 58.0 * np.exp(-t / 450.0)  # from -10 degC, powered in a freezer bag
    readings = np.round((temp + 0.1 * rng.standard_normal(n)) / quantum) * quantum
    gyro = 0.01 + 1e-4 * (temp - T0)[:, None] + 0.005 * rng.standard_normal((n, 3))
    accel = GRAVITY + offset(temp) + noise * rng.standard_normal((n, 3))
    if wander:  # a first-order Gauss-Markov wander of the offsets, 60 s correlation time
        phi = math.exp(-1 / (60.0 * FS))
        from scipy.signal import lfilter

        drive = wander * math.sqrt(1 - phi**2) * rng.standard_normal((n, 3))
        accel = accel + lfilter([1.0], [1.0, -phi], drive, axis=0)  # x[k] = phi x[k-1] + drive[k]
    return t, gyro, accel, readings, temp


def _change(temp, tref) -> np.ndarray:
    return offset(temp) - offset([tref])


def _z_scores(quantum: float, noise: float, seeds: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """(fit - truth) / reported sigma of the accelerometer change and of the gyro bias, per seed, at 4
    temperatures away from tref (where the change and its sigma are 0): arrays (seeds, 4, 3)."""
    za, zg = [], []
    for seed in range(seeds):
        _, gyro, accel, readings, _ = warming_log(100 + seed, quantum=quantum, noise=noise)
        tb = fit_thermal_bias(gyro, readings, FS, accel=accel)
        temps = np.linspace(tb.tmin, tb.tmax, 5)[[0, 1, 3, 4]]
        za.append((tb.accel.change_at(temps) - _change(temps, tb.tref)) / tb.accel.std_at(temps))
        zg.append((tb.bias_at(temps) - (0.01 + 1e-4 * (temps - T0))[:, None]) / tb.std_at(temps))
    return np.array(za), np.array(zg)


@pytest.mark.parametrize(("quantum", "noise"), [(0.01, NOISE), (1.0, NOISE), (1.0, NOISE / 4)])
def test_change_within_its_reported_sigma(quantum, noise):
    """RMS of (fit - truth) / reported sigma over 16 seeds x 3 axes within 1 +- 4 / sqrt(2 * 48), for the
    accelerometer change and for the gyro bias.

    Points of one curve are correlated, so the band is set for 48 independent draws. Readings in
    0.01 degC steps, and in whole degrees with the generator's noise and with a quarter of it: there a
    temperature course 0.02 degC off (crossing times from 0.5 s block medians) gave RMS z 1.9 on the
    accelerometer (2.5 on the steep x axis), the course's error against a block noise of 3e-4 m/s^2;
    with crossing times counted from the raw readings it is within the band."""
    za, zg = _z_scores(quantum, noise)
    for z in (za, zg):
        rms = math.sqrt(np.mean(np.square(z)))
        assert abs(rms - 1) < 4 / math.sqrt(96), rms


def test_orders_zero_at_tref_and_the_gyro_unchanged():
    """The truth's orders are chosen, the curve is 0 (with 0 sigma) at tref, and the gyro fit is the one
    without the accelerometer (one code path, each sensor on its own)."""
    _, gyro, accel, readings, _ = warming_log(7)
    tb = fit_thermal_bias(gyro, readings, FS, accel=accel)
    np.testing.assert_array_equal(tb.accel.orders, [3, 1, 2])
    assert tb.accel.tref == tb.tref and tb.accel.tmin == tb.tmin and tb.accel.tmax == tb.tmax
    assert tb.accel.change_at([tb.tref])[0].tolist() == [0.0, 0.0, 0.0]
    assert tb.accel.std_at([tb.tref])[0].tolist() == [0.0, 0.0, 0.0]
    np.testing.assert_allclose(tb.accel.noise_std, NOISE, rtol=0.02)
    alone = fit_thermal_bias(gyro, readings, FS)
    np.testing.assert_array_equal(alone.coefs, tb.coefs)
    np.testing.assert_array_equal(alone.covariance, tb.covariance)


def test_a_wandering_offset_widens_the_sigma():
    """With a Gauss-Markov wander (0.01 m/s^2, 60 s) the 1-sigma still covers the truth: |z| < 4 at 4
    temperatures on each axis of 3 seeds, and the noise model finds the wander (ar_var > 0)."""
    for seed in range(3):
        _, gyro, accel, readings, _ = warming_log(200 + seed, wander=0.01)
        with pytest.warns(ThermalBiasWarning, match="accelerometer axis .: the block residuals"):
            tb = fit_thermal_bias(gyro, readings, FS, accel=accel)
        temps = np.linspace(tb.tmin, tb.tmax, 5)[[0, 1, 3, 4]]
        z = (tb.accel.change_at(temps) - _change(temps, tb.tref)) / tb.accel.std_at(temps)
        assert np.all(np.abs(z) < 4), z
        assert all(m["ar_var"] > 0 for m in tb.accel.fit["noise_model"])


@pytest.fixture(scope="module")
def fitted():
    _, gyro, accel, readings, _ = warming_log(11)
    return fit_thermal_bias(gyro, readings, FS, accel=accel, source={"device_id": 2424842,
                                                                       "accel_device_id": 2424843})


TEMPS = np.linspace(-30.0, 70.0, 101)  # inside and beyond the fitted range: the firmware clips


def _clipped_change(tb, temps, t0) -> np.ndarray:
    return _change(np.clip(temps, tb.tmin, tb.tmax), t0)


def test_px4_tc_a_reproduces_the_true_change(fitted):
    """PX4's calc_thermal_offsets_3D (firmware_models.px4_offsets, float32) on the TC_A set gives the true
    offset change from TC_A0_TREF within 4 sigma of the fit (at T and at TREF) plus float32 rounding."""
    tb = fitted
    params = parse_px4(px4_params(tb, instance=0))
    assert params["TC_A_ENABLE"] == 1 and params["TC_A0_ID"] == 2424843 and params["TC_G0_ID"] == 2424842
    assert all(params[f"TC_A0_X0_{a}"] == 0.0 for a in range(3))  # zero at TREF, as PX4's own calibration
    assert params["TC_A0_TMIN"] == params["TC_G0_TMIN"] and params["TC_A0_TREF"] == params["TC_G0_TREF"]
    tref = params["TC_A0_TREF"]
    firmware = px4_offsets(params, 0, TEMPS, sensor="A")
    truth = _clipped_change(tb, TEMPS, tref)
    tol = 4 * (tb.accel.std_at(TEMPS) + tb.accel.std_at([tref])) + 1e-5
    assert np.all(np.abs(firmware - truth) < tol), np.max(np.abs(firmware - truth) / tol)


def test_ardupilot_acc_terms_reproduce_the_true_change(fitted):
    """ArduPilot's correct_accel then INS_ACCOFFS (firmware_models.ardupilot_correct, float32): with the
    offsets of an ordinary accelerometer calibration made at 30 degC (INS_ACC1_CALTEMP), the corrected
    reading at rest is gravity within 4 sigma of the fit's change at T and at 30 degC."""
    tb = fitted
    params = parse_ardupilot(ardupilot_params(tb, imu=1))
    assert "INS_ACCOFFS_X" not in params and params["INS_TCAL1_ENABLE"] == 1
    params.update({"INS_ACC1_CALTEMP": 30.0, **{f"INS_ACCOFFS_{ax}": float(offset([30.0])[0, a])
                                                for a, ax in enumerate("XYZ")}})
    raw = GRAVITY + offset(np.clip(TEMPS, tb.tmin, tb.tmax))  # the firmware clips T: compare where it does
    corrected = ardupilot_correct(params, 1, TEMPS, raw, sensor="ACC")
    tol = 4 * (tb.accel.std_at(TEMPS) + tb.accel.std_at([30.0])) + 1e-5
    assert np.all(np.abs(corrected - GRAVITY) < tol), np.max(np.abs(corrected - GRAVITY) / tol)


def test_px4_needs_the_accelerometers_own_id(fitted):
    tb = fitted
    bare = type(tb)(tb.coefs, tb.covariance, tb.orders, tb.tref, tb.tmin, tb.tmax, tb.cv_rms, tb.residual_rms,
                    tb.noise_std, tb.sample_rate, tb.duration, source={"device_id": 1}, accel=tb.accel)
    with pytest.raises(Exception, match="CAL_ACCn_ID"):
        px4_params(bare)
    assert parse_px4(px4_params(bare, accel_device_id=9))["TC_A0_ID"] == 9


@pytest.fixture(scope="module")
def warm_csv(tmp_path_factory):
    """The generator's log as a CSV: time, gyro [rad/s], accelerometer [g], whole-degree temperature."""
    t, gyro, accel, readings, _ = warming_log(21, duration=1500.0)
    path = tmp_path_factory.mktemp("accel") / "warm.csv"
    np.savetxt(path, np.column_stack([t, gyro, accel / 9.80665, readings]), delimiter=",",
               header="t,gx,gy,gz,ax,ay,az,temp", comments="", fmt="%.7g")
    return path


def test_cli_csv_then_px4_and_ardupilot(warm_csv, tmp_path):
    """thermal-bias --accel-units g, then both exports; the PX4 file's TC_A set (firmware_models) holds the
    generator's truth within 4 sigma."""
    out = tmp_path / "tb.json"
    code, text, err = invoke("thermal-bias", warm_csv, "--units", "rad/s", "--accel-units", "g", "-o", out)
    assert code == 0, err
    assert "change of the offsets from" in text and "zero there" in text
    tb = load(out)
    assert tb.accel is not None and tb.source["accel_units"] == "g"
    assert "--accel-device-id" in refused("export", out, "--format", "px4", "-o", tmp_path / "a.params",
                                          "--device-id", "5")
    code, _, err = invoke("export", out, "--format", "px4", "-o", tmp_path / "a.params", "--device-id", "5",
                          "--accel-device-id", "6")
    assert code == 0, err
    params = parse_px4((tmp_path / "a.params").read_text())
    temps = np.linspace(tb.tmin, tb.tmax, 7)
    err_px4 = px4_offsets(params, 0, temps, sensor="A") - _change(temps, params["TC_A0_TREF"])
    assert np.all(np.abs(err_px4) < 4 * (tb.accel.std_at(temps) + tb.accel.std_at([tb.tref])) + 1e-5), err_px4
    assert invoke("export", out, "--format", "ardupilot", "-o", tmp_path / "a.parm")[0] == 0
    assert parse_ardupilot((tmp_path / "a.parm").read_text())["INS_TCAL1_ACC1_X"] != 0


def test_cli_refusals(warm_csv, tmp_path):
    gyro_only = tmp_path / "gyro.csv"
    lines = warm_csv.read_text().splitlines()
    gyro_only.write_text("\n".join(",".join(row.split(",")[:4] + row.split(",")[7:]) for row in lines) + "\n")
    assert "no accelerometer" in refused("thermal-bias", gyro_only, "--units", "rad/s", "--accel-units", "m/s^2")
    line = refused("thermal-bias", warm_csv, "--units", "rad/s", "--accel-units", "furlong/s^2")
    assert "furlong" in line and "--accel-units" in line


def test_cli_dataflash(tmp_path):
    """An ArduPilot log (IMU messages at 25 Hz) whose accelerometer was logged corrected by an older TCAL
    set, offsets and scale (firmware_models.ardupilot_correct, sensor ACC): the reader undoes them and the
    change holds the generator's truth within 4 sigma; g is refused for a flight log (ArduPilot logs m/s^2)."""
    t, gyro, accel, _, temp = warming_log(31, duration=1200.0)
    keep = slice(None, None, 2)
    old = {"INS_TCAL1_ENABLE": 1.0, "INS_TCAL1_TMIN": 0.0, "INS_TCAL1_TMAX": 40.0, "INS_ACC1_CALTEMP": 20.0,
           **{f"INS_TCAL1_{s}{k}_{ax}": 0.0 for s in ("ACC", "GYR") for k in (1, 2, 3) for ax in "XYZ"},
           "INS_TCAL1_ACC1_X": 15000.0, "INS_TCAL1_ACC2_Z": 40.0, "INS_ACCOFFS_X": 0.1, "INS_ACCOFFS_Y": -0.2,
           "INS_ACCOFFS_Z": 0.05, "INS_ACCSCAL_X": 1.01, "INS_ACCSCAL_Y": 0.99, "INS_ACCSCAL_Z": 1.0}
    logged = ardupilot_correct(old, 1, temp[keep], accel[keep], sensor="ACC").astype(float)
    w = imu_log()
    for name, value in old.items():
        w.write("PARM", 1000, name, value)
    for k, (g, a, tt) in enumerate(zip(gyro[keep], logged, temp[keep])):
        w.write("IMU", 10_000 + 40_000 * k, 0, *g, *a, 0, 0, float(tt), 1, 1, 25, 25)
    log = tmp_path / "00000007.BIN"
    log.write_bytes(bytes(w))
    assert "m/s^2" in refused("thermal-bias", log, "--accel-units", "g")
    code, _, err = invoke("thermal-bias", log, "--accel-units", "m/s^2", "-o", tmp_path / "b.json")
    assert code == 0, err
    tb = load(tmp_path / "b.json")
    temps = np.linspace(tb.tmin, tb.tmax, 5)
    diff = tb.accel.change_at(temps) - _change(temps, tb.tref)
    assert np.all(np.abs(diff) < 4 * tb.accel.std_at(temps) + 1e-9), diff
