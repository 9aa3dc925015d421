"""Estimators: the contract suite, class/batch agreement, Algorithm 1 against LM, and errors."""

import math

import numpy as np
import pytest

from gyrocal.errors import ConvergenceError, DegenerateDesignError, NonFiniteInputError, NonPhysicalEstimateError
from gyrocal.estimators import (
    Algorithm1,
    FirstMoment,
    PaperLM,
    algorithm1_batch,
    first_moment_batch,
    make_estimator,
    paper_lm_batch,
)
from gyrocal.estimators._checks import require_positive_k2
from gyrocal.estimators.paper_model import gamma, regressors
from gyrocal.models import ScaleBias
from gyrocal.observations import ObservationSet
from gyrocal.planning.design import Design, crb_covariance
from gyrocal.simulation.windows import PAPER_AXES, paper_observations

SPEED = math.pi / 3  # 60 deg/s, the servo method of Wang et al., section III-A
SIGMA = 0.035


def truth(rng, n):
    return rng.uniform(0.8, 1.2, (n, 3)), rng.uniform(-0.1, 0.1, (n, 3))


def crb_std(k, b, design, sigma=SIGMA):
    return np.array([np.sqrt(np.diag(crb_covariance(design, ScaleBias(ki, bi), sigma))) for ki, bi in zip(k, b)])


def _assert_unit_rms(z: np.ndarray) -> None:
    """Two-sided: RMS of m standard-normal z is 1 +- 1/sqrt(2m); 4 of those (too wide fails as well as too narrow)."""
    rms = float(np.sqrt(np.mean(np.square(z))))
    assert abs(rms - 1) < 4 / math.sqrt(2 * z.size), rms


@pytest.mark.parametrize("static", [0.0, 3.0], ids=["six", "six+static"])
def test_contract_first_moment_truth_within_4_sigma(rng, static):
    """Reference: the simulated truth of 20 gyros; the reported 1-sigma judged two-sided by the RMS of 120 z."""
    k, b = truth(rng, 20)
    obs = paper_observations(k, b, speed=SPEED, static_duration=static, rng=rng)
    fit = FirstMoment().fit_batch(obs)
    z = (fit.params - np.concatenate([k, b], 1)) / fit.std
    assert np.all(np.abs(z) < 4), np.abs(z).max()
    _assert_unit_rms(z)
    assert fit.converged.all()


@pytest.mark.parametrize("estimator", [Algorithm1(tol=1e-12), PaperLM()], ids=["algorithm1", "lm"])
def test_contract_paper_estimators_truth_within_4_sigma(rng, estimator):
    """Without jitter the mean of squares adds only the sample variance of the noise, which
    scales k by sqrt(w^2 / (w^2 + sum k^2 s^2)) (see test_accuracy); the rest is first-moment noise.
    Reference: that expected k and the true b of 20 gyros, in units of the CRB (RMS of 120 z, two-sided)."""
    k, b = truth(rng, 20)
    obs = paper_observations(k, b, speed=SPEED, jitter=0.0, misalignment=0.1, rng=rng)
    fit = estimator.fit_batch(obs)
    c = np.einsum("bj,bnj->bn", k**2, obs.mean_sq - obs.mean**2).mean(axis=1)
    k_expected = k * np.sqrt(SPEED**2 / (SPEED**2 + c))[:, None]
    sd = crb_std(k, b, Design.paper_six(SPEED))
    z = (fit.params - np.concatenate([k_expected, b], 1)) / sd
    assert np.all(np.abs(z) < 4), np.abs(z).max()
    _assert_unit_rms(z)


@pytest.mark.parametrize("method", ["first-moment", "algorithm1", "lm"])
def test_corrected_readings_give_true_rates(rng, method):
    """With (almost) no noise every estimator recovers the model, so corrected readings are the true rates."""
    k, b = truth(rng, 1)
    obs = paper_observations(k, b, speed=SPEED, noise_std=1e-9, jitter=0.0, rng=rng)
    model = make_estimator(method).fit(obs).model
    w = rng.normal(0, 2, (100, 3))
    raw = ScaleBias(k[0], b[0]).distort(w)
    # error ~ sigma / sqrt(n) * |w| = 3e-11 * |w|; 1e-8 leaves room for the sigma^2 bias of the paper form
    np.testing.assert_allclose(model.correct(raw), w, rtol=0, atol=1e-8 * 6)


