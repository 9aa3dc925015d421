"""Honest limits of an IMU chamber calibration: hysteresis, a lagging temperature sensor, too few poses, and
``thermal-report`` on an IMU thermal file.

Reference: the simulator's own truth (:mod:`gyrocal.simulation.chamber`: the board's cubics, the cooling
branch's offsets moved by a known hysteresis; :mod:`gyrocal.simulation.sensor_lag`: a known first-order lag
on the temperature column). RMS z bands count, as in ``test_imu_thermal_sim``, 5 independent z values per
parameter and board (the model between the points rests on the 5 points): 1 +- 4 / sqrt(2 m).
"""

import json

import numpy as np
import pytest
from cli_runner import invoke

from gyrocal.imu.thermal import calibrate_imu_thermal
from gyrocal.imu.thermal_eval import evaluate_imu_thermal
from gyrocal.io import write_csv
from gyrocal.models import ScaleBias
from gyrocal.simulation.chamber import chamber_session, random_thermal_imu
from gyrocal.simulation.sensor_lag import lagged_temperature
from gyrocal.units import STANDARD_GRAVITY

TEMPS = np.linspace(-25.0, 50.0, 5)
MID = (TEMPS[1:] + TEMPS[:-1]) / 2
HEAT_COOL = np.r_[TEMPS, TEMPS[::-1][1:-1]]  # -25 .. 50 heating, then 31.25 .. -6.25 cooling
_LOWER = np.r_[np.nonzero(np.tril(np.ones((3, 3), bool)).ravel())[0], 9, 10, 11]  # the 9-parameter model's
KW = {"gyro_kw": {"noise_std": np.radians(0.1)}, "poses": 12, "still": 2.0, "accel_noise_std": 0.02,
      "sample_rate": 100.0, "temp_noise": 0.05, "soak": 900.0}


def _board(seed, hysteresis=0.0):
    rng = np.random.default_rng(seed)
    return random_thermal_imu(ScaleBias((1.0, 1.0, 1.0), (0.0, 0.0, 0.0)), rng, hysteresis=hysteresis), rng


def _z(fit, truth, cooling=False):
    """The smooth accelerometer model's error over its 1-sigma between the points (4, 9), against the truth."""
    est, sigma = fit.accel.smooth_at(MID)
    return (est - np.array([truth.params(t, cooling)[0][_LOWER] for t in MID])) / sigma, sigma


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


def _band(m):
    return 4 / np.sqrt(2 * m)


@pytest.fixture(scope="module")
def hysteresis_fits():
    """3 boards with 0.05 m/s^2 hysteresis on each offset, visited heating -25..50 and cooling back to -6.25."""
    out = []
    for seed in range(3):
        truth, rng = _board(seed, 0.05)
        rec, _ = chamber_session(truth, HEAT_COOL, rng=rng, **KW)
        out.append((truth, calibrate_imu_thermal(rec.t, rec.gyro, rec.accel, rec.temp)))
    return out


def test_hysteresis_is_measured_and_flagged_with_its_size(hysteresis_fits):
    """The measured cooling-minus-heating offsets against the simulated hysteresis, over their 1-sigma."""
    z = []
    for truth, fit in hysteresis_fits:
        h = fit.limits.accelerometer
        assert h.flagged and h.dof == 9 * 3
        z.append((h.difference[-3:] - truth.hysteresis) / h.std[-3:])
        doc = fit.to_dict()["limits"]
        assert "hysteresis: accelerometer" in doc["flags"]
        assert doc["hysteresis"]["accelerometer"]["flag"] == "hysteresis"
        assert any("hysteresis" in n and "mid-branch" in n for n in fit.notes)
    rms = _rms(z)
    print(f"hysteresis difference: RMS z against the truth {rms:.2f} ({np.size(z)} values)")
    assert abs(rms - 1) < 4 / np.sqrt(2 * np.size(z))


def test_with_hysteresis_the_model_holds_both_branches_within_its_sigma(hysteresis_fits):
    """Between the points, on the heating and on the cooling branch of the truth: RMS z in 1 +- band; without
    the half-width in the 1-sigma the same estimates would be many sigma off."""
    for cooling in (False, True):
        zs, bare = [], []
        for truth, fit in hysteresis_fits:
            z, sigma = _z(fit, truth, cooling)
            zs.append(z)
            extra = fit.limits.accelerometer.extra_variance
            bare.append(z * sigma / np.sqrt(np.maximum(sigma**2 - extra, 1e-30)))
        rms, m = _rms(zs), len(hysteresis_fits) * len(_LOWER) * len(TEMPS)
        print(f"{'cooling' if cooling else 'heating'} branch: RMS z {rms:.2f}; without the half-width {_rms(bare):.1f}")
        assert abs(rms - 1) < _band(m)
        assert _rms(bare) > 3


