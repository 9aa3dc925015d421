"""Error figures, their bootstrap 1-sigma and the noise estimates behind the reference floor.

Independent references: closed-form variances (AR(1) long-run variance, the asymptotic
variance of a sample quantile), Monte Carlo spreads over seeded draws, and the true rates
of the simulation (the truth-based MSE of a calibrated gyro).
"""

import math

import numpy as np
import pytest
from scipy.signal import lfilter
from scipy.stats import norm
from verify_pairs import make_pair

from gyrocal import ScaleBias
from gyrocal.models import correct
from gyrocal.verify import error_metrics, verify_rates
from gyrocal.verify.bootstrap import BlockBootstrap, optimal_block_length
from gyrocal.verify.whitenoise import second_difference_noise


def test_block_length_is_one_for_white_noise_and_long_for_ar1(rng):
    assert optimal_block_length(rng.standard_normal(50_000)) == 1
    ar = lfilter([1.0], [1.0, -0.95], rng.standard_normal(50_000))
    assert optimal_block_length(ar) > 50  # correlation time 1 / (1 - 0.95) = 20 samples


def test_bootstrap_sd_of_a_mean_matches_the_ar1_long_run_variance():
    """AR(1), phi = 0.9: sd of the mean = sigma / (1 - phi) / sqrt(n) (unit innovations)."""
    n, phi = 20_000, 0.9
    est = []
    for seed in range(40):
        rng = np.random.default_rng(seed)
        x = lfilter([1.0], [1.0, -phi], rng.standard_normal(n))
        est.append(BlockBootstrap(n, optimal_block_length(x), 400, rng).means(x[:, None]).std())
    expected = 1.0 / (1.0 - phi) / math.sqrt(n)
    # block bootstraps run a little low (they cut correlation at block edges): within 20 %
    assert np.mean(est) == pytest.approx(expected, rel=0.2)


def test_bootstrap_sd_of_the_99th_percentile_matches_asymptotics(rng):
    """iid |N(0,1)|: sd of the q-quantile = sqrt(q (1 - q) / n) / density at the quantile."""
    n, q = 40_000, 0.99
    x = np.abs(rng.standard_normal(n))
    boot = BlockBootstrap(n, 1, 1000, rng).quantiles(x, q)
    xq = norm.ppf(0.5 + q / 2)
    expected = math.sqrt(q * (1 - q) / n) / (2 * norm.pdf(xq))
    assert boot.mean() == pytest.approx(np.quantile(x, q), abs=4 * expected)
    assert boot.std() == pytest.approx(expected, rel=0.2)  # 1000 replicates, quantised histogram


def test_second_difference_noise_sees_through_smooth_motion():
    """White noise on 1 Hz motion of 1 rad/s: the robust sigma within 4 of its own 1-sigma, over 30 seeds."""
    t = np.arange(20_000) / 200.0
    motion = np.stack([np.sin(2 * np.pi * t), np.cos(2 * np.pi * 0.3 * t), 0.2 * t], 1)
    est, err = [], []
    for seed in range(30):
        rng = np.random.default_rng(seed)
        noise = second_difference_noise(t, motion + 0.01 * rng.standard_normal(motion.shape))
        est.append(noise.std)
        err.append(noise.std_err)
    est, err = np.array(est), np.array(err)
    assert np.all(np.abs(est - 0.01) < 4 * err)
    assert np.std(est, axis=0) == pytest.approx(err.mean(axis=0), rel=0.35)  # 30 draws: sd known to 13 %


def test_metrics_of_known_errors(rng):
    """Constant errors: MSE, RMSE, percentile and reduction follow by hand."""
    n = 5000
    before = np.tile([2.0, -1.0, 0.5], (n, 1))
    after = np.tile([0.2, 0.1, -0.05], (n, 1))
    m = error_metrics(before, after, np.full(3, 0.001), np.zeros(3), rng=rng, replicates=50)
    assert np.allclose(m.values["mse_before"], [4.0, 1.0, 0.25])
    assert np.allclose(m.values["rmse_after"], [0.2, 0.1, 0.05])
    assert np.allclose(m.values["p99_after"], [0.2, 0.1, 0.05])
    assert np.allclose(m.values["reduction_pct"], [99.0, 99.0, 99.0])
    assert np.allclose(m.values["mse_after_net"], [0.039, 0.009, 0.0015])
    assert np.allclose(m.std["mse_after"], 0.0, atol=1e-12)


