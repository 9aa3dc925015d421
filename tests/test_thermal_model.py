"""The temperature table: units, file round trip (format version 2, docs/files.md), compensation, smoothing of
temperature, smooth model. References: ThermalTruth (the simulated true Kg) and the canonical correction."""

import json

import numpy as np
import pytest

from gyrocal.errors import FileFormatError, InputError, OutOfRangeError
from gyrocal.models import correct, kg_to_kb
from gyrocal.recording import Recording
from gyrocal.results.files import load_thermal, save_thermal
from gyrocal.simulation.thermal_truth import ThermalTruth
from gyrocal.thermal import (
    ThermalCalibration,
    ThermalRangeWarning,
    fit_smooth,
    smooth_temperature,
)

TEMPS = np.array([-40.0, -30, -20, -10, 0, 10, 20, 30, 40, 50])
TRUTH = ThermalTruth()


def _cal(**kw) -> ThermalCalibration:
    kg = TRUTH.kg(TEMPS)
    return ThermalCalibration(temps=TEMPS, kg=kg, smooth=fit_smooth(TEMPS, kg, 3), **kw)


def test_user_units_and_canonical_correction_agree_with_internal(rng):
    cal = _cal(input_units="deg/s", output_units="deg/s")
    true = rng.uniform(-5, 5, (20, 3))  # rad/s
    K, B = kg_to_kb(cal.kg[3])
    raw_deg = np.degrees(true @ K.T + B)
    matrix, offset = cal.correction
    np.testing.assert_allclose(correct(matrix[3], offset[3], raw_deg), np.degrees(true), rtol=1e-12, atol=1e-9)
    Ku, Bu = kg_to_kb(cal.kg_user[3])
    np.testing.assert_allclose(np.degrees(true) @ Ku.T + Bu, raw_deg, rtol=1e-12, atol=1e-9)


def test_file_round_trip(tmp_path):
    cal = _cal(input_units="deg/s", output_units="rad/s", std=np.full((10, 12), 1e-5), reference_temp=20.0)
    save_thermal(cal, tmp_path / "t.json")
    back = load_thermal(tmp_path / "t.json")
    np.testing.assert_array_equal(back.kg, cal.kg)
    np.testing.assert_array_equal(back.smooth.coefs, cal.smooth.coefs)
    assert (back.input_units, back.output_units, back.reference_temp, back.range) == ("deg/s", "rad/s", 20.0, (-40, 50))
    doc = json.loads((tmp_path / "t.json").read_text())
    assert doc["format"] == "gyrocal.thermal" and doc["version"] == 2
    assert doc["kg_order"][:4] == ["Kxx", "Kyy", "Kzz", "Kyx"] and doc["fit"] is None
    np.testing.assert_allclose(doc["points"][0]["kg_user"], cal.kg_user[0])


@pytest.mark.parametrize(("field", "value", "match"), [
    ("version", 7, "version"), ("format", "gyrocal.calibration", "format"), ("kg_order", ["a"], "kg_order")])
def test_bad_file_names_the_field(tmp_path, field, value, match):
    save_thermal(_cal(), tmp_path / "t.json")
    doc = json.loads((tmp_path / "t.json").read_text())
    doc[field] = value
    (tmp_path / "t.json").write_text(json.dumps(doc))
    with pytest.raises(FileFormatError, match=match):
        load_thermal(tmp_path / "t.json")


def test_bad_smooth_model_in_file_is_refused(tmp_path):
    save_thermal(_cal(), tmp_path / "t.json")
    doc = json.loads((tmp_path / "t.json").read_text())
    doc["smooth"]["orders"] = [9] * 12
    (tmp_path / "t.json").write_text(json.dumps(doc))
    with pytest.raises(FileFormatError, match="orders"):
        load_thermal(tmp_path / "t.json")


def test_bad_point_in_file_is_named(tmp_path):
    save_thermal(_cal(), tmp_path / "t.json")
    doc = json.loads((tmp_path / "t.json").read_text())
    doc["points"][2]["kg"] = [1.0] * 11
    (tmp_path / "t.json").write_text(json.dumps(doc))
    with pytest.raises(FileFormatError, match=r"points\[2\]\.kg"):
        load_thermal(tmp_path / "t.json")


def _recording(true_rates, temp, truth_temp=None, fs=100.0):
    ideal = TRUTH.gyro(0.0).ideal(true_rates, truth_temp if truth_temp is not None else temp)
    return Recording(t=np.arange(len(ideal)) / fs, gyro=ideal, temp=temp, sample_rate=fs)


def test_apply_recovers_true_rates_at_calibrated_and_between_temperatures():
    cal = _cal(output_units="deg/s")
    n = 400
    true = np.tile(np.radians([[100.0, -50.0, 10.0]]), (n, 1))
    for temp in (-40.0, 25.0, 47.0):
        out = cal.apply(_recording(true, np.full(n, temp)))
        assert out.source_units == "deg/s" and out.units == "rad/s"
        # cubic bias between nodes: Lagrange error stays far below 1e-3 deg/s here
        np.testing.assert_allclose(np.degrees(out.gyro), np.degrees(true), atol=2e-3)