@pytest.mark.parametrize("static", [0.0, 3.0], ids=["closed-form", "lm-path"])
def test_class_and_batch_function_agree_item_by_item(rng, static):
    k, b = truth(rng, 5)
    obs = paper_observations(k, b, speed=SPEED, static_duration=static, rng=rng)
    batch = first_moment_batch(obs)
    # Equal up to rounding: the closed form takes one pivot order per batch, from its first gyro.
    for i in range(5):
        one = FirstMoment().fit(obs.take([i]))
        np.testing.assert_allclose(one.model.params, batch.item(i).model.params, rtol=1e-13, atol=1e-15)
        np.testing.assert_allclose(one.covariance, batch.covariance[i], rtol=1e-10)
        assert one.iterations == batch.iterations[i]
    for est, fn in ((Algorithm1(), algorithm1_batch), (PaperLM(), paper_lm_batch)):
        full = fn(obs)
        for i in range(5):
            np.testing.assert_array_equal(est.fit(obs.take([i])).model.params, full.item(i).model.params)


def test_closed_form_equals_levenberg_marquardt(rng):
    """Six equations, six unknowns: the closed form and LM find the same zero-residual solution."""
    k, b = truth(rng, 300)
    obs = paper_observations(k, b, speed=SPEED, rng=rng)
    fast, slow = first_moment_batch(obs), first_moment_batch(obs, closed_form=False)
    np.testing.assert_allclose(fast.params, slow.params, rtol=0, atol=1e-12)
    np.testing.assert_allclose(fast.covariance, slow.covariance, rtol=1e-9, atol=0)
    np.testing.assert_allclose(fast.residuals, 0, atol=1e-10)
    np.testing.assert_array_equal(fast.history[:, -1], fast.params)
    # and the closed form solved every item itself (its fallback to LM would hide an error in it)
    from gyrocal.estimators._exact6 import exact_six

    solved = exact_six(obs.mean, obs.rate, obs.count, None, obs.noise_var)
    assert solved[4].all()
    np.testing.assert_allclose(np.hstack([solved[0], solved[1]]), slow.params, rtol=0, atol=1e-12)


def test_closed_form_falls_back_for_items_it_cannot_solve(rng, monkeypatch):
    """Items the closed form flags get Levenberg-Marquardt's answer, iterations and covariance."""
    from gyrocal.estimators import first_moment

    real = first_moment.exact_six

    def flag_every_other(*args, **kwargs):
        out = list(real(*args, **kwargs))
        out[4] = out[4].copy()
        out[4][::2] = False
        return tuple(out)

    k, b = truth(rng, 6)
    obs = paper_observations(k, b, speed=SPEED, rng=rng)
    slow = first_moment_batch(obs, closed_form=False)
    fast = first_moment_batch(obs)
    monkeypatch.setattr(first_moment, "exact_six", flag_every_other)
    mixed = first_moment_batch(obs)
    np.testing.assert_array_equal(mixed.iterations[::2], slow.iterations[::2])
    np.testing.assert_array_equal(mixed.iterations[1::2], fast.iterations[1::2])
    np.testing.assert_allclose(mixed.params, slow.params, atol=1e-12)
    np.testing.assert_allclose(mixed.covariance, slow.covariance, rtol=1e-9)
    assert mixed.converged.all()


def test_algorithm1_equals_lm_with_six_observations(rng):
    k, b = truth(rng, 200)
    obs = paper_observations(k, b, speed=SPEED, rng=rng)
    a1, lm = algorithm1_batch(obs, tol=1e-12), paper_lm_batch(obs)
    np.testing.assert_allclose(a1.params, lm.params, rtol=0, atol=1e-9)


def paper_cost(obs, params):
    X, Y = regressors(obs)
    k, b = params[:, :3], params[:, 3:]
    beta = np.concatenate([k**2, 2 * k**2 * b], axis=1)
    r = np.einsum("bni,bi->bn", X, beta) + gamma(beta)[:, None] - Y
    return (r**2).sum(axis=1)


def test_algorithm1_differs_from_lm_with_twelve_observations(rng):
    """Beyond six, Algorithm 1's fixed point ignores d beta0 / d beta and is not the LS optimum.

    Measured at the paper's settings (12 turns: the six, twice): RMS difference ~2e-7 rad/s in
    b and ~2e-8 in k, about 1e-3 .. 1e-4 of their standard deviations (docs/core.md).
    """
    k, b = truth(rng, 200)
    obs = paper_observations(k, b, speed=SPEED, axes=PAPER_AXES * 2, rng=rng)
    a1, lm = algorithm1_batch(obs, tol=1e-12), paper_lm_batch(obs)
    rms = np.sqrt(((a1.params - lm.params) ** 2).mean(axis=0))
    assert np.all(rms[:3] > 2e-9) and np.all(rms[:3] < 2e-7)
    assert np.all(rms[3:] > 2e-8) and np.all(rms[3:] < 2e-6)
    cost_a1, cost_lm = paper_cost(obs, a1.params), paper_cost(obs, lm.params)
    assert np.all(cost_lm <= cost_a1 * (1 + 1e-12))
    assert np.mean(cost_lm < cost_a1) > 0.9


