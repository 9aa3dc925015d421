"""Experimental design: information, CRB, efficiencies, and the CRB against Monte Carlo."""

import math

import numpy as np
import pytest

from gyrocal.errors import DegenerateDesignError, InputError
from gyrocal.estimators import first_moment_batch
from gyrocal.models import ScaleBias
from gyrocal.observations import ObservationSet
from gyrocal.planning.design import (
    Design,
    Rotation,
    Static,
    compare_designs,
    crb_covariance,
    d_efficiency,
    expected_observations,
    format_design_table,
    g_efficiency,
    information_matrix,
    predicted_covariance,
    predicted_std,
)
from gyrocal.simulation.windows import paper_observations

SPEED = math.pi / 3


def test_paper_six_is_d_and_g_optimal():
    d = Design.paper_six(SPEED)
    assert d_efficiency(d) == pytest.approx(1.0, abs=1e-12)
    assert g_efficiency(d) == pytest.approx(1.0, abs=1e-12)
    assert d.total_time == pytest.approx(6 * 6.0 + 5 * 3.0)


def test_other_designs_are_less_efficient():
    tilted = Design.from_axes([[1, 0.3, 0], [-1, 0.3, 0], [0, 1, 0.3], [0, -1, 0.3], [0.3, 0, 1], [0.3, 0, -1]], SPEED)
    assert 0 < d_efficiency(tilted) < 1 and 0 < g_efficiency(tilted) < 1
    diag = Design.face_diagonals(SPEED)
    assert d_efficiency(diag) < 1 and g_efficiency(diag) < 1
    one_sided = Design.from_axes(["+x", "+y", "+z"] * 2, SPEED)
    assert d_efficiency(one_sided) == 0.0 and g_efficiency(one_sided) == 0.0


def test_crb_of_the_six_design_has_the_closed_form():
    """k = 1, b = 0: each scale factor is seen by two windows of N samples, so
    sd(k) = sigma / sqrt(2 N) / omega (docs/core.md: sigma/sqrt(N) k^2/(sqrt 2 omega))."""
    sd = predicted_std(Design.paper_six(SPEED), noise_std=0.035, sample_rate=200.0)
    n = round(2 * math.pi / SPEED * 200)
    np.testing.assert_allclose(sd[:3], 0.035 / math.sqrt(2 * n) / SPEED, rtol=1e-12)


def test_noise_density_and_std_agree():
    d = Design.paper_six(SPEED)
    a = predicted_std(d, noise_std=0.035, sample_rate=200.0)
    b = predicted_std(d, noise_density=0.035 / math.sqrt(200.0), sample_rate=200.0)
    np.testing.assert_allclose(a, b, rtol=1e-12)
    with pytest.raises(InputError, match="exactly one of noise_std"):
        predicted_std(d, sample_rate=200.0)


def test_six_window_covariance_has_the_closed_form_for_any_gyro(rng):
    """Independent reference, worked by hand from eq. 1 and the norm equations: with turns of N samples
    at speed w about +-j, only axis j's noise enters the two equations of that axis, and solving them gives
    sd(k_j) = k_j^2 sigma / (w sqrt(2 N)), sd(b_j) = sigma / sqrt(2 N), no correlations. The CRB, the
    design's prediction and the estimator's own covariance must all equal it."""
    model = ScaleBias(rng.uniform(0.8, 1.2, 3), rng.uniform(-0.1, 0.1, 3))
    d = Design.paper_six(SPEED)
    n = round(2 * math.pi / SPEED * 200)
    want = np.diag(np.concatenate([model.k**4 * 0.035**2 / (SPEED**2 * 2 * n), np.full(3, 0.035**2 / (2 * n))]))
    np.testing.assert_allclose(crb_covariance(d, model, 0.035), want, rtol=1e-9, atol=1e-18)
    np.testing.assert_allclose(predicted_covariance(d, model, 0.035), want, rtol=1e-9, atol=1e-18)
    obs = expected_observations(d, model, 200.0, noise_std=0.035)
    fit = first_moment_batch(obs, noise_var=np.full(3, 0.035**2))
    np.testing.assert_allclose(fit.params[0], model.params, atol=1e-12)  # noise-free windows
    np.testing.assert_allclose(fit.covariance[0], want, rtol=1e-9, atol=1e-18)


