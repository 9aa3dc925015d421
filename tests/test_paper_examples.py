"""The servo method's worked example (section III-A) and the three Table I cases.

Each case is simulated 200 times at the paper's normal conditions (200 Hz, 60 deg/s,
0.035 rad/s, 5 % jitter, tilts up to 0.1 rad). Table I's convergence behaviour is
checked against the fixed-point analysis in docs/core.md.
"""

import math

import numpy as np
import pytest

from gyrocal.estimators import algorithm1_batch, first_moment_batch
from gyrocal.estimators.paper_model import regressors
from gyrocal.simulation.windows import paper_observations

SPEED, SIGMA, JITTER, RUNS = math.pi / 3, 0.035, 0.05, 200
CASES = {
    "worked example": ([0.9070, 1.0501, 0.8734], [0.0528, 0.0813, -0.0992]),
    "Table I.1 high scale": ([1.9074, 1.9529, 1.5635], [0.0827, 0.0265, -0.0805]),
    "Table I.2 high bias": ([1.0979, 1.1052, 0.9851], [-0.1046, 0.1995, 0.1565]),
    "Table I.3 both": ([1.5044, 1.6494, 1.5282], [0.1483, -0.1282, 0.1794]),
}


def simulate(k, b, seed, speed=SPEED):
    rng = np.random.default_rng(seed)
    return paper_observations(np.tile(k, (RUNS, 1)), np.tile(b, (RUNS, 1)), speed=speed, noise_std=SIGMA,
                              jitter=JITTER, misalignment=0.1, rng=rng)


@pytest.mark.parametrize("case", CASES)
def test_first_moment_recovers_the_case(case):
    k, b = map(np.array, CASES[case])
    fit = first_moment_batch(simulate(k, b, seed=sorted(CASES).index(case)))
    err = fit.params - np.concatenate([k, b])
    assert np.all(np.abs(err[0]) < 4 * fit.std[0])  # one run, as in the paper's worked example
    se = err.std(axis=0) / math.sqrt(RUNS)
    assert np.all(np.abs(err.mean(axis=0)) < 4 * se)  # unbiased over the 200 runs
    np.testing.assert_allclose(err.std(axis=0), np.sqrt((fit.std**2).mean(axis=0)), rtol=4 / math.sqrt(2 * RUNS))


@pytest.mark.parametrize("case", CASES)
def test_algorithm1_recovers_the_case_with_its_predicted_bias(case):
    k, b = map(np.array, CASES[case])
    obs = simulate(k, b, seed=10 + sorted(CASES).index(case))
    fit = algorithm1_batch(obs)
    n = obs.count[0]
    c = (JITTER * SPEED) ** 2 * (n - 1) / n + SIGMA**2 * np.sum(k**2)  # see test_accuracy
    want = np.concatenate([k * math.sqrt(SPEED**2 / (SPEED**2 + c)), b])
    err = fit.params - want
    assert np.all(np.abs(err.mean(axis=0)) < 4 * err.std(axis=0) / math.sqrt(RUNS))


@pytest.mark.parametrize("case", CASES)
def test_algorithm1_converges_at_the_fixed_point_rate(case):
    """beta(n+1) - beta* = -(gamma(beta(n)) - gamma*) v with v = X^-1 1, so near the fixed
    point each update shrinks the step by rho = |grad gamma(beta*) . v|; roughly beta0 / w^2
    (gamma is homogeneous of degree 1 and v ~ beta / w^2), which sets the iteration count."""
    k, b = map(np.array, CASES[case])
    obs = simulate(k, b, seed=20 + sorted(CASES).index(case))
    fit = algorithm1_batch(obs, tol=1e-13)
    X, _ = regressors(obs)
    v = np.linalg.solve(X, np.ones(X.shape[:2])[..., None])[..., 0]
    beta = np.concatenate([fit.k**2, 2 * fit.k**2 * fit.b], axis=1)
    grad = np.concatenate([-(beta[:, 3:] ** 2) / (4 * beta[:, :3] ** 2), beta[:, 3:] / (2 * beta[:, :3])], axis=1)
    rho = np.abs(np.sum(grad * v, axis=1))
    h = fit.history
    hb = np.concatenate([h[..., :3] ** 2, 2 * h[..., :3] ** 2 * h[..., 3:]], axis=-1)
    steps = np.abs(np.diff(hb, axis=1)).sum(axis=-1)  # (runs, updates)
    np.testing.assert_allclose(steps[:, 2] / steps[:, 1], rho, rtol=0.05)
    beta0 = np.sum(k**2 * b**2)
    assert 0.7 < np.median(rho) / (beta0 / SPEED**2) < 1.3
    # Updates until sum |delta beta| < 1e-6 (the paper's test) follow from rho and the first step.
    predicted = 1 + np.ceil(np.log(1e-6 / steps[:, 0]) / np.log(rho))
    counts = algorithm1_batch(obs, tol=1e-6).iterations
    assert np.mean(np.abs(counts - predicted) <= 1) > 0.95
