"""The gyro fit's analytic Jacobian (``gyrocal.imu._gyro_jac``) against numerical references.

References, none of which uses the analytic derivative:

* a five-point central difference of the residuals themselves (truncation O(h^4), round-off about
  eps / h: at a relative step of 1e-3 both are below 1e-9 of a column's size);
* a per-step loop of quaternion products (:func:`gyrocal.quaternion.multiply`) for the blocked scan;
* the whole fit run with a central-difference Jacobian instead: the same optimum and covariance
  within what that finite difference resolves.
"""

from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import gyrocal.imu._gyro_solve as solve_mod
import gyrocal.imu.gyro as gyro_mod
from gyrocal import quaternion as quat
from gyrocal.imu import calibrate_imu
from gyrocal.imu._gyro_jac import prefix_products, right_jacobian
from gyrocal.imu._gyro_solve import MASKS, jacobian, residuals, residuals_jacobian
from gyrocal.io import read_windows
from gyrocal.models import Affine
from gyrocal.simulation.gyro import VirtualGyro
from gyrocal.simulation.multiposition import MultiPositionProtocol, VirtualImu, simulate_multi_position


def _session(seed):
    rng = np.random.default_rng(seed)
    k = np.eye(3) * rng.uniform(0.97, 1.03, 3) + rng.normal(0, 0.005, (3, 3))
    gyro = VirtualGyro(Affine(k, np.radians(rng.normal(0, 0.5, 3))), noise_std=np.radians(0.1))
    imu = VirtualImu(gyro, accel_matrix=np.eye(3), accel_offset=rng.normal(0, 0.1, 3), accel_noise_std=0.02)
    return simulate_multi_position(imu, MultiPositionProtocol(poses=10, static_duration=(1.5, 2.5),
                                                              uneven_steps=0.03), rng=rng)


def _capture(*args, **kwargs):
    """The gyro problem and accelerometer fit that :func:`gyrocal.imu.gyro.fit_gyroscope` builds for
    ``calibrate_imu(*args, **kwargs)``, and the calibration."""
    seen = {}
    real = gyro_mod.solve

    def spy(prob, model, with_g, p0, accel, means):
        seen.setdefault("args", (prob, accel))
        return real(prob, model, with_g, p0, accel, means)

    gyro_mod.solve = spy
    try:
        result = calibrate_imu(*args, **kwargs)
    finally:
        gyro_mod.solve = real
    return seen["args"] + (result,)


@pytest.fixture(scope="module")
def captured():
    """The gyro problem of a simulated session, as :func:`gyrocal.imu.gyro.fit_gyroscope` builds it."""
    s = _session(7)
    return _capture(s.t, s.gyro, s.accel)


@pytest.fixture(scope="module")
def captured_turns():
    """The gyro problem of imucal's Ferraris session: poses and three known-angle turns."""
    data = Path(str(resources.files("gyrocal") / "data" / "imucal_ferraris"))
    df = pd.read_csv(data / "example_ferraris_session.csv")
    fs = 102.4  # Hz, from the session's README
    windows = read_windows(data / "example_ferraris_session_list.json", sample_rate=fs)
    return _capture(np.arange(len(df)) / fs, np.radians(df[["gyr_x", "gyr_y", "gyr_z"]].to_numpy()),
                    df[["acc_x", "acc_y", "acc_z"]].to_numpy(), gravity=9.81, windows=windows)


def _five_point(fun, p, rel=1e-3):
    cols = []
    for j in range(p.size):
        h = rel * max(abs(p[j]), 1e-3 * float(np.abs(p).max()))
        dp = np.zeros_like(p)
        dp[j] = h
        cols.append((-fun(p + 2 * dp) + 8 * fun(p + dp) - 8 * fun(p - dp) + fun(p - 2 * dp)) / (12 * h))
    return np.column_stack(cols)


def _check_columns(captured, model, with_g):
    prob, accel, result = captured
    rng = np.random.default_rng(11)
    prob.factors = np.array([1.3, 0.8, 1.7])
    p = np.concatenate([result.gyro.matrix[MASKS[model]] * 1.002, result.gyro.offset + 2e-4,
                        rng.normal(0, 1e-4, 9) if with_g else []])
    d, d_std = accel.directions, accel.direction_std
    ref = _five_point(lambda q: residuals(prob, model, with_g, q, d, d_std), p)
    got = residuals_jacobian(prob, model, with_g, p, d, d_std)
    assert got.shape == ref.shape
    scale = np.abs(ref).max(axis=0)
    assert np.all(np.abs(got - ref).max(axis=0) <= 1e-8 * scale)