def test_with_hysteresis_the_corrected_accelerometer_holds_its_sigma_on_both_branches(hysteresis_fits):
    """Test logs of each board between the points, reached heating (from -40 degC) and cooling (from 60 degC):
    every still pose's |f| - g under the smooth model over its 1-sigma. Reference: the simulated truth sets
    the readings; z values at one temperature share the model's error, so the band counts 3 per temperature
    and board: 1 +- 4 / sqrt(2 m)."""
    rng = np.random.default_rng(99)
    for start, temps in ((-40.0, MID), (60.0, MID[::-1])):
        zs = []
        for truth, fit in hysteresis_fits:
            test, points = chamber_session(truth, np.r_[start, temps], rng=rng, **KW)
            keep = slice(points[1]["samples"][0], None)  # the first point only sets the branch
            ev = evaluate_imu_thermal(fit.to_dict(), test.t[keep], test.gyro[keep], test.accel[keep],
                                      test.temp[keep], gravity=STANDARD_GRAVITY)
            zs.append(ev.accel_z)
        rms, m = _rms(np.concatenate(zs)), 3 * len(MID) * len(hysteresis_fits)
        print(f"test log from {start:g} degC: RMS z of |f| - g {rms:.2f}")
        assert abs(rms - 1) < _band(m)


def test_branches_that_agree_are_not_flagged():
    """No hysteresis in the truth: the chi-square of the branches' difference is that of noise (p > 1e-3); and a
    temperature sensor that follows the die is not flagged as moving."""
    truth, rng = _board(11)
    rec, _ = chamber_session(truth, [0.0, 40.0, 0.0, -20.0], rng=rng, **KW)
    fit = calibrate_imu_thermal(rec.t, rec.gyro, rec.accel, rec.temp)
    assert fit.limits.accelerometer is not None and not fit.limits.accelerometer.flagged
    assert not any(d.flagged for d in fit.limits.drifts)
    assert fit.to_dict()["limits"]["flags"] == []


def test_a_lagging_temperature_sensor_is_flagged_and_its_lag_corrected():
    """A first-order lag of 300 s on the temperature column: each later plateau's drift flagged; the model between
    the points is many sigma off without the lag, and back within its 1-sigma with the lag given."""
    raw, fixed = [], []
    for seed in range(2):
        truth, rng = _board(20 + seed)
        rec, points = chamber_session(truth, TEMPS, rng=rng, **KW)
        temp = lagged_temperature(rec.t, rec.temp, points, 300.0)
        lagged = calibrate_imu_thermal(rec.t, rec.gyro, rec.accel, temp)
        assert [d.flagged for d in lagged.limits.drifts] == [False, True, True, True, True]
        assert "temperature moving during plateaus" in lagged.to_dict()["limits"]["flags"]
        raw.append(_z(lagged, truth)[0])
        fixed.append(_z(calibrate_imu_thermal(rec.t, rec.gyro, rec.accel, temp, sensor_lag=300.0), truth)[0])
    m = len(raw) * len(_LOWER) * len(TEMPS)
    print(f"lagging sensor: RMS z {_rms(raw):.2f} as read, {_rms(fixed):.2f} with the lag given")
    assert _rms(raw) > 3
    assert abs(_rms(fixed) - 1) < _band(m)


def _cut(rec, points, k, fraction):
    """The log with point `k`'s pose sequence cut to its first `fraction`."""
    a, b = points[k]["samples"]
    keep = np.ones(len(rec.t), bool)
    keep[a + int(fraction * (b - a)):b] = False
    return rec.t[keep], rec.gyro[keep], rec.accel[keep], rec.temp[keep]


def test_a_point_with_too_few_poses_is_left_out_with_a_note():
    """The middle point cut to its first 7 or 5 poses (the truth: a 9-parameter board at every point): the point
    is left out and said, the others keep the model they determine."""
    truth, rng = _board(3)
    rec, points = chamber_session(truth, TEMPS, rng=rng, **{**KW, "still": 5.0})
    for fraction, says in ((0.6, "determine only the scale-bias accelerometer"), (0.4, "determine no accelerometer")):
        fit = calibrate_imu_thermal(*_cut(rec, points, 2, fraction))
        assert fit.accel_model == "triangular"
        assert [round(p.temperature) for p in fit.points] == [-25, -6, 31, 50]
        assert any("12.5 degC" in n and "left out" in n and says in n for n in fit.notes), fit.notes
        z, _ = _z(fit, truth)
        assert _rms(z) < 3  # one board, four points: the model still holds its truth