def test_batch_lm_matches_scipy_least_squares(rng):
    from scipy.optimize import least_squares

    k, b = truth(rng, 10)
    obs = paper_observations(k, b, speed=SPEED, axes=PAPER_AXES * 2, rng=rng)
    ours = paper_lm_batch(obs)
    X, Y = regressors(obs)
    for i in range(10):
        def fun(beta, i=i):
            return X[i] @ beta + gamma(beta[None])[0] - Y[i]

        beta0 = np.linalg.lstsq(X[i], Y[i], rcond=None)[0]
        ref = least_squares(fun, beta0, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15).x
        np.testing.assert_allclose(ours.k[i], np.sqrt(ref[:3]), rtol=1e-9)
        np.testing.assert_allclose(ours.b[i], ref[3:] / (2 * ref[:3]), rtol=0, atol=1e-9)


def test_results_are_frozen(rng):
    k, b = truth(rng, 2)
    fit = first_moment_batch(paper_observations(k, b, speed=SPEED, rng=rng))
    with pytest.raises(ValueError):
        fit.k[0, 0] = 1.0
    with pytest.raises(ValueError):
        fit.covariance[0, 0, 0] = 1.0
    one = fit.item(0)
    for arrays in (fit, one):
        for name in ("residuals", "history", "noise_std", "covariance"):
            with pytest.raises(ValueError):
                getattr(arrays, name).flat[0] = 1.0
    for name in ("iterations", "converged"):
        with pytest.raises(ValueError):
            getattr(fit, name)[0] = 0


# --- errors: one sentence naming the argument (docs/core.md, Estimators) ---


def test_all_rotations_about_one_axis_is_degenerate(rng):
    obs = paper_observations(np.ones((1, 3)), np.zeros((1, 3)), speed=SPEED, axes=("+x", "-x") * 3, rng=rng)
    for method in ("first-moment", "algorithm1", "lm"):
        with pytest.raises(DegenerateDesignError, match="the y axis|cannot separate|no information"):
            make_estimator(method).fit(obs)


def test_fewer_observations_than_parameters(rng):
    obs = paper_observations(np.ones((1, 3)), np.zeros((1, 3)), speed=SPEED, axes=PAPER_AXES[:5], rng=rng)
    for method in ("first-moment", "algorithm1", "lm"):
        with pytest.raises(DegenerateDesignError, match=r"give 5 equation\(s\) for 6 parameters"):
            make_estimator(method).fit(obs)


def test_non_finite_input_is_refused(rng):
    obs = paper_observations(np.ones((1, 3)), np.zeros((1, 3)), speed=SPEED, rng=rng)
    mean = np.array(obs.mean)
    mean[0, 2, 1] = np.inf
    with pytest.raises(NonFiniteInputError, match=r"mean holds 1 NaN or infinite value\(s\), first at index \(0, 2, 1\)"):
        ObservationSet(mean, obs.mean_sq, obs.noise_var, obs.rate, obs.count, obs.duration, obs.static)


def test_non_positive_k2_is_refused(rng):
    with pytest.raises(NonPhysicalEstimateError, match=r"Algorithm 1 estimated k\^2 = -0.5 <= 0 \(batch item 0, axis y\)"):
        require_positive_k2(np.array([[1.0, -0.5, 1.0]]), "Algorithm 1")
    # A reference far too slow for the readings drives Algorithm 1's k^2 negative.
    obs = paper_observations(np.ones((1, 3)), np.full((1, 3), 0.1), speed=SPEED, rng=rng)
    rate = np.array(obs.rate)
    rate[0, ::2] = 0.01  # +x, +y, +z claimed at 0.01 rad/s
    bad = ObservationSet(obs.mean, obs.mean_sq, obs.noise_var, rate, obs.count, obs.duration, obs.static)
    with pytest.raises(NonPhysicalEstimateError, match=r"k\^2 = .* <= 0"):
        Algorithm1().fit(bad)


def test_non_convergence_reports_iterations(rng):
    obs = paper_observations(np.full((1, 3), 1.1), np.full((1, 3), 0.1), speed=SPEED, rng=rng)
    with pytest.raises(ConvergenceError, match="did not converge after 1 iterations") as info:
        Algorithm1(max_iter=1).fit(obs)
    assert info.value.iterations == 1
    with pytest.raises(ConvergenceError, match="first-moment least squares did not converge after 1 iterations"):
        FirstMoment(max_iter=1).fit(obs)
    with pytest.raises(ConvergenceError, match="did not converge after 1 iterations"):
        PaperLM(max_iter=1).fit(obs)
