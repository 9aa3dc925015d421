"""Calibrations of one unit compared in units of their combined 1-sigma.

Independent references: calibrations drawn from the truth with known covariances, whose
differences must follow the chi-square distribution; the Jacobian of the scale-bias to
Kg mapping against finite differences; thermal tables made from one simulated truth.
"""

import math

import numpy as np
import pytest
from scipy.stats import chi2

from gyrocal import Affine, Calibration, ScaleBias
from gyrocal.errors import InputError
from gyrocal.simulation.thermal_truth import ThermalTruth
from gyrocal.thermal import ThermalCalibration, fit_smooth
from gyrocal.verify.compare import _scale_bias_to_kg, compare_calibrations

TRUE = ScaleBias(k=(1.0069, 0.9960, 0.9955), b=(0.0442, -0.0089, 0.0076))


def _random_cov(rng, p: int, scale: np.ndarray) -> np.ndarray:
    a = rng.standard_normal((p, p))
    corr = a @ a.T + p * np.eye(p)
    d = np.sqrt(np.diag(corr))
    return corr / np.outer(d, d) * np.outer(scale, scale)


def _draw(rng, cov) -> Calibration:
    params = TRUE.params + np.linalg.cholesky(cov) @ rng.standard_normal(6)
    return Calibration(model=ScaleBias.from_params(params), input_units="rad/s", output_units="rad/s", covariance=cov)


def test_differences_follow_chi_square_with_full_covariances():
    """200 pairs drawn from one truth, each with its own correlated covariance: mean chi2 = 6 within
    3 standard errors, and about 1 % of p-values under 0.01."""
    rng = np.random.default_rng(3)
    scale = np.array([1e-3] * 3 + [1e-4] * 3)
    chi2, p, z = [], [], []
    for _ in range(200):
        c = compare_calibrations([_draw(rng, _random_cov(rng, 6, scale)), _draw(rng, _random_cov(rng, 6, scale))])
        chi2.append(c.chi2[0])
        p.append(c.p_value[0])
        z.append(c.z[0])
    assert abs(np.mean(chi2) - 6) < 3 * math.sqrt(2 * 6 / 200)
    assert np.mean(np.array(p) < 0.01) < 0.04
    assert math.sqrt(np.mean(np.square(z))) == pytest.approx(1.0, abs=3 * math.sqrt(1 / (2 * 1200)) + 0.02)


def test_a_shifted_calibration_is_outside_the_tolerance(rng):
    cov = np.diag([1e-6] * 3 + [1e-8] * 3)
    a = Calibration(model=TRUE, covariance=cov)
    shifted = ScaleBias(k=TRUE.k + [0, 5e-3, 0], b=TRUE.b)  # 5e-3 / sqrt(2e-6) = 3.5 sigma on ky
    c = compare_calibrations([a, Calibration(model=shifted, covariance=cov)], ["a.json", "b.json"])
    assert c.names == ("kx", "ky", "kz", "bx", "by", "bz")
    assert c.z[0, 1] == pytest.approx(5e-3 / math.sqrt(2e-6))
    assert c.within(4.0).tolist() == [True] and c.within(3.0).tolist() == [False]
    assert "OUTSIDE 3 sigma of a.json (largest: ky at +3.54 sigma)" in c.verdicts(3.0)[0]
    # jointly, one 3.5-sigma parameter out of six is not yet a significant difference (p = 0.05)
    assert c.p_value[0] == pytest.approx(chi2.sf(12.5, 6)) and "agrees with a.json" in c.verdicts()[0]
    far = compare_calibrations([a, Calibration(model=ScaleBias(k=TRUE.k + [0, 8e-3, 0], b=TRUE.b), covariance=cov)],
                               ["a.json", "b.json"])
    assert "differs from a.json" in far.verdicts()[0]


def test_biases_are_shown_in_the_input_units():
    cov = np.diag([1e-6] * 3 + [1e-8] * 3)
    a = Calibration(model=TRUE, input_units="deg/s", output_units="deg/s", covariance=cov)
    c = compare_calibrations([a, a])
    assert c.units[3] == "deg/s" and c.values[0, 3] == pytest.approx(math.degrees(TRUE.b[0]))
    assert c.std[0, 3] == pytest.approx(math.degrees(1e-4))
    assert np.all(c.z == 0) and c.chi2[0] == 0