def test_estimator_covariance_is_at_least_the_crb(rng):
    model = ScaleBias(np.array([0.8, 1.0, 1.2]), np.array([0.1, -0.1, 0.05]))
    d = Design.paper_six_static(SPEED)
    gap = predicted_covariance(d, model, 0.035) - crb_covariance(d, model, 0.035)
    assert np.linalg.eigvalsh(gap).min() > -1e-15


def test_static_waits_improve_the_biases_only():
    six, stat = predicted_std(Design.paper_six(SPEED), noise_std=0.035), predicted_std(Design.paper_six_static(SPEED), noise_std=0.035)
    np.testing.assert_allclose(stat[:3], six[:3], rtol=1e-12)
    assert np.all(stat[3:] < 0.7 * six[3:])


def test_crb_matches_monte_carlo_for_the_static_design(rng):
    """A larger design: the first-moment RMS error meets the CRB (chi-square tolerance on 400 fits)."""
    model = ScaleBias(np.array([0.9, 1.1, 1.0]), np.array([0.05, -0.05, 0.02]))
    n = 400
    obs = paper_observations(np.tile(model.k, (n, 1)), np.tile(model.b, (n, 1)), speed=SPEED, jitter=0.05,
                             misalignment=0.0, static_duration=3.0, rng=rng)
    err = first_moment_batch(obs).params - model.params
    ratio = np.sqrt((err**2).mean(axis=0)) / predicted_std(Design.paper_six_static(SPEED), model, 0.035)
    # RMS over n draws has relative sd 1/sqrt(2n) = 3.5 %; 4 sigma
    assert np.all(np.abs(ratio - 1) < 4 / math.sqrt(2 * n)), ratio


def test_information_matrix_is_symmetric_and_scales_with_noise():
    d = Design.face_diagonals(SPEED)
    a = information_matrix(d, noise_std=0.01)
    np.testing.assert_allclose(a, a.T, rtol=1e-12)
    np.testing.assert_allclose(information_matrix(d, noise_std=0.02), a / 4, rtol=1e-12)


def test_degenerate_designs_are_refused():
    with pytest.raises(DegenerateDesignError, match="no information on ky, kz"):
        predicted_std(Design.from_axes(["+x", "-x"] * 3, SPEED), noise_std=0.03)
    with pytest.raises(DegenerateDesignError, match=r"give 3 equation\(s\) for 6 parameters"):
        predicted_std(Design.from_axes(["+x", "+y", "+z"], SPEED), noise_std=0.03)
    with pytest.raises(DegenerateDesignError, match="cannot separate"):
        predicted_std(Design.from_axes(["+x", "+y", "+z"] * 2, SPEED), noise_std=0.03)


def test_design_inputs_are_checked():
    with pytest.raises(InputError, match="speed must be finite and > 0"):
        Rotation("+x", -1.0)
    with pytest.raises(InputError, match="axis must be a non-zero vector"):
        Rotation([0, 0, 0], 1.0)
    with pytest.raises(InputError, match="duration must be finite and > 0"):
        Static(0.0)
    with pytest.raises(InputError, match="non-empty sequence"):
        Design(())
    with pytest.raises(InputError, match="model must be a ScaleBias"):
        predicted_std(Design.paper_six(), model="k=1", noise_std=0.03)


def test_comparison_table():
    reports = compare_designs([Design.paper_six(), Design.paper_six_static(), Design.face_diagonals()], noise_std=0.035)
    assert [r.windows for r in reports] == [6, 12, 12]
    table = format_design_table(reports)
    assert table.count("\n") == 4 and "| paper six | 6 | 51.0 | 1.000 | 1.000 |" in table


# Independent references: the physics of the measurement, written without the estimator's Jacobian.
# A gyro with model (k, b) reads m = omega / k - b per axis (eq. 1 solved for m) plus white noise of
# sigma_j per sample; a turn holds omega = speed * u for angle / speed seconds, a static window
# omega = 0. The norm equations do not know a turn's axis u in the gyro frame, so u carries two
# nuisance angles per turn; the bound on (k, b) is the (k, b) block of the inverse of the full
# Fisher information.


