"""``simulate --protocol multi-position --temp-points`` and ``plan --design poses --temp-points``.

References: the truth sidecar's cubics (the simulator's own truth, evaluated here from its JSON), and
for the plan, the scatter of ``gyrocal imu``'s temperature model over seeded simulated sessions
(independent of the covariance algebra the plan uses).
"""

import json

import numpy as np
import pytest
from cli_runner import invoke, refused
from thermal_sessions import smooth_at, truth_params

from gyrocal.imu.planning import predict_poses
from gyrocal.imu.thermal import calibrate_imu_thermal
from gyrocal.imu.thermal_planning import predict_thermal, smooth_sigma, suggest_thermal
from gyrocal.models import ScaleBias
from gyrocal.results.files import load
from gyrocal.simulation.chamber import chamber_session, random_thermal_imu

TEMPS = np.linspace(-25.0, 50.0, 5)
MID = (TEMPS[1:] + TEMPS[:-1]) / 2
FS, POSES, STILL, ACCEL_DENSITY = 100.0, 12, 2.0, 2e-3
_LOWER = np.r_[np.nonzero(np.tril(np.ones((3, 3), bool)).ravel())[0], 9, 10, 11]  # the 9-parameter model's


def _session(d, seed):
    """Simulate a chamber session with `seed` into `d` and fit it with ``gyrocal imu``: log, truth, section."""
    log = d / f"chamber{seed}.csv"
    code, out, err = invoke("simulate", "--protocol", "multi-position", "--temp-points",
                            ",".join(f"{t:g}" for t in TEMPS), "--temp-soak", "900", "--temp-noise", "0.05",
                            "--poses", str(POSES), "--still", str(STILL), "--sample-rate", str(FS), "--noise",
                            "0.005", "--seed", str(seed), "-o", log)
    assert code == 0, err
    cal = d / f"cal{seed}.json"
    code, _, err = invoke("imu", log, "--units", "deg/s", "--accel-units", "m/s^2", "-o", cal)
    assert code == 0, err
    return log, json.loads(log.with_suffix(".truth.json").read_text())["imu_thermal"], load(cal).accelerometer


@pytest.fixture(scope="module")
def chamber_cli(tmp_path_factory):
    return _session(tmp_path_factory.mktemp("sim24"), 4)


def test_the_log_has_a_pose_sequence_per_point_and_jumps_over_each_soak(chamber_cli):
    log, truth, _ = chamber_cli
    data = np.genfromtxt(log, delimiter=",", names=True, skip_header=1)
    points = truth["points"]
    assert [p["temperature_degC"] for p in points] == TEMPS.tolist()
    assert all(p["branch"] == "heating" for p in points)
    for p, q in zip(points[:-1], points[1:]):
        assert q["samples"][0] == p["samples"][1]
        assert 900.0 < data["t"][q["samples"][0]] - data["t"][p["samples"][1] - 1] < 901.0
        np.testing.assert_allclose(np.mean(data["temp"][slice(*p["samples"])]), p["temperature_degC"], atol=0.01)
    np.testing.assert_allclose(points[2]["accelerometer"], truth_params(truth, "accelerometer", [TEMPS[2]])[0])


def test_imu_recovers_the_sidecars_temperature_model_within_its_sigma(chamber_cli, tmp_path):
    """Both sensors' smooth models at the points and between them over 6 seeded boards: RMS z of the error
    against the truth. The 9 temperatures of one parameter rest on 5 points, so the band counts 5 independent
    z values per parameter and board: 1 +- 4 / sqrt(2 m)."""
    sessions = [chamber_cli] + [_session(tmp_path, seed) for seed in (0, 1, 2, 3, 5)]
    temps = np.r_[TEMPS, MID]
    z = {"accelerometer": [], "gyro": []}
    for _, truth, section in sessions:
        for sensor, keep in (("accelerometer", _LOWER), ("gyro", slice(None))):
            value, sigma = smooth_at(section["thermal"][sensor], temps)
            z[sensor].append((value - truth_params(truth, sensor, temps)[:, keep]) / sigma)
    for sensor, zs in z.items():
        zs = np.array(zs)
        rms, m = float(np.sqrt(np.mean(zs**2))), len(sessions) * zs.shape[2] * len(TEMPS)
        print(f"{sensor}: RMS z of the smooth model against the truth {rms:.2f} ({m} independent z values)")
        assert abs(rms - 1.0) < 4 / np.sqrt(2 * m), (sensor, rms)


