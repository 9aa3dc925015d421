"""Whole hand sessions, simulated: still-pose detection, both sensors within their uncertainty, and refusals.

The simulator moves the board with closed-form minimum-jerk rotations and reads both sensors at
the (possibly uneven) true sample times, so it is an independent reference for the detector,
the quaternion integration and the fits.
"""

import numpy as np
import pytest

from gyrocal.errors import DegenerateDesignError
from gyrocal.imu import calibrate_imu, detect_statics
from gyrocal.models import Affine
from gyrocal.simulation.gyro import VirtualGyro
from gyrocal.simulation.multiposition import MultiPositionProtocol, VirtualImu, simulate_multi_position

GYRO_NOISE = np.radians(0.1)  # per sample at 100 Hz [rad/s]
ACCEL_NOISE = 0.02            # per sample [m/s^2]


def _imu(rng, gyro_noise=GYRO_NOISE, accel_noise=ACCEL_NOISE, g_sens=None):
    k = np.eye(3) * rng.uniform(0.97, 1.03, 3) + rng.normal(0, 0.005, (3, 3))
    gyro = VirtualGyro(Affine(k, np.radians(rng.normal(0, 0.5, 3))), noise_std=gyro_noise)
    a = np.tril(np.eye(3) * rng.uniform(0.97, 1.03, 3) + rng.normal(0, 0.005, (3, 3)))
    return VirtualImu(gyro, accel_matrix=a, accel_offset=rng.normal(0, 0.2, 3), accel_noise_std=accel_noise,
                      g_sensitivity=np.zeros((3, 3)) if g_sens is None else g_sens)


def _session(seed, protocol=None, **kw):
    rng = np.random.default_rng(seed)
    imu = _imu(rng, **kw)
    return simulate_multi_position(imu, protocol or MultiPositionProtocol(poses=14, static_duration=(1.5, 2.5),
                                                                          uneven_steps=0.03), rng=rng)


def _z(result, truth):
    acc = np.concatenate([truth["accel_matrix"][np.tril(np.ones((3, 3), bool))], truth["accel_offset"]])
    gyr = np.concatenate([truth["gyro_matrix"].ravel(), truth["gyro_offset"]])
    return (result.accel.params - acc) / result.accel.std, (result.gyro.params[:12] - gyr) / result.gyro.std[:12]


def test_detector_finds_every_pose_inside_its_true_still_span():
    """Reference: the simulator's still spans; the noise it measures is the simulated noise."""
    s = _session(0)
    det = detect_statics(s.t, s.gyro, s.accel)
    assert len(det.statics) == len(s.still)
    for st, (a, b) in zip(det.statics, s.still):
        assert a <= st.start and st.stop <= b
        assert st.count > 0.7 * (b - a) - det.window
    np.testing.assert_allclose(det.accel_noise, ACCEL_NOISE, rtol=0.15)
    np.testing.assert_allclose(det.gyro_noise, GYRO_NOISE, rtol=0.15)


def test_a_slow_steady_turn_is_not_a_pose():
    """A 2 deg/s drift inside a pose (too slow to raise the variance) must not count as still."""
    s = _session(1)
    a, b = s.still[5]
    gyro = s.gyro.copy()
    gyro[a:b, 2] += np.radians(2.0)
    det = detect_statics(s.t, gyro, s.accel)
    assert all(st.stop <= a or st.start >= b for st in det.statics)


def test_noise_free_session_recovers_both_sensors_exactly():
    """Reference: the simulated truth. Without noise only the integration error is left: third order per step,
    largest on the 20 ms steps of dropped samples, and far below the 4e-4 a noisy session reaches."""
    s = _session(2, MultiPositionProtocol(poses=14, static_duration=(1.5, 2.5), uneven_steps=0.03, latitude_deg=None),
                 gyro_noise=0.0, accel_noise=1e-9)
    r = calibrate_imu(s.t, s.gyro, s.accel)
    assert r.accel.model == "triangular" and r.gyro.model == "affine"
    np.testing.assert_allclose(r.accel.matrix, s.truth["accel_matrix"], atol=1e-9)
    np.testing.assert_allclose(r.gyro.matrix, s.truth["gyro_matrix"], atol=5e-5)
    np.testing.assert_allclose(r.gyro.offset, s.truth["gyro_offset"], atol=1e-5)


