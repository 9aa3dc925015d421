"""imucal's real Ferraris session (MIT, bundled with its licence): gyrocal's whole-IMU fit against imucal's.

imucal runs in the test on the same samples and section list. Both use the same model
(``f = A (u - o)`` for the accelerometer in the frame of the six faces; ``w = A (m - o)`` for the
gyro); what differs, and the tolerance each difference justifies:

* accelerometer matrix: imucal takes each column from the difference of opposite faces. That is
  the least-squares solution of gyrocal's model when every pose has the same weight, so with
  equal weights the two agree to rounding; with each pose weighted by its own noise they differ
  by far less than gyrocal's 1-sigma.
* accelerometer offset: imucal averages the two faces of each axis, gyrocal all six (its least
  squares with weights); both estimate the same offset, so they agree within 3 of gyrocal's
  1-sigma (which is scaled up by the fit's own scatter: the poses are hand-placed faces).
* gyro: imucal assumes each turn is about the sensor axis it is named after; gyrocal measures
  the vertical in the poses beside each turn and also joins the six poses. Scale factors agree
  within 3 sigma; cross terms within 3 sigma plus the angle between the measured and assumed
  turn axes (the size of imucal's assumption); biases (both the mean of the still poses) within
  3 sigma.
"""

import json
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from imucal import FerrarisCalibration, ferraris_regions_from_section_list

from gyrocal.imu import calibrate_imu, fit_accelerometer
from gyrocal.io import read_windows

DATA = Path(str(resources.files("gyrocal") / "data" / "imucal_ferraris"))
SESSION = DATA / "example_ferraris_session.csv"
SECTIONS = DATA / "example_ferraris_session_list.json"
FS = 102.4  # Hz, from the session's README
G = 9.81    # imucal's default gravity, given to both


@pytest.fixture(scope="module")
def session():
    df = pd.read_csv(SESSION)
    return df, np.arange(len(df)) / FS


@pytest.fixture(scope="module")
def imucal_info(session):
    df, _ = session
    sections = pd.DataFrame(json.loads(SECTIONS.read_text())).T
    regions = ferraris_regions_from_section_list(df, sections)
    return FerrarisCalibration(grav=G).compute(regions, sampling_rate_hz=FS, from_acc_unit="m/s^2",
                                               from_gyr_unit="deg/s")


@pytest.fixture(scope="module")
def ours(session):
    df, t = session
    gyro = np.radians(df[["gyr_x", "gyr_y", "gyr_z"]].to_numpy())
    acc = df[["acc_x", "acc_y", "acc_z"]].to_numpy()
    return calibrate_imu(t, gyro, acc, gravity=G, windows=read_windows(SECTIONS, sample_rate=FS))


def _imucal_accel(info):
    return np.linalg.inv(info.R_a) @ np.linalg.inv(info.K_a), np.asarray(info.b_a)


def test_ferraris_session_is_recognised(ours):
    assert ours.kind == "ferraris"
    assert ours.accel.model == "affine" and ours.gyro.model == "affine"
    assert [s.label for s in ours.statics] == ["x_p", "x_a", "y_p", "y_a", "z_p", "z_a"]
    assert [t.label for t in ours.turns] == ["x_rot", "y_rot", "z_rot"]


def test_equal_weights_reproduce_imucal_accelerometer_matrix_exactly(ours, imucal_info):
    """Reference: imucal's Ferraris equations. Unweighted least squares over the six faces is the same estimator."""
    means = np.array([s.accel_mean for s in ours.statics])
    dirs = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    fit = fit_accelerometer(means, np.full_like(means, 1e-3), gravity=G, directions=dirs)  # equal weights
    matrix, _ = _imucal_accel(imucal_info)
    np.testing.assert_allclose(fit.matrix, matrix, rtol=0, atol=1e-12)
    # the offset: gyrocal's is the mean of all six faces, imucal's the mean of each axis's two faces
    np.testing.assert_allclose(fit.offset, means.mean(axis=0), atol=1e-12)


def test_accelerometer_agrees_with_imucal_within_its_uncertainty(ours, imucal_info):
    matrix, offset = _imucal_accel(imucal_info)
    std = ours.accel.std
    assert np.all(np.abs(ours.accel.matrix.ravel() - matrix.ravel()) < 3 * std[:9])
    assert np.all(np.abs(ours.accel.offset - offset) < 3 * std[9:])
    assert ours.accel.fit.covariance_scaled  # hand-placed faces scatter beyond the sensor noise, and it says so


def test_gyro_agrees_with_imucal_within_its_uncertainty(ours, imucal_info):
    info = imucal_info
    matrix = np.linalg.inv(info.R_g) @ np.linalg.inv(info.K_g)
    bias = np.radians(np.asarray(info.b_g))
    std = ours.gyro.std
    a_std, o_std = std[:9].reshape(3, 3), std[9:12]
    diag = np.eye(3, dtype=bool)
    assert np.all(np.abs(ours.gyro.matrix - matrix)[diag] < 3 * a_std[diag])
    # imucal takes each turn's axis as the sensor axis; gyrocal measures it: their angle bounds the cross terms
    axis_angle = max(np.arccos(np.clip(abs(t.axis[i]), 0, 1)) for i, t in enumerate(ours.turns))
    assert np.all(np.abs(ours.gyro.matrix - matrix)[~diag] < 3 * a_std[~diag] + axis_angle)
    assert np.all(np.abs(ours.gyro.offset - bias) < 3 * o_std)


def test_every_pose_pair_and_turn_is_reported(ours):
    labels = [c.label for c in ours.gyro.checks]
    assert labels == ["pose 1 -> 2", "pose 2 -> 3", "pose 3 -> 4", "pose 4 -> 5", "pose 5 -> 6",
                      "x_rot", "y_rot", "z_rot"]
    angles = [c.angle_deg for c in ours.gyro.checks]
    np.testing.assert_allclose(angles[5:], 360.0, atol=2.0)  # the known 360 deg turns, as integrated