def test_figures_before_calibration_are_nan_without_raw_rates(rng):
    m = error_metrics(None, rng.standard_normal((3000, 3)), np.zeros(3), np.zeros(3), rng=rng, replicates=20)
    assert np.isnan(m.values["mse_before"]).all() and np.isfinite(m.values["mse_after"]).all()
    assert math.isnan(m.axis(0)["reduction_pct"])


def _verified(pair, cal: ScaleBias, seed: int, ref_gyro=None, replicates: int = 200):
    calibrated = correct(cal.matrix, cal.offset, pair.test.gyro)
    ref_gyro = pair.ref.gyro if ref_gyro is None else ref_gyro
    report, series = verify_rates(pair.test.t, pair.test.gyro, calibrated, pair.ref.t, ref_gyro, units="rad/s",
                                  seed=seed, replicates=replicates)
    truth = np.stack([np.interp(series.t, pair.test.t, pair.rates[:, j]) for j in range(3)], 1)
    return report, series, truth


def test_mse_after_net_of_the_floor_equals_the_truth_based_mse():
    """One session, 16 reference-noise draws with a reference as noisy as the test gyro's calibration error.

    The truth-based MSE is that of the calibrated readings against the true rates at the
    test times. The measured MSE holds the reference's noise on top; net of the floor it
    must be unbiased: mean difference within 4 standard errors over the draws.
    """
    rng = np.random.default_rng(11)
    true = ScaleBias(k=(1.01, 0.99, 1.02), b=(0.02, -0.01, 0.015))
    cal = ScaleBias(k=true.k * (1 + np.array([2e-3, -1e-3, 1.5e-3])), b=true.b + [4e-3, -3e-3, 2e-3])
    base = make_pair(rng, duration=40.0, noise_test=0.01, noise_ref=0.0, offset=1.3, drift=30.0, model=true)
    diffs, floors = [], []
    for seed in range(16):
        noisy = np.asarray(base.ref.gyro) + 0.006 * np.random.default_rng(seed).standard_normal(base.ref.gyro.shape)
        report, series, truth = _verified(base, cal, seed, ref_gyro=noisy)
        truth_mse = np.mean((series.calibrated - truth) ** 2, axis=0)
        diffs.append(report.metrics.values["mse_after_net"] - truth_mse)
        floors.append(report.metrics.values["reference_floor"])
    diffs = np.array(diffs)
    assert np.mean(floors) > 0.1 * np.mean(truth_mse)  # the floor matters here: without it the test would fail
    assert np.all(np.abs(diffs.mean(axis=0)) < 4 * diffs.std(axis=0, ddof=1) / math.sqrt(len(diffs)))


@pytest.mark.slow
def test_bootstrap_sigma_of_the_mse_matches_repeated_sessions():
    """16 sessions of random smooth motion (a new motion each time): the spread of the MSE after calibration
    against the mean bootstrap 1-sigma."""
    true = ScaleBias(k=(1.01, 0.99, 1.02), b=(0.02, -0.01, 0.015))
    cal = ScaleBias(k=true.k * 1.003, b=true.b + 0.004)
    mse, sd = [], []
    for seed in range(16):
        pair = make_pair(np.random.default_rng(seed), duration=40.0, noise_test=0.01, noise_ref=0.001, model=true)
        report, _, _ = _verified(pair, cal, seed)
        mse.append(report.metrics.values["mse_after"])
        sd.append(report.metrics.std["mse_after"])
    ratio = np.std(mse, axis=0, ddof=1) / np.mean(sd, axis=0)
    assert np.all((ratio > 0.5) & (ratio < 1.6)), ratio  # 16 sessions: a sample sd is known to +-18 % (1-sigma)