def test_hysteresis_moves_the_accelerometer_offsets_of_the_cooling_branch(tmp_path):
    log = tmp_path / "h.csv"
    code, _, err = invoke("simulate", "--protocol", "multi-position", "--temp-points", "0,40,0", "--poses", "6",
                          "--still", "1", "--sample-rate", "50", "--temp-hysteresis", "0.05", "-o", log)
    assert code == 0, err
    truth = json.loads(log.with_suffix(".truth.json").read_text())["imu_thermal"]
    first, _, back = truth["points"]
    assert (first["branch"], back["branch"]) == ("heating", "cooling")
    np.testing.assert_allclose(np.subtract(back["accelerometer"], first["accelerometer"])[9:],
                               truth["hysteresis"]["accel_offset"], atol=1e-12)
    np.testing.assert_allclose(np.abs(truth["hysteresis"]["accel_offset"]), 0.05)


def test_chamber_flags_are_refused_where_they_mean_nothing(tmp_path):
    assert "--temp-points" in refused("simulate", "--protocol", "multi-position", "--temp-soak", "10",
                                      "-o", tmp_path / "a.csv")
    assert "--temp-points" in refused("simulate", "--protocol", "servo", "--temp-points", "0,10",
                                      "-o", tmp_path / "b.csv")
    assert "--temp-range" in refused("plan", "--design", "poses", "--temp-points", "5", "--temp-range", "9:1")
    assert "--target-cross" in refused("plan", "--design", "poses", "--temp-points", "5", "--target-cross", "1e-3")
    code, out, err = invoke("plan", "--design", "poses", "--temp-points", "5", "--target-bias", "0.001deg/s")
    assert code == 0, err
    assert "gyro bias across the range" in out and "gyro scale at a point" in out


def test_plan_predicts_the_scatter_of_the_temperature_model_over_seeded_sessions():
    """Reference: 6 seeded boards simulated and fitted by gyrocal imu's thermal calibration; the error of the
    accelerometer's smooth model (and the gyro's bias) between the points over the plan's 1-sigma there
    (Cramer-Rao per point carried through the weighted polynomial). Orders chosen below the top lower the
    variance, a missed cubic raises it: the two-sided band holds the ratio of empirical to predicted variance."""
    plan = predict_poses(POSES, 90.0, static_duration=STILL, sample_rate=FS, accel_noise_density=ACCEL_DENSITY,
                         gyro_noise_density=np.radians(0.01))
    predicted = smooth_sigma(TEMPS, np.tile(plan.accel_std, (len(TEMPS), 1)), MID)
    gyro_predicted = smooth_sigma(TEMPS, np.tile(plan.gyro_std, (len(TEMPS), 1)), MID)[:, 9:]
    z, zg = [], []
    for seed in range(6):
        rng = np.random.default_rng(seed)
        truth = random_thermal_imu(ScaleBias((1.0, 1.0, 1.0), (0.0, 0.0, 0.0)), rng)
        rec, _ = chamber_session(truth, TEMPS, gyro_kw={"noise_std": np.radians(0.1)}, poses=POSES, still=STILL,
                                 accel_noise_std=ACCEL_DENSITY * np.sqrt(FS), sample_rate=FS, rng=rng)
        fit = calibrate_imu_thermal(rec.t, rec.gyro, rec.accel, rec.temp)
        est, _ = fit.accel.smooth_at(MID)
        z.append((est - np.array([truth.params(t)[0][_LOWER] for t in MID])) / predicted)
        gest, _ = fit.gyro.smooth_at(MID)
        zg.append((gest[:, 9:] - np.array([truth.params(t)[1][9:] for t in MID])) / gyro_predicted)
    ratio, gyro_ratio = float(np.mean(np.square(z))), float(np.mean(np.square(zg)))
    print(f"empirical / predicted variance between the points: accelerometer {ratio:.2f} (6 boards, 9 parameters, "
          f"4 temperatures), gyro bias {gyro_ratio:.2f}")
    assert 0.6 < ratio < 1.6
    assert 0.6 < gyro_ratio < 1.6


def test_more_points_and_poses_help_and_the_suggestion_is_the_smallest_that_meets_the_target():
    few, more = predict_thermal(5, 12), predict_thermal(9, 24)
    assert all(more.between[k] < few.between[k] and more.per_point[k] < few.per_point[k] for k in few.between)
    assert all(few.between_rms[k] < few.between[k] for k in few.between)
    target = {"accel_offset": 0.8 * few.between["accel_offset"]}
    best = suggest_thermal(target)
    assert best.meets(target) and best.points >= 5
    assert not any(predict_thermal(n, p).meets(target) for n in range(5, 13) for p in (12, 16, 20, 24, 30, 36, 48)
                   if n * p < best.points * best.poses)
    code, out, err = invoke("plan", "--design", "poses", "--temp-points", "5", "--poses", "12",
                            "--target-accel-offset", str(target["accel_offset"]))
    assert code == 0, err
    assert f"{best.points} " in out.split("temperature points")[1].splitlines()[0]
