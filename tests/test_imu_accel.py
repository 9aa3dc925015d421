"""Accelerometer fits from still poses: truth within the reported uncertainty, and the model the poses allow.

Pose means are drawn directly (a direction per pose, the true model, Gaussian noise of the
stated standard error), so hundreds of seeds run in a second; the full session path is checked
in test_imu_session.py.
"""

import numpy as np
import pytest

from gyrocal.errors import DegenerateDesignError
from gyrocal.imu import fibonacci_directions, fit_accelerometer, normal_gravity
from gyrocal.imu.accel import param_names

G = 9.80665
SE = 0.004  # standard error of a pose mean [m/s^2]: 0.02 m/s^2 per sample over 25 samples


def _truth(rng, model="triangular"):
    a = np.eye(3) * rng.uniform(0.95, 1.05, 3) + rng.normal(0, 0.01, (3, 3))
    if model == "triangular":
        a = np.tril(a)
    elif model == "scale-bias":
        a = np.diag(np.diag(a))
    return a, rng.normal(0, 0.2, 3)


def _poses(rng, a, o, dirs, se=SE):
    u = (G * dirs) @ np.linalg.inv(a).T + o
    return u + rng.normal(0, se, u.shape), np.full(u.shape, se)


def _random_dirs(rng, n):
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _z(fit, a, o):
    mask = np.tril(np.ones((3, 3), bool)) if fit.model == "triangular" else (
        np.eye(3, dtype=bool) if fit.model == "scale-bias" else np.ones((3, 3), bool))
    return (fit.params - np.concatenate([a[mask], o])) / fit.std


@pytest.mark.parametrize("model", ["triangular", "scale-bias"])
def test_truth_within_reported_uncertainty_over_seeds(model):
    """Reference: the simulated truth. Over 200 seeds the z-scores have RMS 1 (band +-0.1, about 4 sigma of the RMS)."""
    z = []
    for seed in range(200):
        rng = np.random.default_rng(seed)
        a, o = _truth(rng, model)
        u, se = _poses(rng, a, o, _random_dirs(rng, 24))
        fit = fit_accelerometer(u, se, gravity=G, model=model)
        z.append(_z(fit, a, o))
    z = np.array(z)
    assert 0.9 < np.sqrt(np.mean(z**2)) < 1.1
    assert np.all(np.abs(z.mean(axis=0)) < 4 / np.sqrt(len(z)))  # no bias beyond 4 sigma of a mean of 200


def test_known_directions_recover_the_full_matrix_within_uncertainty():
    """Reference: the simulated truth, a general (not triangular) matrix, six faces each held three times."""
    z = []
    dirs = np.repeat(np.vstack([np.eye(3), -np.eye(3)]), 3, axis=0)
    for seed in range(100):
        rng = np.random.default_rng(seed)
        a, o = _truth(rng, "affine")
        u, se = _poses(rng, a, o, dirs)
        fit = fit_accelerometer(u, se, gravity=G, directions=dirs)
        assert fit.model == "affine"
        z.append(_z(fit, a, o))
    assert 0.88 < np.sqrt(np.mean(np.square(z))) < 1.12


def test_auto_takes_the_nine_parameter_model_when_poses_allow():
    rng = np.random.default_rng(5)
    a, o = _truth(rng)
    fit = fit_accelerometer(*_poses(rng, a, o, fibonacci_directions(24)), gravity=G)
    assert fit.model == "triangular" and fit.param_names == param_names("triangular")
    assert fit.choice == ("triangular: fitted (15 spare equations)",)
    assert fit.fit.dof == 15 and not fit.fit.warnings


def test_ten_poses_fit_scale_and_bias_and_say_why():
    """Ten poses leave the 9-parameter model one spare equation: too few to check it, so scale and bias are fitted."""
    rng = np.random.default_rng(6)
    a, o = _truth(rng, "scale-bias")
    fit = fit_accelerometer(*_poses(rng, a, o, fibonacci_directions(10)), gravity=G)
    assert fit.model == "scale-bias"
    assert fit.choice[0] == "triangular: only 1 spare equation(s), 3 needed to check the fit"
    assert fit.choice[1] == "scale-bias: fitted (4 spare equations)"
    assert np.all(np.abs(_z(fit, a, o)) < 4.5)


def test_six_faces_fit_without_spare_equations_and_warn():
    rng = np.random.default_rng(7)
    a, o = _truth(rng, "scale-bias")
    fit = fit_accelerometer(*_poses(rng, a, o, np.vstack([np.eye(3), -np.eye(3)])), gravity=G)
    assert fit.model == "scale-bias" and fit.fit.dof == 0
    assert "too few to check it" in fit.choice[-1]
    assert any("cannot be checked" in w for w in fit.fit.warnings)
    assert np.all(np.abs(_z(fit, a, o)) < 4.5)


def test_five_poses_are_refused_with_the_number_needed():
    rng = np.random.default_rng(8)
    a, o = _truth(rng)
    with pytest.raises(DegenerateDesignError, match=r"5 distinct orientations.*at least 6 distinct orientations"
                                                    r".*in 1 more orientation"):
        fit_accelerometer(*_poses(rng, a, o, fibonacci_directions(5)), gravity=G)


def test_poses_on_one_great_circle_are_refused_naming_the_blind_axis():
    rng = np.random.default_rng(9)
    a, o = _truth(rng)
    ang = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    dirs = np.stack([np.cos(ang), np.sin(ang), np.zeros_like(ang)], axis=1)
    with pytest.raises(DegenerateDesignError, match="not determined"):
        fit_accelerometer(*_poses(rng, a, o, dirs), gravity=G)


def test_excess_scatter_scales_the_covariance_and_says_so():
    """Poses noisier than their stated standard error: the Birge ratio scales the covariance (z stays near 1)."""
    z = []
    for seed in range(60):
        rng = np.random.default_rng(seed)
        a, o = _truth(rng)
        u, _ = _poses(rng, a, o, _random_dirs(rng, 30), se=5 * SE)
        fit = fit_accelerometer(u, np.full(u.shape, SE), gravity=G)
        assert fit.fit.covariance_scaled and "scaled up" in fit.fit.warnings[0]
        z.append(_z(fit, a, o))
    assert 0.85 < np.sqrt(np.mean(np.square(z))) < 1.15


def test_sensor_axes_match_the_truth():
    """Reference: sensitivities and inter-axis angles computed from the true matrix by hand."""
    rng = np.random.default_rng(10)
    a, o = _truth(rng)
    fit = fit_accelerometer(*_poses(rng, a, o, fibonacci_directions(40)), gravity=G)
    m = np.linalg.inv(a)
    axes = m / np.linalg.norm(m, axis=1, keepdims=True)
    want = {"sens_x": np.linalg.norm(m[0]), "angle_xy": np.degrees(np.arccos(axes[0] @ axes[1])),
            "angle_yz": np.degrees(np.arccos(axes[1] @ axes[2]))}
    got = fit.sensor_axes()
    for key, value in want.items():
        assert abs(got[key][0] - value) < 4.5 * got[key][1]


@pytest.mark.parametrize("lat, g", [(0.0, 9.7803253359), (90.0, 9.8321849378)])
def test_normal_gravity_matches_wgs84(lat, g):
    """Reference: WGS84's defining normal gravity at the equator and at the pole (NIMA TR8350.2, table 3.4)."""
    assert normal_gravity(lat) == pytest.approx(g, abs=2e-9)
    assert normal_gravity(lat, 1000.0) == pytest.approx(g - 3.086e-3, abs=2e-9)  # free-air gradient
