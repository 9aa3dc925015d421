"""Experimental design: information, CRB, efficiencies, and the CRB against Monte Carlo."""

import math

import numpy as np
import pytest

from gyrocal.design import (
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
from gyrocal.errors import DegenerateDesignError, InputError
from gyrocal.estimators import first_moment_batch
from gyrocal.models import ScaleBias
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
