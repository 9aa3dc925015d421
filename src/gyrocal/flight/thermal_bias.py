"""Gyro bias against temperature from a still log of a warming board (no turntable).

This is what the flight stacks calibrate: PX4 (``process_sensor_caldata.py``) and ArduPilot
(``tempcal_IMU.py``, and the on-board learner) fit a cubic in temperature to the gyro
output of a board that is cooled, then powered and left still while it warms. gyrocal
fits the same kind of polynomial, but

* refuses a log that moves (:mod:`gyrocal.segmentation.stillness`) or spans too few degrees (10 degC by
  default, ArduPilot's minimum: ``TEMP_RANGE_MIN`` in ``AP_InertialSensor_tempcal.cpp``);
* smooths the (often whole-degree) temperature readings in time without lag;
* chooses each axis's order (up to 3, what both firmwares evaluate) by leave-one-
  temperature-segment-out error (:mod:`.polyfit`);
* reports each coefficient's 1-sigma from the residuals, modelled as white noise plus a
  Gauss-Markov wander of the bias (:func:`.polyfit.ar1_covariance`), and the curve's 1-sigma.

The model, per axis: ``bias(T) = sum_n coefs[n] (T - tref)^n`` [rad/s], ``T`` clipped to
``[tmin, tmax]``, and the compensated rate is ``reading - bias(T)``: PX4's form exactly.

With the accelerometer's readings the same blocks, order choice and 1-sigma give its offsets'
*change* from ``tref`` (:class:`.curve.AccelDrift`, zero at ``tref``): a board in one
orientation cannot tell an offset from gravity, only how the reading moves with temperature.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from .._validation import at_least, finite_array, positive
from ..errors import GyrocalWarning, InputError
from ..segmentation.stillness import find_motion
from .curve import MAX_ORDER, AccelDrift, BlockGrid, TemperaturePolynomial, check_axes, check_curve, fit_sensor
from .temperature import temperature_course

__all__ = ["MAX_ORDER", "AccelDrift", "ThermalBias", "ThermalBiasWarning", "fit_thermal_bias"]
#: ArduPilot's minimum temperature rise for a calibration [degC].
MIN_SPAN = 10.0


class ThermalBiasWarning(GyrocalWarning):
    """The thermal-bias fit holds less well than its noise would let it."""


@dataclass(frozen=True)
class ThermalBias(TemperaturePolynomial):
    """Gyro bias as a polynomial of temperature, per axis, with its uncertainty (and the accelerometer's).

    Attributes
    ----------
    coefs : ndarray, shape (3, MAX_ORDER + 1)
        ``coefs[a, n]`` multiplies ``(T - tref)^n`` [rad/s/degC^n]; zero above each axis's order.
    covariance : ndarray, shape (3, MAX_ORDER + 1, MAX_ORDER + 1)
        Covariance of each axis's coefficients (zero rows above its order).
    orders : ndarray of int, shape (3,)
        Chosen order of each axis.
    tref, tmin, tmax : float
        Reference temperature and the range the fit covers [degC].
    cv_rms : ndarray, shape (MAX_ORDER + 1, 3)
        Leave-one-segment-out RMS prediction error of every order [rad/s].
    residual_rms, noise_std : ndarray, shape (3,)
        RMS residual of the block means, and the per-sample white noise [rad/s].
    sample_rate, duration : float
        Of the log [Hz], [s].
    fit : dict
        How the fit was made (blocks, segments, HAC lag, temperature smoothing).
    source : dict
        Where the data came from (file, IMU instance, device id), for the record.
    warnings : tuple of str
    accel : AccelDrift or None
        The accelerometer offsets' change from ``tref`` over the same range, when fitted.
    """

    coefs: np.ndarray
    covariance: np.ndarray
    orders: np.ndarray
    tref: float
    tmin: float
    tmax: float
    cv_rms: np.ndarray
    residual_rms: np.ndarray
    noise_std: np.ndarray
    sample_rate: float
    duration: float
    fit: dict = field(default_factory=dict)
    source: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    accel: AccelDrift | None = None

    #: File kind (registered by :mod:`gyrocal.flight.thermal_bias_document`, which holds the document code).
    FORMAT: ClassVar[str] = "gyrocal.thermal-bias"
    VERSION: ClassVar[int] = 2

    def __post_init__(self):
        check_curve(self)
        if self.accel is not None and not isinstance(self.accel, AccelDrift):
            raise InputError(f"accel must be an AccelDrift or None, got {type(self.accel).__name__}")
        if self.accel is not None and (self.accel.tref, self.accel.tmin, self.accel.tmax) != (
                self.tref, self.tmin, self.tmax):
            # one INS_TCALn_TMIN/TMAX serves both sensors in ArduPilot: the fits share their range
            raise InputError("the accelerometer part must cover the gyro's range and reference temperature")

    def bias_at(self, temp) -> np.ndarray:
        """Bias (N, 3) [rad/s] at temperatures (N,) [degC], clipped to ``[tmin, tmax]``."""
        return self.value_at(temp)

    def compensate(self, gyro, temp) -> np.ndarray:
        """Readings (N, 3) [rad/s] less the bias at temperatures (N,) [degC]."""
        return finite_array("gyro", gyro, shape_tail=(3,), ndim=2) - self.bias_at(temp)


def _check_input(g, temp, fs, min_span) -> None:
    check_axes(g, "gyro")
    if temp.min() == temp.max() or np.ptp(temp) < min_span:
        raise InputError(f"the log spans only {np.ptp(temp):.1f} degC ({temp.min():.1f} to {temp.max():.1f}); a "
                         f"bias-versus-temperature fit needs at least {min_span:g} degC: cool the board first "
                         "(a freezer), then log it warming up, still")
    still = find_motion(g, fs)
    if not still.still:
        raise InputError(f"the board moved ({still.describe(fs)}); a thermal-bias log must be still from start to "
                         "end: record it again untouched, or cut the log to a still stretch")


def _grid(course, n: int, size: int, segments: int, min_span: float, fs: float) -> tuple[BlockGrid, float, float]:
    """The blocks with a known temperature, their scaled temperature and segment; and the range they cover."""
    nb = n // size
    keep = course.valid[: nb * size].reshape(nb, size).all(axis=1)
    tm = np.where(course.valid, course.temp, 0.0)[: nb * size].reshape(nb, size).mean(axis=1)[keep]
    if len(tm) < 4 * (MAX_ORDER + 1):
        raise InputError(f"the log holds {len(tm)} blocks of {size / fs:g} s; a thermal-bias fit needs at least "
                         f"{4 * (MAX_ORDER + 1)}: log longer")
    tmin, tmax = float(tm.min()), float(tm.max())
    if tmax - tmin < min_span:
        raise InputError(f"the temperature is known well enough over {tmin:.1f} to {tmax:.1f} degC only (readings in "
                         f"steps of {course.quantum:g} degC); a bias-versus-temperature fit needs {min_span:g} degC")
    tref, half = 0.5 * (tmin + tmax), 0.5 * (tmax - tmin)
    u = (tm - tref) / half
    seg = np.minimum(((u + 1) / 2 * segments).astype(int), segments - 1)
    return BlockGrid(size, keep, u, seg, tref, half), tmin, tmax


def fit_thermal_bias(gyro, temp, sample_rate: float, *, max_order: int = MAX_ORDER, min_span: float = MIN_SPAN,
                     block_s: float = 5.0, segments: int = 8, source: dict | None = None,
                     accel=None) -> ThermalBias:
    """Fit the gyro bias (and the accelerometer's offset change) against temperature on a still, warming log.

    Parameters
    ----------
    gyro : array_like, shape (N, 3)
        Readings at rest [rad/s].
    temp : array_like, shape (N,)
        Sensor temperature readings [degC]; readings in steps (whole degrees) are turned into a
        course through their level crossings (:func:`.temperature.temperature_course`).
    sample_rate : float
        Mean sampling rate [Hz].
    max_order : int
        Highest polynomial order tried, at most 3 (what PX4 and ArduPilot evaluate).
    min_span : float
        Smallest temperature span accepted [degC].
    block_s : float
        Block length for the fit [s].
    segments : int
        Temperature segments for the order choice (each left out in turn).
    source : dict, optional
        Where the data came from, recorded in the result.
    accel : array_like, shape (N, 3), optional
        Accelerometer readings [m/s^2] of the same samples: their change with temperature from
        ``tref`` is fitted the same way (:class:`.curve.AccelDrift`).

    Raises
    ------
    InputError
        A log that moves, spans fewer than `min_span` degrees, or has a constant axis.
    """
    g = finite_array("gyro", gyro, shape_tail=(3,), ndim=2)
    t_raw = finite_array("temp", temp, ndim=1)
    if len(t_raw) != len(g):
        raise InputError(f"temp has {len(t_raw)} samples but gyro has {len(g)}")
    a = None if accel is None else finite_array("accel", accel, shape_tail=(3,), ndim=2)
    if a is not None and len(a) != len(g):
        raise InputError(f"accel has {len(a)} samples but gyro has {len(g)}")
    fs = positive("sample_rate", sample_rate)
    if not 0 <= int(max_order) <= MAX_ORDER:
        raise InputError(f"{{param}} must be 0..{MAX_ORDER} (PX4 and ArduPilot evaluate cubics), got {max_order!r}",
                         param="max_order", value=max_order)
    _check_input(g, t_raw, fs, at_least("min_span", min_span, 0.0, " degC"))
    if a is not None:
        check_axes(a, "accelerometer")
    size = max(10, int(round(block_s * fs)))
    course = temperature_course(t_raw, fs)
    grid, tmin, tmax = _grid(course, len(g), size, segments, min_span, fs)
    gf = fit_sensor(g, grid, int(max_order))
    af = None if a is None else fit_sensor(a, grid, int(max_order), label="accelerometer ", relative=True)
    found = gf.warnings + ([] if af is None else af.warnings)
    for message in found:
        warnings.warn(message, ThermalBiasWarning, stacklevel=2)
    fit = {"blocks": int(grid.keep.sum()), "block_s": size / fs, "segments": int(segments),
           "max_order": int(max_order), "min_span_degC": min_span, "temperature": course.method,
           "noise_model": gf.noise_model}
    drift = None if af is None else AccelDrift(af.coefs, af.covariance, af.orders, grid.tref, tmin, tmax, af.cv_rms,
                                               af.residual_rms, af.noise_std, {"noise_model": af.noise_model})
    return ThermalBias(gf.coefs, gf.covariance, gf.orders, grid.tref, tmin, tmax, gf.cv_rms, gf.residual_rms,
                       gf.noise_std, fs, len(g) / fs, fit, dict(source or {}), tuple(found), drift)
