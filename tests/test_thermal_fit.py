"""Per-temperature 12-parameter least squares (the full-temperature-range method, eq. 15-19) against simulated truth."""

import numpy as np
import pytest

from gyrocal.errors import DegenerateDesignError
from gyrocal.simulation.thermal_truth import EQ23_KG, ThermalTruth, eq23_kg
from gyrocal.simulation.turntable import TurntableProtocol, simulate_turntable
from gyrocal.thermal import calibrate_thermal, fit_point
from gyrocal.thermal.fit import kg_eq19, omega_matrix

NOISE = np.radians(0.05)  # rad/s per sample


def _session(rng, noise=NOISE, **protocol):
    truth = ThermalTruth()
    proto = TurntableProtocol(step_duration=protocol.pop("step_duration", 4.0), **protocol)
    return truth, simulate_turntable(truth.gyro(noise), proto, sample_rate=50.0, rng=rng)


def test_omega_first_row_is_eq15():
    om = omega_matrix(np.array([[2.0, 3.0, 5.0]]))
    kg = np.arange(1.0, 13.0)
    # wx = Kxx w~x + Kyx w~y + Kzx w~z + Bx (the full-temperature-range method, eq. 15, first row of Omega^T)
    assert (kg @ om)[0] == pytest.approx(1 * 2 + 4 * 3 + 5 * 5 + 10)


def test_split_solution_equals_eq19_as_written(rng):
    ref = np.zeros((21 * 3, 3))
    rates = rng.uniform(-7, 7, 21)
    for a in range(3):
        ref[21 * a:21 * (a + 1), a] = rates
    kg = eq23_kg()
    from gyrocal.thermal.model import kg_to_kb

    K, B = kg_to_kb(kg)
    means = ref @ K.T + B + rng.normal(scale=1e-3, size=ref.shape)
    fp = fit_point(ref, means, np.full(ref.shape, 1e-4), np.full(len(ref), 100))
    np.testing.assert_allclose(fp.kg, kg_eq19(ref, means), rtol=1e-10, atol=1e-13)


def test_noise_free_session_returns_truth_exactly(rng):
    truth, rec = _session(rng, noise=0.0, temps=(-10.0, 10.0, 30.0))
    # an explicit full scale: without it, noise-free plateaus look like saturation
    _, fit = calibrate_thermal([rec], settle=2.0, full_scale=10.0)
    np.testing.assert_allclose(fit.kg, truth.kg(fit.temps), atol=1e-9)


def test_session_recovered_within_predicted_uncertainty(rng):
    truth, rec = _session(rng)
    _cal, fit = calibrate_thermal([rec], settle=1.0)
    assert np.allclose(fit.temps, TurntableProtocol().temps)
    z = (fit.kg - truth.kg(fit.temps)) / fit.std_noise
    assert np.max(np.abs(z)) < 4.0
    # the predicted sigma is neither too small nor too large: mean z^2 = 1 +- 4 * sqrt(2 / 120)
    assert abs(np.mean(z ** 2) - 1.0) < 4 * np.sqrt(2 / z.size)
    # residual-based and noise-based sigmas agree for white noise (dof 59 per axis: +-4 * 1/sqrt(118))
    ratio = fit.std / fit.std_noise
    assert abs(np.median(ratio) - 1.0) < 4 / np.sqrt(118)


def test_eq23_is_the_truth_at_25_degc():
    kg = ThermalTruth().kg([25.0])[0]
    np.testing.assert_allclose(kg[:9], EQ23_KG[:9])
    np.testing.assert_allclose(np.degrees(kg[9:]), EQ23_KG[9:])


def test_truth_shapes_follow_figures_4_to_6():
    truth = ThermalTruth()
    t = np.linspace(-40, 50, 10)
    kg = truth.kg(t)
    assert np.allclose(np.diff(kg[:, :3], 2, axis=0), 0, atol=1e-15)  # scale linear
    assert np.allclose(kg[:, 3:9], kg[0, 3:9])  # misalignment constant
    assert np.all(np.abs(np.diff(kg[:, 9:], 2, axis=0)) > 1e-8)  # bias not linear


def test_one_position_only_is_degenerate():
    ref = np.zeros((6, 3))
    ref[:, 0] = [-2, -1, 0, 1, 2, 3]
    with pytest.raises(DegenerateDesignError, match="x, y, z"):
        fit_point(ref, np.zeros((6, 3)), np.ones((6, 3)), np.ones(6) * 10)