def _schedule(design: Design, fs: float) -> list[tuple[float, np.ndarray, int]]:
    """(speed, axis, sample count) of every window, read off the design (speed 0 for a static one)."""
    return [(w.speed, np.asarray(w.axis), int(round(w.angle / w.speed * fs))) if isinstance(w, Rotation)
            else (0.0, np.zeros(3), int(round(w.duration * fs))) for w in design.windows]


def _normal_pair(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    e1 = np.cross(a, np.eye(3)[np.argmin(np.abs(a))])
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(a, e1)


def _samples(theta: np.ndarray, schedule) -> np.ndarray:
    """Noise-free reading of every sample (n_samples, 3); complex-safe for the complex step."""
    k, b, out, r = theta[:3], theta[3:6], [], 0
    for speed, axis, n in schedule:
        omega = np.zeros(3, dtype=theta.dtype)
        if speed > 0:
            e1, e2 = _normal_pair(axis)
            v = axis + theta[6 + 2 * r] * e1 + theta[7 + 2 * r] * e2  # the turn's tilted axis
            omega = speed * v / np.sqrt(np.sum(v * v))
            r += 1
        out.append(np.tile(omega / k - b, (n, 1)))
    return np.concatenate(out)


def _physics_crb(design: Design, model: ScaleBias, sigma: np.ndarray, fs: float) -> np.ndarray:
    """(k, b) block of the inverse Fisher information, sum over samples and axes of d m d m^T / sigma^2.

    Derivatives by the complex step (exact to rounding: no difference error to budget)."""
    schedule = _schedule(design, fs)
    theta = np.concatenate([model.params, np.zeros(2 * sum(s > 0 for s, _, _ in schedule))])
    h = 1e-30
    grads = np.array([_samples(theta + 1j * h * e, schedule).imag / h for e in np.eye(len(theta))])
    fisher = np.einsum("ptj,qtj,j->pq", grads, grads, 1.0 / sigma**2)
    return np.linalg.inv(fisher)[:6, :6]


PHYSICS_CASES = {
    "six+static": (Design.paper_six_static(SPEED), 200.0),
    "face diagonals": (Design.face_diagonals(SPEED), 200.0),
    "tilted, mixed speeds and angles": (Design((Rotation([1, 0.2, -0.1], 1.0, 5.0), Rotation([-1, 0.1, 0.3], 0.7, 7.0),
                                                Rotation([0.2, 1, 0], 1.3, 6.5), Rotation([0.1, -1, 0.2], 0.9, 6.3),
                                                Rotation([0, 0.3, 1], 1.1, 6.6), Rotation([0.2, 0.1, -1], 0.8, 5.6),
                                                Static(2.5), Rotation([1, 1, 1], 1.2, 4.0))), 150.0),
}


@pytest.mark.parametrize("case", PHYSICS_CASES)
def test_crb_equals_the_fisher_information_of_the_sample_physics(rng, case):
    """Independent reference: the Fisher information of every sample's reading under the physics above,
    differentiated numerically (complex step) and inverted, with per-axis noise that differs. Both sides are
    exact linear algebra (correlation matrices of condition < 10): rounding leaves about 1e-13, so 1e-9."""
    design, fs = PHYSICS_CASES[case]
    model = ScaleBias(rng.uniform(0.8, 1.2, 3), rng.uniform(-0.1, 0.1, 3))
    sigma = rng.uniform(0.01, 0.05, 3)
    want = _physics_crb(design, model, sigma, fs)
    got = crb_covariance(design, model, sigma, fs)
    sd = np.sqrt(np.diag(want))
    np.testing.assert_allclose(np.sqrt(np.diag(got)), sd, rtol=1e-9)
    np.testing.assert_allclose(got / np.outer(sd, sd), want / np.outer(sd, sd), atol=1e-9)  # correlations
    info = information_matrix(design, model, sigma, fs)
    np.testing.assert_allclose(info * np.outer(sd, sd), np.linalg.inv(want) * np.outer(sd, sd), atol=1e-9)


def _known_axis_crb(design: Design, model: ScaleBias, sigma: np.ndarray, fs: float) -> np.ndarray:
    """Per-axis bound with every turn's axis known: an explicit loop over axes, windows and samples."""
    crb = np.zeros((6, 6))
    for j in range(3):
        fisher = np.zeros((2, 2))
        for speed, axis, n in _schedule(design, fs):
            g = np.array([-speed * axis[j] / model.k[j] ** 2, -1.0])  # dm_j / d(k_j, b_j)
            for _ in range(n):
                fisher += np.outer(g, g) / sigma[j] ** 2
        crb[np.ix_([j, 3 + j], [j, 3 + j])] = np.linalg.inv(fisher)
    return crb


def test_known_axes_would_only_tighten_the_bound(rng):
    """Independent reference, the per-axis model with each turn's axis known (Fisher information of (k_j, b_j)
    the sum over samples of g g^T / sigma_j^2, g = (-w_j / k_j^2, -1)). design.py's bound leaves the axes
    unknown, as the norm equations do, so it can only be wider; for the paper's six turns k's bound is the same
    and b's variance three times as large (a turn about x tells b_y, b_z only when its axis is known)."""
    model = ScaleBias(rng.uniform(0.8, 1.2, 3), rng.uniform(-0.1, 0.1, 3))
    sigma, fs = rng.uniform(0.01, 0.05, 3), 200.0
    for design in (Design.paper_six_static(SPEED), Design.face_diagonals(SPEED)):
        crb = crb_covariance(design, model, sigma, fs)
        assert np.linalg.eigvalsh(crb - _known_axis_crb(design, model, sigma, fs)).min() > -1e-12 * np.trace(crb)
    six = Design.paper_six(SPEED)
    ratio = np.diag(crb_covariance(six, model, sigma, fs)) / np.diag(_known_axis_crb(six, model, sigma, fs))
    np.testing.assert_allclose(ratio, [1, 1, 1, 3, 3, 3], rtol=1e-9)


def _numpy_sessions(design: Design, model: ScaleBias, sigma: np.ndarray, fs: float, n: int, rng) -> ObservationSet:
    """n sessions of white-noise samples from plain numpy (not gyrocal.simulation), reduced to window moments."""
    mean, mean_sq, noise_var, rate, count = [], [], [], [], []
    for speed, axis, m in _schedule(design, fs):
        x = speed * axis / model.k - model.b + sigma * rng.standard_normal((n, m, 3))
        mean.append(x.mean(axis=1))
        mean_sq.append((x * x).mean(axis=1))
        noise_var.append(np.diff(x, axis=1).var(axis=1) / 2)
        rate.append(speed)
        count.append(m)
    count = np.array(count, dtype=float)
    return ObservationSet(np.stack(mean, 1), np.stack(mean_sq, 1), np.stack(noise_var, 1), np.array(rate), count,
                          count / fs, np.array(rate) == 0)


def test_estimator_variance_meets_the_physics_bound_over_seeded_sessions():
    """Independent reference: 2000 sessions drawn with plain numpy, fitted by the production estimator; the
    sample variance of every k and b must equal the bound of the sample physics (_physics_crb), two-sided:
    the sample variance of n normal draws has relative sd sqrt(2 / (n - 1)) = 3.2 %; 4 of those. For this
    design the estimator is efficient (its sandwich equals the bound), so no margin is owed."""
    design, fs, n = Design.paper_six_static(SPEED), 50.0, 2000
    model = ScaleBias(np.array([0.9, 1.1, 1.0]), np.array([0.05, -0.05, 0.02]))
    sigma = np.full(3, 0.035)
    err = first_moment_batch(_numpy_sessions(design, model, sigma, fs, n, np.random.default_rng(20))).params - model.params
    bound = np.diag(_physics_crb(design, model, sigma, fs))
    ratio = err.var(axis=0, ddof=1) / bound
    assert np.all(np.abs(ratio - 1) < 4 * math.sqrt(2 / (n - 1))), ratio
    assert np.all(np.abs(err.mean(axis=0)) < 4 * np.sqrt(bound / n)), err.mean(axis=0)  # unbiased