@pytest.mark.parametrize("model", ["affine", "scale"])
@pytest.mark.parametrize("with_g", [False, True])
def test_jacobian_matches_a_five_point_difference_of_the_residuals(captured, model, with_g):
    """Away from the optimum, with unequal group factors (they scale each group's noise): every column
    within 1e-8 of its largest entry (the difference's own error is below 1e-9)."""
    _check_columns(captured, model, with_g)


@pytest.mark.parametrize("with_g", [False, True])
def test_jacobian_of_known_angle_turns_matches_a_five_point_difference(captured_turns, with_g):
    """The same check on a session with known-angle turns (their rows, whose noise holds the Earth's rate
    over each turn's duration): every column within 1e-8 of its largest entry."""
    prob, _, _ = captured_turns
    assert len(prob.turns) == 3
    _check_columns(captured_turns, "affine", with_g)


def test_prefix_products_match_a_loop_of_quaternion_products():
    """Every inclusive prefix of step rotations against quaternion products in order, one per step;
    lengths that do not fill the blocks evenly."""
    rng = np.random.default_rng(3)
    for length in (1, 2, 7, 50, 101):
        phi = rng.normal(0, 0.3, (2, length, 3))
        got = prefix_products(quat.rotvec_matrix(phi))
        for p in range(2):
            q = np.array([1.0, 0.0, 0.0, 0.0])
            for k in range(length):
                q = quat.multiply(q, quat.from_rotvec(phi[p, k]))
                np.testing.assert_allclose(got[p, k], quat.to_matrix(q), atol=1e-12)


def test_right_jacobian_is_the_derivative_of_the_rotation():
    """``exp([phi + d]x) = exp([phi]x) exp([J_r d]x)`` to first order: against central differences of
    Rodrigues' formula, for small angles (the series) and large ones."""
    rng = np.random.default_rng(5)
    for size in (1e-5, 3e-3, 0.5, 2.5):
        phi = rng.normal(0, 1, 3)
        phi *= size / np.linalg.norm(phi)
        jr = right_jacobian(phi)
        r0 = quat.rotvec_matrix(phi)
        for j in range(3):
            h = 1e-6
            dphi = np.zeros(3)
            dphi[j] = h
            dr = (quat.rotvec_matrix(phi + dphi) - quat.rotvec_matrix(phi - dphi)) / (2 * h)
            w = r0.T @ dr  # the skew matrix of J_r e_j
            np.testing.assert_allclose([w[2, 1], w[0, 2], w[1, 0]], jr[:, j], atol=1e-8)


def test_right_jacobian_series_near_its_switch_against_the_closed_form():
    """Just below the angle where the small-angle series takes over (|phi| = 9e-3): the closed form written
    without cancellation, (1 - cos a) / a^2 = 2 sin^2(a/2) / a^2 and (a - sin a) / a^3 (relative error about
    1e-11 here), to 1e-12 of the identity."""
    phi = np.array([0.6, -0.48, 0.64]) * 9e-3
    a = float(np.linalg.norm(phi))
    c1, c2 = 2 * np.sin(a / 2) ** 2 / a**2, (a - np.sin(a)) / a**3
    skew = np.array([[0, -phi[2], phi[1]], [phi[2], 0, -phi[0]], [-phi[1], phi[0], 0]])
    want = np.eye(3) - c1 * skew + c2 * skew @ skew
    np.testing.assert_allclose(right_jacobian(phi), want, rtol=0, atol=1e-12)


def test_fit_reaches_the_finite_difference_fits_optimum_and_covariance(monkeypatch):
    """The fit with the central-difference Jacobian (relative step 1e-6, error about 1e-7 of an entry):
    parameters within 1e-4 of their 1-sigma, covariance within 1e-5 of the diagonal's scale."""
    s = _session(21)
    fast = calibrate_imu(s.t, s.gyro, s.accel).gyro

    def numeric(prob, model, with_g, p, directions, directions_std):
        return jacobian(lambda q: residuals(prob, model, with_g, q, directions, directions_std), p)

    monkeypatch.setattr(solve_mod, "residuals_jacobian", numeric)
    slow = calibrate_imu(s.t, s.gyro, s.accel).gyro
    assert fast.model == slow.model
    assert np.all(np.abs(fast.params - slow.params) <= 1e-4 * slow.std)
    scale = np.sqrt(np.outer(np.diag(slow.covariance), np.diag(slow.covariance)))
    assert np.all(np.abs(fast.covariance - slow.covariance) <= 1e-5 * scale)
