"""PX4 and ArduPilot thermal parameters, re-evaluated the way each firmware evaluates them.

Independent references: the evaluators in ``firmware_models.py``, written from the firmware
sources, not from gyrocal's code. Each is compared with gyrocal's own compensation, within what
float32 parameters and arithmetic allow.
"""

import numpy as np
import pytest
from firmware_models import ardupilot_correct, parse_ardupilot, parse_px4, px4_offsets  # noqa: E402

from gyrocal.errors import InputError
from gyrocal.flight import ScaleNotCarriedWarning, ThermalBias, ardupilot_params, bias_from_thermal, px4_params

F32 = np.float32
EPS32 = float(np.finfo(np.float32).eps)
TEMPS = np.linspace(-30.0, 70.0, 201)  # inside and beyond the fitted range, to test the clipping


def _bias() -> ThermalBias:
    """A fit as thermal-bias writes it: a cubic, a line and a parabola about the range's middle."""
    coefs = np.array([[0.0123, 1.9e-4, -2.9e-6, 5.1e-8], [-0.0201, -1.02e-4, 0.0, 0.0], [0.0049, 3.1e-5, 2.1e-6, 0.0]])
    cov = np.zeros((3, 4, 4))
    for a in range(3):
        cov[a] = np.diag([1e-5, 1e-7, 1e-9, 1e-11]) ** 2
    return ThermalBias(coefs, cov, np.array([3, 1, 2]), 20.0537, -8.93, 49.21, np.zeros((4, 3)), np.full(3, 1e-5),
                       np.full(3, 5e-3), 100.0, 2700.0, source={"file": "warm.ulg", "device_id": 2424842})


def _float32_tolerance(coefs: np.ndarray, temp: np.ndarray, t0: float) -> np.ndarray:
    """Rounding of float32 coefficients, temperatures and a 4-term sum: 16 eps times the terms' sizes."""
    size = np.abs(temp) + abs(t0) + 1.0
    return 16 * EPS32 * np.sum(np.abs(coefs)[None, :, :] * size[:, None, None] ** np.arange(4), axis=2)


def test_px4_parameters_evaluate_to_gyrocals_compensation(rng):
    tb = _bias()
    params = parse_px4(px4_params(tb, instance=1))
    assert params["TC_G_ENABLE"] == 1 and params["TC_G1_ID"] == 2424842
    assert {f"TC_G1_X{n}_{a}" for n in range(4) for a in range(3)} <= set(params)
    reading = rng.standard_normal((len(TEMPS), 3)) * 0.1
    firmware = reading - px4_offsets(params, 1, TEMPS)
    ours = tb.compensate(reading, TEMPS)
    tol = _float32_tolerance(tb.coefs, TEMPS, tb.tref)
    assert np.all(np.abs(firmware - ours) <= tol), np.max(np.abs(firmware - ours) / tol)


def test_px4_needs_a_device_id_and_a_slot():
    tb = _bias()
    bare = ThermalBias(tb.coefs, tb.covariance, tb.orders, tb.tref, tb.tmin, tb.tmax, tb.cv_rms, tb.residual_rms,
                       tb.noise_std, tb.sample_rate, tb.duration)
    with pytest.raises(InputError, match="device id.*give the id .the CAL_GYROn_ID value. with device_id"):
        px4_params(bare)
    assert parse_px4(px4_params(bare, device_id=7))["TC_G0_ID"] == 7
    with pytest.raises(InputError, match="TC_G0..TC_G3"):
        px4_params(tb, instance=4)


def test_ardupilot_parameters_evaluate_to_gyrocals_compensation(rng):
    tb = _bias()
    text = ardupilot_params(tb, imu=2, caltemp=31.7)
    params = parse_ardupilot(text)
    assert params["INS_TCAL2_ENABLE"] == 1 and params["INS_GYR2_CALTEMP"] == pytest.approx(31.7, abs=1e-5)
    assert all(params[f"INS_TCAL2_ACC{k}_{ax}"] == 0 for k in (1, 2, 3) for ax in "XYZ")
    reading = rng.standard_normal((len(TEMPS), 3)) * 0.1
    firmware = ardupilot_correct(params, 2, TEMPS, reading)
    ours = tb.compensate(reading, TEMPS)
    tol = 2 * _float32_tolerance(tb.coefficients_about(35.0), TEMPS, 35.0) + 4 * EPS32 * np.abs(reading)
    assert np.all(np.abs(firmware - ours) <= tol), np.max(np.abs(firmware - ours) / tol)
    assert "INS_GYROFFS_X" in ardupilot_params(tb, imu=1) and "INS_GYR1_CALTEMP" in ardupilot_params(tb, imu=1)
    with pytest.raises(InputError, match="INS_TCAL1..INS_TCAL3"):
        ardupilot_params(tb, imu=0)


def _turntable():
    """A full-temperature-range calibration whose bias is a cubic and whose scale drifts 30 ppm/degC."""
    from gyrocal.models import KG_NAMES
    from gyrocal.thermal import ThermalCalibration, fit_smooth

    temps = np.arange(-40.0, 51.0, 10.0)
    kg = np.zeros((len(temps), len(KG_NAMES)))
    kg[:, :3] = 1.0 + 3e-5 * (temps[:, None] - 25.0)
    d = temps - 25.0
    kg[:, 9] = 0.004 + 1e-4 * d - 2e-6 * d**2 + 3e-8 * d**3
    kg[:, 10] = -0.002 + 5e-5 * d
    kg[:, 11] = 0.001 - 1e-6 * d**2
    return ThermalCalibration(temps, kg, fit_smooth(temps, kg, max_order=3), std=np.full((len(temps), 12), 1e-5))


def test_turntable_bias_part_exports_with_a_warning(rng):
    cal = _turntable()
    # K moves 30 ppm/degC: 1800 ppm from the reference point (20 degC, nearest 25) to -40 degC
    with pytest.warns(ScaleNotCarriedWarning, match="up to 1800 ppm.*bias only"):
        tb = bias_from_thermal(cal)
    temps = np.linspace(-40.0, 50.0, 91)
    ours = cal.kg_at(temps, model="smooth")[:, 9:12]  # gyrocal's own smooth bias B(T) (eq. 12 at rest)
    params = parse_px4(px4_params(tb, device_id=1))
    firmware = px4_offsets(params, 0, temps)
    tol = _float32_tolerance(tb.coefs, temps, tb.tref) + 1e-12
    assert np.all(np.abs(firmware - ours) <= tol), np.max(np.abs(firmware - ours) / tol)
    assert np.all(tb.std_at(temps) > 0)  # propagated from the points' 1-sigma
