"""Bias against temperature from simulated warm-up logs (a still board warming from cold).

Independent reference: the simulation's true bias polynomial (`BiasDrift`) and true temperature
course; tolerances are the fit's own reported 1-sigma (z-scores over seeds).
"""

import math

import numpy as np
import pytest

from gyrocal.errors import FileFormatError, InputError
from gyrocal.flight import fit_thermal_bias, temperature_course
from gyrocal.flight.thermal_bias_document import load_thermal_bias, save_thermal_bias
from gyrocal.models import ScaleBias
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.still import BiasDrift, StillProtocol, simulate_still

FS = 100.0
#: Truth: a cubic on x, a line on y, a parabola on z [rad/s/degC^n] about 25 degC.
COEFS = np.array([[0.01, 2e-4, -3e-6, 5e-8], [-0.02, -1e-4, 0.0, 0.0], [0.005, 3e-5, 2e-6, 0.0]])
WARM = StillProtocol(duration=2700.0, temp_start=-10.0, temp_end=50.0, temp_tau=600.0, temp_quantum=1.0)


def _log(seed, *, protocol=WARM, bias_instability=0.0):
    drift = BiasDrift(COEFS, 25.0)
    gyro = VirtualGyro(ScaleBias(np.ones(3), np.zeros(3)), noise_std=0.005, bias_instability=bias_instability,
                       bias_tau=100.0, thermal=drift)
    rec, true_temp = simulate_still(gyro, protocol, sample_rate=FS, rng=np.random.default_rng(seed))
    return rec, true_temp, drift


@pytest.mark.parametrize("bias_instability", [0.0, 2e-4])
def test_curve_within_its_reported_sigma(bias_instability):
    """RMS of (fit - truth) / reported sigma over seeds, axes and temperatures within a 4-sigma band of 1.

    The 24 curves (8 seeds x 3 axes) are each checked at 3 temperatures; points of one curve are
    correlated, so the band is set for 24 independent draws: 1 +- 4 / sqrt(2 * 24).
    With bias_instability a Gauss-Markov bias (41 deg/h, 100 s) wanders through the warm-up.
    """
    z = []
    for seed in range(8):
        rec, _, drift = _log(seed, bias_instability=bias_instability)
        tb = fit_thermal_bias(rec.gyro, rec.temp, FS)
        temps = np.linspace(tb.tmin, tb.tmax, 3)
        z.append((tb.bias_at(temps) - drift.bias(temps)) / tb.std_at(temps))
    rms = math.sqrt(np.mean(np.square(z)))
    assert abs(rms - 1) < 4 / math.sqrt(48), rms


def test_orders_are_chosen_by_leaving_out_temperature_segments():
    rec, _, _ = _log(1)
    tb = fit_thermal_bias(rec.gyro, rec.temp, FS)
    np.testing.assert_array_equal(tb.orders, [3, 1, 2])  # the truth's orders
    assert np.all(np.argmin(tb.cv_rms, axis=0) >= tb.orders)  # the one-standard-error rule only lowers
    assert tb.tmin < -8 and tb.tmax > 47  # the range the course is known over (first to last crossing)
    assert "level crossings" in tb.fit["temperature"]


def test_whole_degree_readings_become_a_course_through_their_crossings():
    rng = np.random.default_rng(2)
    t = np.arange(int(2700 * FS)) / FS
    true = WARM.temperature(t)
    readings = np.round(true + rng.standard_normal(len(t)) * 0.1)
    course = temperature_course(readings, FS)
    assert course.quantum == 1.0
    err = course.temp[course.valid] - true[course.valid]
    # against half a step (0.5 degC) for the raw readings: the crossings pin the course. A crossing time
    # counted from readings with 0.1 degC Gaussian noise errs, as a temperature, by
    # sqrt(0.1 * slope / (sqrt(pi) * FS)) = 0.0075 degC at the steepest slope (0.1 degC/s, the start) and
    # less later: RMS below that, the largest of 57 crossings within 4 times it
    bound = math.sqrt(0.1 * 0.1 / (math.sqrt(math.pi) * FS))
    assert np.sqrt(np.mean(err**2)) < bound and np.abs(err).max() < 4 * bound, (np.sqrt(np.mean(err**2)),
                                                                                 np.abs(err).max())
    assert course.valid.mean() > 0.75  # after the last crossing the board sits within a step of 49 degC


def test_a_board_that_moves_is_refused():
    rec, _, _ = _log(3)
    g = rec.gyro.copy()
    g[100_000:100_600, 2] += 0.5  # someone turns the board for 6 s
    with pytest.raises(InputError, match="the board moved .1 motion, at 99"):
        fit_thermal_bias(g, rec.temp, FS)


def test_too_few_degrees_and_constant_axes_are_refused(rng):
    rec, _, _ = _log(4, protocol=StillProtocol(duration=600.0, temp_start=30.0, temp_end=36.0, temp_tau=300.0))
    with pytest.raises(InputError, match="spans only [45].[0-9] degC .*at least 10 degC"):
        fit_thermal_bias(rec.gyro, rec.temp, FS)
    g = rec.gyro.copy()
    g[:, 0] = 0.0
    with pytest.raises(InputError, match="axis x reads 0 in every sample"):
        fit_thermal_bias(g, rec.temp, FS)


def test_file_round_trip(tmp_path):
    rec, _, _ = _log(5)
    tb = fit_thermal_bias(rec.gyro, rec.temp, FS, source={"file": "warm.csv"})
    path = tmp_path / "bias.json"
    save_thermal_bias(tb, path)
    back = load_thermal_bias(path)
    np.testing.assert_array_equal(back.coefs, tb.coefs)
    np.testing.assert_array_equal(back.covariance, tb.covariance)
    assert back.orders.tolist() == tb.orders.tolist() and back.source == {"file": "warm.csv"}
    temps = np.linspace(-20, 60, 9)
    np.testing.assert_array_equal(back.bias_at(temps), tb.bias_at(temps))
    doc = path.read_text().replace('"order": 1', '"order": 7', 1)
    path.write_text(doc)
    with pytest.raises(FileFormatError, match="axes.y.order"):
        load_thermal_bias(path)