def test_scale_bias_to_kg_jacobian_matches_finite_differences(rng):
    params = TRUE.params
    cov = _random_cov(rng, 6, np.array([1e-3] * 3 + [1e-4] * 3))
    _, mapped = _scale_bias_to_kg(params, cov)
    jac = np.empty((12, 6))
    for i in range(6):
        step = np.zeros(6)
        step[i] = 1e-7
        jac[:, i] = (_scale_bias_to_kg(params + step, None)[0] - _scale_bias_to_kg(params - step, None)[0]) / 2e-7
    assert np.allclose(mapped, jac @ cov @ jac.T, rtol=1e-6, atol=1e-20)
    kg = _scale_bias_to_kg(params, None)[0]
    assert np.allclose(kg, TRUE.to_affine().kg)


def test_scale_bias_and_affine_compare_in_kg(rng):
    cov = np.diag([1e-6] * 3 + [1e-8] * 3)
    affine = Calibration(model=Affine.from_kg(TRUE.to_affine().kg), covariance=np.eye(12) * 1e-6)
    c = compare_calibrations([Calibration(model=TRUE, covariance=cov), affine])
    assert c.names[0] == "Kxx" and len(c.names) == 12
    assert np.allclose(c.diff, 0, atol=1e-12) and c.dof[0] == 12


def test_thermal_tables_compare_point_by_point():
    temps = np.array([-20.0, 0.0, 20.0, 40.0])
    kg = ThermalTruth().kg(temps)
    std = np.full((4, 12), 1e-4)
    a = ThermalCalibration(temps=temps, kg=kg, smooth=fit_smooth(temps, kg, 2), std=std)
    shifted = kg.copy()
    shifted[2, 9] += 3e-4  # Bx at 20 degC, 3e-4 / (1e-4 sqrt 2) = 2.1 sigma
    b = ThermalCalibration(temps=temps, kg=shifted, smooth=fit_smooth(temps, shifted, 2), std=std)
    c = compare_calibrations([a, b], ["a", "b"])
    assert len(c.names) == 48 and c.joint == "diagonal"
    worst = int(np.argmax(np.abs(c.z[0])))
    assert c.names[worst] == "Bx@20C" and c.z[0, worst] == pytest.approx(3e-4 / (1e-4 * math.sqrt(2)))


def test_thermal_tables_at_other_temperatures_are_refused():
    t1, t2 = np.array([-20.0, 0.0, 20.0]), np.array([-10.0, 10.0, 30.0])
    truth = ThermalTruth()
    a = ThermalCalibration(temps=t1, kg=truth.kg(t1), smooth=fit_smooth(t1, truth.kg(t1), 2))
    b = ThermalCalibration(temps=t2, kg=truth.kg(t2), smooth=fit_smooth(t2, truth.kg(t2), 2))
    with pytest.raises(InputError, match="other temperatures"):
        compare_calibrations([a, b], ["a", "b"])
    with pytest.raises(InputError, match="thermal files with thermal files"):
        compare_calibrations([a, Calibration(model=TRUE)])


def test_counts_without_sensitivity_do_not_compare_with_rates():
    counts = Calibration(model=ScaleBias(k=(0.0001,) * 3, b=(10.0, -3.0, 2.0)), input_units="counts",
                         output_units="deg/s")
    with pytest.raises(InputError, match="share a unit"):
        compare_calibrations([counts, Calibration(model=TRUE)])


def test_without_covariance_there_is_no_verdict_in_sigmas():
    c = compare_calibrations([Calibration(model=TRUE), Calibration(model=TRUE)], ["a", "b"])
    assert "no uncertainties" in c.verdicts()[0]
    with pytest.raises(InputError, match="no 1-sigma"):
        c.within(3.0)


def test_one_calibration_is_not_a_comparison():
    with pytest.raises(InputError, match="at least two"):
        compare_calibrations([Calibration(model=TRUE)])