def _sim(path, temps, seed):
    code, _, err = invoke("simulate", "--protocol", "multi-position", "--temp-points", ",".join(f"{t:g}" for t in temps),
                          "--temp-soak", "900", "--temp-noise", "0.05", "--poses", "12", "--still", "2",
                          "--sample-rate", "100", "--noise", "0.005", "--seed", str(seed), "-o", path)
    assert code == 0, err
    return json.loads(path.with_suffix(".truth.json").read_text())["imu_thermal"]


def _truth_params(doc, temps):
    x = (np.asarray(temps) - doc["ref_temp_degC"]) / doc["scale_degC"]
    return np.vander(x, 4, increasing=True) @ np.asarray(doc["accelerometer"]["coefs"]).T


def test_thermal_report_on_an_imu_file_beats_the_baseline_by_the_factor_the_truth_implies(tmp_path):
    """A board calibrated at 5 points and tested (same seed: same board) at the 4 temperatures between them.
    Reference: the sidecar's truth gives each test pose's true specific force and the baseline's error there
    (the point at 31.25 degC applied at every temperature): the report's baseline error matches it, and the
    smooth model's error matches its own 1-sigma."""
    truth = _sim(tmp_path / "cal.csv", TEMPS, 4)
    _sim(tmp_path / "test.csv", MID, 4)
    code, _, err = invoke("imu", tmp_path / "cal.csv", "--units", "deg/s", "--accel-units", "m/s^2", "-o",
                          tmp_path / "cal.json")
    assert code == 0, err
    code, out, err = invoke("thermal-report", tmp_path / "cal.json", tmp_path / "test.csv", "-o", tmp_path / "rep")
    assert code == 0, err
    assert "x baseline" in out and (tmp_path / "rep" / "summary.md").exists()
    poses = np.genfromtxt(tmp_path / "rep" / "poses.csv", delimiter=",", names=True)
    u = np.column_stack([poses["raw_ax"], poses["raw_ay"], poses["raw_az"]])
    p, ref = _truth_params(truth, poses["temperature"]), _truth_params(truth, [TEMPS[3]])[0]
    true_f = np.einsum("nij,nj->ni", p[:, :9].reshape(-1, 3, 3), u - p[:, 9:])
    implied = np.linalg.norm((u - ref[9:]) @ ref[:9].reshape(3, 3).T, axis=1) - np.linalg.norm(true_f, axis=1)
    assert np.sqrt(np.mean((poses["single_accel"] - implied) ** 2)) < 0.02 * _rms(implied)
    z = _rms(poses["smooth_accel_z"])
    sigma = np.abs(poses["smooth_accel"] / poses["smooth_accel_z"])
    factor, implied_factor = _rms(poses["single_accel"]) / _rms(poses["smooth_accel"]), _rms(implied) / _rms(sigma)
    print(f"thermal-report: smooth RMS z {z:.2f}; factor on the baseline {factor:.0f}, implied {implied_factor:.0f}")
    assert 0.5 < z < 2.0  # one board: its 9 parameters' errors are shared by every pose at one temperature
    assert 0.5 < factor / implied_factor < 2.0
    summary = np.genfromtxt(tmp_path / "rep" / "summary.csv", delimiter=",", names=True, dtype=None, encoding=None)
    assert summary["scheme"].tolist() == ["single", "lagrange", "smooth"]
    assert summary["accel_factor"][2] > 20


def test_imu_warns_of_a_lagging_sensor_and_temp_lag_moves_the_points_to_the_die(tmp_path):
    """The CLI on a simulated log whose temperature column lags the die by 300 s (sidecar truth: the die at the
    set points, the column 0.9 degC behind at the later points): the warning and the file's flag, and with
    --temp-lag 300 the points sit at the set points."""
    truth = _sim(tmp_path / "sim.csv", TEMPS, 6)
    data = np.genfromtxt(tmp_path / "sim.csv", delimiter=",", names=True, skip_header=1)
    cols = {k: data[k] for k in data.dtype.names}
    cols["temp"] = lagged_temperature(data["t"], data["temp"], truth["points"], 300.0)
    write_csv(tmp_path / "lag.csv", cols)
    code, out, err = invoke("imu", tmp_path / "lag.csv", "--units", "deg/s", "--accel-units", "m/s^2", "--temp-lag",
                            "300", "-o", tmp_path / "cal.json")
    assert code == 0, err
    assert "temperature still moving during the poses of 4 of 5 plateaus" in out + err
    assert "lag of 300 s" in out + err
    section = json.loads((tmp_path / "cal.json").read_text())["accelerometer"]["thermal"]
    assert "temperature moving during plateaus" in section["limits"]["flags"]
    assert section["limits"]["temperature_drift"]["sensor_lag_s"] == 300.0
    np.testing.assert_allclose([p["temperature"] for p in section["points"]], TEMPS, atol=0.1)
