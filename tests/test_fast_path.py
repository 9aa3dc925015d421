"""The fast path draws the same window statistics, in law, as the per-sample generator.

References: the per-sample simulation (two-sample Kolmogorov-Smirnov tests) and the moments of the window
statistics derived by hand in the comments.
"""

import math

import numpy as np
import pytest
from scipy import stats

from gyrocal.errors import InputError
from gyrocal.estimators import Algorithm1, FirstMoment, PaperLM
from gyrocal.simulation.fast import noise_var_dof, simulate_observations, window_statistics

DRAWS = 5000
SPEEDS = (math.pi / 3, 2.0, 3.0)
ESTIMATORS = (Algorithm1(), PaperLM(), FirstMoment())
# 3 estimators x 6 parameters = 18 KS tests per speed. A correct fast path fails a
# single test at p < 0.01 one time in a hundred, so the family of 18 is held to a
# Bonferroni threshold: family-wise false alarms stay at 1 % per speed.
FAMILY = len(ESTIMATORS) * 6
ALPHA = 0.01


def _truth(rng, n):
    return rng.uniform(0.8, 1.2, (n, 3)), rng.uniform(-0.1, 0.1, (n, 3))


@pytest.mark.parametrize("speed", SPEEDS)
def test_error_distributions_match_per_sample_path(speed, rng):
    k, b = _truth(rng, DRAWS)
    kw = dict(speed=speed, noise_std=0.2, rng=rng)
    slow = simulate_observations(k, b, fast=False, **kw)
    fast = simulate_observations(k, b, **kw)
    truth = np.concatenate([k, b], axis=1)
    pvalues = []
    for est in ESTIMATORS:
        e_slow = est.fit_batch(slow).params - truth
        e_fast = est.fit_batch(fast).params - truth
        pvalues += [stats.ks_2samp(e_slow[:, j], e_fast[:, j]).pvalue for j in range(6)]
    assert min(pvalues) > ALPHA / FAMILY, np.round(pvalues, 4)


def test_reported_uncertainty_matches_per_sample_path(rng):
    """noise_var (drawn from a two-moment match) gives the same first-moment covariance."""
    k, b = _truth(rng, 3000)
    kw = dict(speed=2.0, noise_std=0.1, rng=rng)
    std_slow = FirstMoment().fit_batch(simulate_observations(k, b, fast=False, **kw)).std
    std_fast = FirstMoment().fit_batch(simulate_observations(k, b, **kw)).std
    p = [stats.ks_2samp(std_slow[:, j], std_fast[:, j]).pvalue for j in range(6)]
    assert min(p) > ALPHA / 6, np.round(p, 4)


def test_window_statistics_moments(rng):
    """Mean, variance and cross-axis covariance of mean_sq against their closed forms."""
    n, draws, sd, jitter = 50, 40000, np.array([0.1, 0.2, 0.05]), 0.05
    c, d = np.array([1.0, -0.2, 0.3]), np.array([1.2, 0.1, 0.0])
    mean, mean_sq, noise_var = window_statistics(np.broadcast_to(c, (draws, 1, 3)), d, [n], sd, jitter, rng)
    cov = jitter**2 * np.outer(d, d) + np.diag(sd**2)
    # E[mean_sq] = c^2 + sd^2 / n + (n - 1) Sigma_aa / n
    expect = c**2 + sd**2 / n + (n - 1) * np.diag(cov) / n
    se = mean_sq[:, 0].std(axis=0) / math.sqrt(draws)
    assert np.all(np.abs(mean_sq[:, 0].mean(axis=0) - expect) < 4 * se)
    # Scatter part: Var = 2 (n - 1) Sigma_aa^2 / n^2; Cov(x, y) = 2 (n - 1) Sigma_xy^2 / n^2
    scatter = mean_sq[:, 0] - mean[:, 0] ** 2
    emp = np.cov(scatter.T)
    pred = 2 * (n - 1) * cov**2 / n**2
    rel_se = math.sqrt(2.0 / draws) * 2  # sampling error of a variance estimate of a skewed law, generous x2
    assert np.allclose(emp[np.diag_indices(3)], pred[np.diag_indices(3)], rtol=4 * rel_se)
    assert abs(emp[0, 1] - pred[0, 1]) < 4 * rel_se * math.sqrt(pred[0, 0] * pred[1, 1])
    # noise_var has mean Sigma_aa exactly
    se_nv = noise_var[:, 0].std(axis=0) / math.sqrt(draws)
    assert np.all(np.abs(noise_var[:, 0].mean(axis=0) - np.diag(cov)) < 4 * se_nv)


def test_noise_var_dof_matches_first_difference_variance(rng):
    n, draws = 40, 40000
    x = rng.standard_normal((draws, n))
    stat = (np.diff(x, axis=1) ** 2).mean(axis=1) / 2
    nu = noise_var_dof(n)
    # chi2_nu / nu has variance 2 / nu
    assert stat.var() == pytest.approx(2.0 / nu, rel=4 * math.sqrt(2.0 / draws) * 2)


def test_fast_path_with_static_windows_matches_layout(rng):
    obs = simulate_observations(np.ones((4, 3)), np.zeros((4, 3)), speed=1.0, static_duration=2.0, rng=rng)
    ref = simulate_observations(np.ones((4, 3)), np.zeros((4, 3)), speed=1.0, static_duration=2.0, rng=rng,
                                fast=False)
    assert obs.mean.shape == ref.mean.shape == (4, 12, 3)
    np.testing.assert_array_equal(obs.static, ref.static)
    np.testing.assert_array_equal(obs.count, ref.count)
    assert np.all(obs.rate[:, obs.static] == 0)


def test_window_statistics_rejects_bad_input(rng):
    with pytest.raises(InputError, match="count"):
        window_statistics(np.zeros((2, 3)), np.zeros((2, 3)), [2, 2], 0.1, 0.0, rng)
    with pytest.raises(InputError, match="jitter"):
        window_statistics(np.zeros((1, 3)), np.zeros((1, 3)), [10], 0.1, -1.0, rng)
    with pytest.raises(InputError, match="k must be > 0"):
        simulate_observations(-np.ones((1, 3)), np.zeros((1, 3)), speed=1.0, rng=rng)
