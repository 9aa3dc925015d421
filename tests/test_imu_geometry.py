"""Quaternion integration, pose coverage and the frame of the 9-parameter accelerometer model."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from gyrocal import quaternion as quat
from gyrocal.imu import coverage, fibonacci_directions, pose_sequence, triangular_frame


def _scipy(q):
    return Rotation.from_quat(np.asarray(q)[..., [1, 2, 3, 0]])


def test_constant_rate_integrates_to_the_exact_rotation_on_uneven_stamps():
    """Reference: a constant body rate w for a time T is the rotation exp(w T), whatever the sample times."""
    rng = np.random.default_rng(1)
    t = np.concatenate([[0.0], np.cumsum(rng.choice([0.005, 0.01, 0.02], size=399))])
    w = np.array([0.7, -1.1, 0.4])
    q = quat.attitude_change(t, np.tile(w, (400, 1)), [[0, 399], [17, 250]])
    for (a, b), qi in zip([(0, 399), (17, 250)], q):
        want = Rotation.from_rotvec(w * (t[b] - t[a]))
        assert (_scipy(qi) * want.inv()).magnitude() < 1e-12


def test_varying_rate_matches_a_fine_step_reference():
    """Reference: scipy's rotation product over 20x finer steps (error of the coarse steps is third order)."""
    def rates(t):
        return np.stack([np.sin(3 * t), 2 * np.cos(2 * t), 0.5 + t], axis=1)

    fine = np.linspace(0.0, 3.0, 6001)  # 2 kHz: its own error is 400 times below the 100 Hz one
    ref = Rotation.identity()
    for rv in quat.step_rotvecs(fine, rates(fine)):
        ref = ref * Rotation.from_rotvec(rv)
    err = []
    for n in (301, 601):  # 100 Hz and 200 Hz
        coarse = np.linspace(0.0, 3.0, n)
        q = quat.attitude_change(coarse, rates(coarse), [[0, n - 1]])[0]
        err.append(np.degrees((_scipy(q) * ref.inv()).magnitude()))
    # second order overall: halving the step quarters the error; at 100 Hz it is far below any calibration's noise
    assert 3.0 < err[0] / err[1] < 5.0
    assert err[0] < 0.02


def test_tree_product_keeps_the_order_of_non_commuting_steps():
    """Reference: scipy multiplies the same step rotations one after the other, in time order."""
    rng = np.random.default_rng(2)
    t = np.cumsum(rng.uniform(0.5, 1.5, 38))
    omega = rng.normal(size=(38, 3))  # big random steps: order matters at first order
    want = Rotation.identity()
    for rv in quat.step_rotvecs(t[5:31], omega[5:31]):
        want = want * Rotation.from_rotvec(rv)
    got = quat.attitude_change(t, omega, [[5, 30]])[0]
    assert (_scipy(got) * want.inv()).magnitude() < 1e-12


@pytest.mark.parametrize("dirs, spread, cap", [
    (np.vstack([np.eye(3), -np.eye(3)]), 1.0, 54.7),      # six faces: even, empty cap at a cube corner
    (fibonacci_directions(200), 1.0, 12.0),
    (np.array([[np.cos(a), np.sin(a), 0] for a in np.linspace(0, 2 * np.pi, 12, endpoint=False)]), 0.0, 90.0),
])
def test_coverage_of_known_pose_sets(dirs, spread, cap):
    """Reference: the spread and empty cap of the cube faces, an even spiral and a great circle, by geometry."""
    c = coverage(dirs)
    assert c.spread == pytest.approx(spread, abs=0.03)
    assert c.empty_cap_deg == pytest.approx(cap, abs=3.0) if cap > 20 else c.empty_cap_deg < cap


def test_coverage_counts_repeated_poses_once():
    dirs = np.vstack([np.eye(3), np.eye(3) + 0.01, -np.eye(3)])
    assert coverage(dirs).poses == 6


def test_pose_sequence_tilts_by_the_turn_and_fills_the_sphere():
    """Reference: the angle between successive 'up' directions is the requested tilt."""
    q = pose_sequence(24, 90.0, rng=np.random.default_rng(3))
    up = quat.rotate(q * [1, -1, -1, -1], np.array([0.0, 0.0, 1.0]))
    tilt = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", up[:-1], up[1:]), -1, 1)))
    np.testing.assert_allclose(tilt, 90.0, atol=1e-6)
    assert coverage(up).spread > 0.8


def test_triangular_frame_is_a_rotation_of_the_correction():
    """Reference: |L v| = |A v| for every v, L lower triangular with a positive diagonal, R orthonormal."""
    rng = np.random.default_rng(4)
    a = np.eye(3) + rng.normal(0, 0.05, (3, 3))
    lower, rot = triangular_frame(a)
    assert np.allclose(np.triu(lower, 1), 0) and np.all(np.diag(lower) > 0)
    np.testing.assert_allclose(rot @ rot.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(lower, rot @ a, atol=1e-12)


def test_poses_picture_draws_every_pose_and_move():
    """The sphere picture's artists: one point and label per pose, one arc per move, red for disagreeing pairs."""
    from gyrocal.plotting import new_figure
    from gyrocal.plotting.imu import draw_poses

    dirs = fibonacci_directions(7)
    ax = new_figure().add_subplot(projection="3d")
    art = draw_poses(ax, dirs, disagree=[2], empty_cap=(np.array([0.0, 0.0, 1.0]), 30.0))
    assert art["points"].get_offsets().shape[0] == 7 and len(art["labels"]) == 7
    assert len(art["moves"]) == 6
    colors = [m.get_color() for m in art["moves"]]
    assert colors[2] == "tab:red" and colors.count("tab:red") == 1
    assert len(art["empty_cap"]) == 1