@pytest.mark.slow
def test_both_sensors_within_reported_uncertainty_over_seeds():
    """Reference: the simulated truth. 10 sessions x 9 accel and 12 gyro parameters: RMS z in [0.75, 1.25]
    (4 sigma of the RMS of about 100 z-scores) and no parameter off by more than 4.5 sigma."""
    za, zg = [], []
    for seed in range(10):
        s = _session(100 + seed)
        r = calibrate_imu(s.t, s.gyro, s.accel)
        a, g = _z(r, s.truth)
        za.append(a)
        zg.append(g)
    for z in (np.array(za), np.array(zg)):
        assert 0.75 < np.sqrt(np.mean(z**2)) < 1.25
        assert np.abs(z).max() < 4.5


def test_a_pose_pair_that_disagrees_is_named_and_left_out():
    """A 3 deg jolt in the gyro alone between poses 7 and 8 (as if the gyro saturated): that pair, and only
    that pair, is named and left out; the others still fit within their noise."""
    s = _session(3)
    (_, end7), (start8, _) = s.still[6], s.still[7]
    gyro = s.gyro.copy()
    i = (end7 + start8) // 2 - 10
    d8 = s.truth["accel_matrix"] @ (s.accel[start8 + 20] - s.truth["accel_offset"])
    axis = np.cross(d8, [1.0, 0.0, 0.0])  # across gravity, so the jolt tilts the predicted direction
    gyro[i:i + 20] += np.radians(3.0) / 0.2 * axis / np.linalg.norm(axis)
    r = calibrate_imu(s.t, gyro, s.accel)
    assert [c.label for c in r.gyro.disagreeing] == ["pose 7 -> 8"]
    assert r.gyro.left_out == ("pose 7 -> 8",)
    assert any("pose 7 -> 8 disagrees" in w and "left out" in w for w in r.warnings)
    assert r.gyro.noise_factors["turns between poses"] < 1.5


def test_gyro_g_sensitivity_is_recovered_where_the_poses_determine_it():
    """Reference: the simulated G (0.05 deg/s per g on the diagonal, smaller across)."""
    g_sens = np.radians(0.05) / 9.81 * (np.eye(3) + 0.3 * np.random.default_rng(4).normal(size=(3, 3)))
    s = _session(4, g_sens=g_sens)
    r = calibrate_imu(s.t, s.gyro, s.accel, g_sensitivity=True)
    assert r.gyro.g_sensitivity is not None and "g-sensitivity: fitted" in r.gyro.choice[-1]
    z = (r.gyro.g_sensitivity.ravel() - g_sens.ravel()) / r.gyro.std[12:]
    assert np.abs(z).max() < 4.5


def test_too_few_poses_are_refused_with_the_number_needed():
    s = _session(5, MultiPositionProtocol(poses=4, static_duration=(2.0, 3.0)))
    with pytest.raises(DegenerateDesignError, match=r"4 still poses.*at least 6 distinct orientations.*2 more"):
        calibrate_imu(s.t, s.gyro, s.accel)


def test_turns_about_two_axes_only_leave_the_third_gyro_axis_undetermined():
    """Every move turns the board about its own x or y axis, never z: the gyro's z response is not determined."""
    from gyrocal import quaternion as quat

    q = [np.array([1.0, 0.0, 0.0, 0.0])]
    for k in range(13):
        axis = np.eye(3)[k % 2] * (1 if (k // 2) % 3 else -1)
        q.append(quat.multiply(q[-1], quat.from_rotvec(np.radians(70.0) * axis)))
    s = _session(6, MultiPositionProtocol(orientations=np.array(q), static_duration=(2.0, 3.0), wobble_deg=0.0))
    with pytest.raises(DegenerateDesignError, match="determine no gyro model"):
        calibrate_imu(s.t, s.gyro, s.accel)
