"""White noise from first differences (gyrocal._white), the one definition its callers share.

Reference: seeded white noise of known standard deviation, with a drift and steps added that the
estimates must not see. Tolerances from the estimates' predicted standard deviations: half the mean
square of n differences of white noise of variance s^2 has variance 3 s^4 / n (var d^2 = 8 s^4, and
neighbouring d^2 correlate by 1/4); the MAD's sigma has asymptotic relative variance 1.36 / n for
independent values, at most twice that for differences whose only correlation is -1/2 at lag 1.
"""

from __future__ import annotations

import math

import numpy as np

from gyrocal._white import difference_variance, robust_difference_std

N, SIGMA = 200_000, 0.03


def _noise(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(N) / 100.0
    return SIGMA * rng.standard_normal((N, 3)) + 1e-3 * t[:, None] ** 1.5 + np.array([0.5, -2.0, 0.0])


def test_half_the_mean_square_of_differences_is_the_white_variance():
    d = np.diff(_noise(1), axis=0)
    sd = SIGMA**2 * math.sqrt(3.0 / len(d))
    assert np.all(np.abs(difference_variance(d) - SIGMA**2) < 5 * sd)


def test_the_robust_estimate_ignores_steps_that_the_mean_square_sees():
    x = _noise(2)
    x[::1000] += 5.0  # a spike every 1000 samples: 2 differences in 1000 are huge
    d = np.diff(x, axis=0)
    rel_sd = math.sqrt(2 * 1.36 / len(d))
    assert np.all(np.abs(robust_difference_std(d) / SIGMA - 1) < 5 * rel_sd + 2 * 2e-3)  # + the spikes' share
    assert np.all(difference_variance(d) > 10 * SIGMA**2)


def test_empty_differences_give_zero_and_batches_reduce_along_their_axis():
    assert difference_variance(np.zeros(0)) == 0.0
    batch = np.diff(_noise(3)[:2000].reshape(4, 500, 3), axis=1)
    expected = np.stack([difference_variance(b) for b in batch])
    np.testing.assert_allclose(difference_variance(batch, axis=1), expected, rtol=1e-12)