def test_apply_without_temp_is_an_error():
    rec = Recording(t=np.arange(10) / 10.0, gyro=np.zeros((10, 3)))
    with pytest.raises(InputError, match="no 'temp' column"):
        _cal().apply(rec)


def test_apply_out_of_range_policies():
    cal = _cal()
    rec = _recording(np.zeros((50, 3)), np.full(50, 55.0))
    with pytest.raises(OutOfRangeError, match="55"):
        cal.apply(rec)
    for policy in ("clamp", "extrapolate"):
        with pytest.warns(ThermalRangeWarning):
            cal.apply(rec, out_of_range=policy)
    with pytest.warns(ThermalRangeWarning):
        cal.apply(rec, model="smooth", out_of_range="clamp")


def test_quantised_temperature_does_not_make_the_output_jump():
    cal = _cal()
    fs, n = 100.0, 30_000  # 300 s
    true_temp = np.linspace(24.2, 25.8, n)  # a slow drift across the 25 degC reading boundary
    read = np.round(true_temp)  # 1 degC quantisation
    true = np.tile(np.radians([[400.0, 0.0, 0.0]]), (n, 1))
    rec = _recording(true, read, truth_temp=true_temp, fs=fs)
    jumpy = cal.apply(rec, temp_tau=0.0).gyro
    smooth = cal.apply(rec).gyro
    step = np.max(np.abs(np.diff(jumpy, axis=0)))
    noise = np.radians(0.05)  # a typical per-sample noise
    assert step > noise / 10  # without smoothing the 1 degC step shows
    assert np.max(np.abs(np.diff(smooth, axis=0))) < noise / 100


def test_temperature_smoothing_keeps_constants_and_has_no_lag():
    x = np.full(1000, 21.5)
    np.testing.assert_allclose(smooth_temperature(x, 100.0, 5.0), x)
    ramp = np.linspace(0, 10, 20_000)
    y = smooth_temperature(ramp, 100.0, 5.0)
    # zero phase: the middle of a ramp is not delayed
    assert abs(y[10_000] - ramp[10_000]) < 1e-6
    with pytest.raises(InputError, match="temp_tau"):
        smooth_temperature(x, 100.0, -1.0)


def test_smooth_orders_chosen_by_loto(rng):
    t = TEMPS
    u = (t - t.mean()) / 45
    values = np.stack([2 + 0 * t, 1 + 3 * u, 1 + u - 2 * u ** 3], axis=1)
    values = values + rng.normal(scale=1e-6, size=values.shape)
    sm = fit_smooth(t, values, max_order=5)
    assert sm.orders.tolist() == [0, 1, 3]
    np.testing.assert_allclose(sm(t), values, atol=5e-6)


def test_smooth_model_needs_three_points():
    with pytest.raises(InputError, match=">= 3 temperature points"):
        fit_smooth([0.0, 10.0], np.zeros((2, 12)))


def test_singular_k_is_refused():
    kg = TRUTH.kg(TEMPS)
    kg[4, :9] = 0.0
    with pytest.raises(InputError, match="0 degC is singular"):
        ThermalCalibration(temps=TEMPS, kg=kg, smooth=fit_smooth(TEMPS, TRUTH.kg(TEMPS)))


@pytest.mark.parametrize(("fs", "tau", "n"), [(200.0, 20.0, 60_000), (1.0, 20.0, 3_000), (100.0, 0.01, 20_000)])
def test_temperature_smoothing_equals_two_passes_of_scipy_lfilter(rng, fs, tau, n):
    """Reference: scipy.signal.lfilter, forward then backward, each pass starting at its first reading."""
    from scipy.signal import lfilter

    x = np.round(20 + np.cumsum(rng.normal(0, 0.01, n)) + rng.normal(0, 0.3, n))  # whole-degree readings
    a = np.exp(-1 / (fs * tau))
    y, _ = lfilter([1 - a], [1, -a], x, zi=[a * x[0]])
    y, _ = lfilter([1 - a], [1, -a], y[::-1], zi=[a * y[-1]])
    np.testing.assert_allclose(smooth_temperature(x, fs, tau), y[::-1], rtol=1e-11, atol=0)


def test_compensation_equals_numpy_solve_per_sample(rng):
    """Reference: numpy.linalg.solve of K(T) w = raw - B(T) sample by sample, with K(T), B(T) from kg_at;
    enough samples to span several of the compensation's chunks."""
    cal = _cal()
    n = 150_000
    temp = rng.uniform(-40.0, 50.0, n)
    raw = rng.normal(0.0, 2.0, (n, 3))
    K, B = kg_to_kb(cal.kg_at(temp))
    want = np.linalg.solve(K, (raw - B)[..., None])[..., 0]
    np.testing.assert_allclose(cal.compensate(raw, temp), want, rtol=1e-12, atol=1e-14)
