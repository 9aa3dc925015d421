"""Planning a hand session: the predicted accuracy is what a fit of such a session reports, and what it achieves."""

import numpy as np
import pytest

from gyrocal.errors import DegenerateDesignError, InputError
from gyrocal.imu import calibrate_imu, fibonacci_directions, fit_accelerometer, pose_sequence
from gyrocal.imu.planning import FIGURES, predict_poses, suggest_poses
from gyrocal.models import Affine
from gyrocal.simulation.gyro import VirtualGyro
from gyrocal.simulation.multiposition import MultiPositionProtocol, VirtualImu, simulate_multi_position

ACCEL_DENSITY, GYRO_DENSITY, FS = 2e-3, np.radians(0.01), 100.0


def test_prediction_matches_the_uncertainty_a_fit_of_that_session_reports():
    """Reference: the covariance reported by a fit of the simulated plan (itself checked against the truth by
    the z-score tests of test_imu_session.py). Same poses, moves and noise: within 20 %."""
    plan = predict_poses(16, 90.0, static_duration=2.0, peak_rate_deg=150.0, sample_rate=FS,
                         accel_noise_density=ACCEL_DENSITY, gyro_noise_density=GYRO_DENSITY)
    rng = np.random.default_rng(11)
    imu = VirtualImu(VirtualGyro(Affine(np.eye(3), np.zeros(3)), noise_std=GYRO_DENSITY * np.sqrt(FS)),
                     accel_noise_std=ACCEL_DENSITY * np.sqrt(FS))
    protocol = MultiPositionProtocol(orientations=pose_sequence(16, 90.0), static_duration=(2.0, 2.0),
                                     first_static=2.0, peak_rate_deg=(150.0, 150.0), wobble_deg=0.0,
                                     lever_arm=(0.0, 0.0, 0.0), sample_rate=FS)
    s = simulate_multi_position(imu, protocol, rng=rng)
    r = calibrate_imu(s.t, s.gyro, s.accel)
    assert r.accel.model == "triangular" and r.gyro.model == "affine"
    np.testing.assert_allclose(r.accel.std, plan.accel_std, rtol=0.2)
    np.testing.assert_allclose(r.gyro.std[:12], plan.gyro_std, rtol=0.2)


def test_accelerometer_prediction_is_the_spread_of_repeated_fits():
    """Reference: the standard deviation of 300 fits of noisy pose means (independent of any Jacobian)."""
    plan = predict_poses(24, 90.0, accel_noise_density=ACCEL_DENSITY, gyro_noise_density=GYRO_DENSITY)
    from gyrocal.imu.planning import DETECTOR_WINDOW
    n = round((plan.static_duration - DETECTOR_WINDOW) * FS)
    se = ACCEL_DENSITY * np.sqrt(FS) / np.sqrt(n)
    dirs = np.array([np.array([0, 0, 1.0])] + [d for d in pose_dirs(24)[1:]])
    est = []
    for seed in range(300):
        rng = np.random.default_rng(seed)
        u = 9.80665 * dirs + rng.normal(0, se, dirs.shape)
        est.append(fit_accelerometer(u, np.full(u.shape, se), model="triangular").params)
    spread = np.std(est, axis=0, ddof=1)
    # the sample standard deviation of 300 draws is within 20 % of the truth with probability > 0.999
    np.testing.assert_allclose(spread, plan.accel_std, rtol=0.2)


def pose_dirs(n):
    from gyrocal import quaternion as quat

    return quat.rotate(pose_sequence(n, 90.0) * [1, -1, -1, -1], np.array([0.0, 0.0, 1.0]))


def test_more_poses_and_larger_tilts_help_and_a_half_turn_sequence_is_degenerate():
    fig = {n: predict_poses(n, 90.0).figures() for n in (12, 48)}
    assert all(fig[48][k] < fig[12][k] for k in FIGURES)
    assert predict_poses(24, 90.0).figures()["gyro_scale"] < predict_poses(24, 45.0).figures()["gyro_scale"]
    # 180 deg tilts only flip the board between two faces: nothing is determined
    assert np.isinf(predict_poses(12, 180.0).figures()["accel_scale"])


def test_suggestion_is_the_shortest_plan_that_reaches_the_targets():
    targets = {"gyro_scale": 2e-4, "accel_offset": 2e-3}
    grid = dict(pose_counts=(12, 24, 36), turns=(45.0, 90.0))
    plan = suggest_poses(targets, accel_noise_density=4e-3, gyro_noise_density=9e-5, **grid)
    assert all(plan.figures()[k] <= v for k, v in targets.items())
    shorter = [predict_poses(n, t, accel_noise_density=4e-3, gyro_noise_density=9e-5)
               for n in grid["pose_counts"] for t in grid["turns"]]
    assert all(p.total_time >= plan.total_time or any(p.figures()[k] > v for k, v in targets.items())
               for p in shorter)


def test_unreachable_targets_are_refused_with_the_closest_plan():
    with pytest.raises(DegenerateDesignError, match="no plan of up to 16 poses reaches the targets; the closest"):
        suggest_poses({"gyro_scale": 1e-7}, pose_counts=(12, 16), turns=(90.0,))
    with pytest.raises(InputError, match="targets must name"):
        suggest_poses({"scale": 1e-3})
    assert fibonacci_directions(3).shape == (3, 3)


def test_plan_command_for_poses():
    """The CLI prints the library's prediction (same numbers) and refuses servo-only flags."""
    from cli_runner import invoke, refused

    code, out, err = invoke("plan", "--design", "poses", "--poses", "16", "--tilt", "90", "--noise-density",
                            "1e-4", "--accel-noise-density", "0.002", "--sample-rate", "100")
    assert code == 0, err
    f = predict_poses(16, 90.0, sample_rate=100.0, accel_noise_density=0.002, gyro_noise_density=1e-4).figures()
    assert f"{1e4 * f['gyro_scale']:.3g}" in out and f"{f['accel_offset']:.2g}" in out
    assert "--speed does not apply to --design poses" in refused("plan", "--design", "poses", "--speed", "30")
