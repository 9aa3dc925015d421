"""Gyro bias against temperature from a still log of a warming board (no turntable).

This is what the flight stacks calibrate: PX4 (``process_sensor_caldata.py``) and ArduPilot
(``tempcal_IMU.py``, and the on-board learner) fit a cubic in temperature to the gyro
output of a board that is cooled, then powered and left still while it warms. gyrocal
fits the same kind of polynomial, but

* refuses a log that moves (:mod:`gyrocal.stillness`) or spans too few degrees (10 degC by
  default, ArduPilot's minimum: ``TEMP_RANGE_MIN`` in ``AP_InertialSensor_tempcal.cpp``);
* smooths the (often whole-degree) temperature readings in time without lag;
* chooses each axis's order (up to 3, what both firmwares evaluate) by leave-one-
  temperature-segment-out error (:mod:`.polyfit`);
* reports each coefficient's 1-sigma from the residuals, modelled as white noise plus a
  Gauss-Markov wander of the bias (:func:`.polyfit.ar1_covariance`), and the curve's 1-sigma.

The model, per axis: ``bias(T) = sum_n coefs[n] (T - tref)^n`` [rad/s], ``T`` clipped to
``[tmin, tmax]``, and the compensated rate is ``reading - bias(T)``: PX4's form exactly.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from .._validation import at_least, finite_array, positive
from ..errors import GyrocalWarning, InputError
from ..stillness import find_motion
from ..units import MAD_TO_SIGMA
from .polyfit import ar1_covariance, choose_orders, segment_cv, vander
from .temperature import temperature_course

__all__ = ["MAX_ORDER", "ThermalBias", "ThermalBiasWarning", "fit_thermal_bias"]

#: Highest order PX4 (X0..X3) and ArduPilot (constant + GYR1..GYR3) evaluate.
MAX_ORDER = 3
#: ArduPilot's minimum temperature rise for a calibration [degC].
MIN_SPAN = 10.0


class ThermalBiasWarning(GyrocalWarning):
    """The thermal-bias fit holds less well than its noise would let it."""


@dataclass(frozen=True)
class ThermalBias:
    """Gyro bias as a polynomial of temperature, per axis, with its uncertainty.

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

    #: File kind (registered by :mod:`gyrocal.thermal_bias_file`, which holds the document code).
    FORMAT: ClassVar[str] = "gyrocal.thermal-bias"
    VERSION: ClassVar[int] = 1

    def to_document(self) -> dict:
        """The JSON-ready document (``format: gyrocal.thermal-bias``)."""
        from ..thermal_bias_file import to_document

        return to_document(self)

    @classmethod
    def from_document(cls, doc: dict, path="document") -> ThermalBias:
        """Validate a document and rebuild the fit, naming any bad field."""
        from ..thermal_bias_file import from_document

        return from_document(doc, path)

    def __post_init__(self):
        k = MAX_ORDER + 1
        for name, shape in (("coefs", (3, k)), ("covariance", (3, k, k)), ("cv_rms", (k, 3)),
                            ("residual_rms", (3,)), ("noise_std", (3,))):
            arr = finite_array(name, getattr(self, name))
            if arr.shape != shape:
                raise InputError(f"{name} must have shape {shape}, got {arr.shape}")
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        orders = np.asarray(self.orders, dtype=int)
        if orders.shape != (3,) or np.any(orders < 0) or np.any(orders > MAX_ORDER):
            raise InputError(f"orders must be 3 integers in 0..{MAX_ORDER}, got {self.orders!r}")
        orders.setflags(write=False)
        object.__setattr__(self, "orders", orders)
        if not (self.tmin <= self.tref <= self.tmax and self.tmax > self.tmin):
            raise InputError(f"need tmin <= tref <= tmax and tmax > tmin, got {self.tmin}, {self.tref}, {self.tmax}")

    def clip(self, temp) -> np.ndarray:
        """Temperatures [degC] clipped to the fitted range, as PX4 clips them."""
        return np.clip(np.asarray(temp, dtype=float), self.tmin, self.tmax)

    def bias_at(self, temp) -> np.ndarray:
        """Bias (N, 3) [rad/s] at temperatures (N,) [degC], clipped to ``[tmin, tmax]``."""
        d = self.clip(np.atleast_1d(temp)) - self.tref
        return vander(d, MAX_ORDER) @ self.coefs.T

    def std_at(self, temp) -> np.ndarray:
        """1-sigma (N, 3) [rad/s] of :meth:`bias_at`."""
        X = vander(self.clip(np.atleast_1d(temp)) - self.tref, MAX_ORDER)
        return np.sqrt(np.maximum(np.einsum("ni,aij,nj->na", X, self.covariance, X), 0.0))

    def coefficients_about(self, t0: float) -> np.ndarray:
        """Coefficients (3, MAX_ORDER + 1) of the same polynomials in powers of ``(T - t0)``.

        A Taylor shift, exact up to rounding: ``sum_n c_n (T - tref)^n = sum_k c'_k (T - t0)^k``
        with ``c'_k = sum_{n >= k} c_n C(n, k) (t0 - tref)^(n - k)``. ArduPilot's polynomial is
        about 35 degC, and PX4's ``TREF`` is written as a float32.
        """
        h = float(t0) - self.tref
        k = MAX_ORDER + 1
        shift = np.array([[math.comb(n, j) * h ** (n - j) if n >= j else 0.0 for n in range(k)] for j in range(k)])
        return self.coefs @ shift.T

    def compensate(self, gyro, temp) -> np.ndarray:
        """Readings (N, 3) [rad/s] less the bias at temperatures (N,) [degC]."""
        return finite_array("gyro", gyro, shape_tail=(3,), ndim=2) - self.bias_at(temp)


def _blocks(g: np.ndarray, temp: np.ndarray, valid: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """Block means of the readings and of the temperature course, blocks with any invalid temperature dropped."""
    nb = len(g) // size
    keep = valid[: nb * size].reshape(nb, size).all(axis=1)
    gm = g[: nb * size].reshape(nb, size, 3).mean(axis=1)[keep]
    tm = np.where(valid, temp, 0.0)[: nb * size].reshape(nb, size).mean(axis=1)[keep]
    return gm, tm


def _check_input(g, temp, fs, min_span) -> None:
    for j, axis in enumerate("xyz"):
        if g[:, j].min() == g[:, j].max():
            raise InputError(f"gyro axis {axis} reads {float(g[0, j]):g} in every sample: a constant column holds "
                             "no bias to fit (a dead sensor, or the wrong column mapped?)")
    if temp.min() == temp.max() or np.ptp(temp) < min_span:
        raise InputError(f"the log spans only {np.ptp(temp):.1f} degC ({temp.min():.1f} to {temp.max():.1f}); a "
                         f"bias-versus-temperature fit needs at least {min_span:g} degC: cool the board first "
                         "(a freezer), then log it warming up, still")
    still = find_motion(g, fs)
    if not still.still:
        raise InputError(f"the board moved ({still.describe(fs)}); a thermal-bias log must be still from start to "
                         "end: record it again untouched, or cut the log to a still stretch")


def fit_thermal_bias(gyro, temp, sample_rate: float, *, max_order: int = MAX_ORDER, min_span: float = MIN_SPAN,
                     block_s: float = 5.0, segments: int = 8, source: dict | None = None) -> ThermalBias:
    """Fit the gyro bias against temperature on a still, warming log.

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

    Raises
    ------
    InputError
        A log that moves, spans fewer than `min_span` degrees, or has a constant axis.
    """
    g = finite_array("gyro", gyro, shape_tail=(3,), ndim=2)
    t_raw = finite_array("temp", temp, ndim=1)
    if len(t_raw) != len(g):
        raise InputError(f"temp has {len(t_raw)} samples but gyro has {len(g)}")
    fs = positive("sample_rate", sample_rate)
    if not 0 <= int(max_order) <= MAX_ORDER:
        raise InputError(f"{{param}} must be 0..{MAX_ORDER} (PX4 and ArduPilot evaluate cubics), got {max_order!r}",
                         param="max_order", value=max_order)
    _check_input(g, t_raw, fs, at_least("min_span", min_span, 0.0, " degC"))
    size = max(10, int(round(block_s * fs)))
    course = temperature_course(t_raw, fs)
    gm, tm = _blocks(g, course.temp, course.valid, size)
    if len(gm) < 4 * (MAX_ORDER + 1):
        raise InputError(f"the log holds {len(gm)} blocks of {size / fs:g} s; a thermal-bias fit needs at least "
                         f"{4 * (MAX_ORDER + 1)}: log longer")
    tmin, tmax = float(tm.min()), float(tm.max())
    if tmax - tmin < min_span:
        raise InputError(f"the temperature is known well enough over {tmin:.1f} to {tmax:.1f} degC only (readings in "
                         f"steps of {course.quantum:g} degC); a bias-versus-temperature fit needs {min_span:g} degC")
    tref, half = 0.5 * (tmin + tmax), 0.5 * (tmax - tmin)
    u = (tm - tref) / half
    seg = np.minimum(((u + 1) / 2 * segments).astype(int), segments - 1)
    cv = np.full((MAX_ORDER + 1, 3), np.nan)
    cv[: max_order + 1] = segment_cv(u, gm, seg, int(max_order))
    orders = choose_orders(cv[: max_order + 1], len(np.unique(seg)))
    d = np.diff(g[: len(g) // size * size].reshape(-1, size, 3), axis=1).reshape(-1, 3)
    noise = MAD_TO_SIGMA * np.median(np.abs(d - np.median(d, axis=0)), axis=0) / math.sqrt(2.0)  # white, robust to drift
    coefs, cov, resid_rms, wander = _fit_axes(u, gm, orders, noise**2 / size, half)
    found = _quality(resid_rms, noise, size, cv, orders)
    for message in found:
        warnings.warn(message, ThermalBiasWarning, stacklevel=2)
    fit = {"blocks": len(gm), "block_s": size / fs, "segments": int(segments), "max_order": int(max_order),
           "min_span_degC": min_span, "temperature": course.method,
           "noise_model": wander}
    return ThermalBias(coefs, cov, orders, tref, tmin, tmax, np.nan_to_num(cv, nan=0.0), resid_rms, noise, fs,
                       len(g) / fs, fit, dict(source or {}), tuple(found))


def _fit_axes(u, gm, orders, white_var, half):
    """Each axis's polynomial of its order, in powers of (T - tref), with its covariance."""
    coefs = np.zeros((3, MAX_ORDER + 1))
    cov = np.zeros((3, MAX_ORDER + 1, MAX_ORDER + 1))
    resid_rms = np.empty(3)
    wander = []
    for a, p in enumerate(orders):
        X = vander(u, int(p))
        c, *_ = np.linalg.lstsq(X, gm[:, a], rcond=None)
        r = gm[:, a] - X @ c
        C, model = ar1_covariance(X, r, white_var[a])
        wander.append({k: float(v) for k, v in model.items()})
        scale = half ** -np.arange(p + 1)  # from powers of u to powers of (T - tref)
        coefs[a, : p + 1] = c * scale
        cov[a, : p + 1, : p + 1] = C * np.outer(scale, scale)
        resid_rms[a] = math.sqrt(np.mean(r**2))
    return coefs, cov, resid_rms, wander


def _quality(resid_rms, noise, size, cv, orders) -> list[str]:
    """Warnings where the residuals or the left-out predictions exceed what the noise explains."""
    found = []
    white = noise / math.sqrt(size)
    for a, axis in enumerate("xyz"):
        ratio = resid_rms[a] / max(white[a], 1e-300)
        if ratio > 3:
            found.append(f"axis {axis}: the block residuals are {ratio:.1f}x the white noise (bias instability or "
                         "temperature lag); the 1-sigma is taken from the residuals")
        held = cv[orders[a], a] / max(resid_rms[a], 1e-300)
        if held > 3:
            found.append(f"axis {axis}: predicting each temperature segment from the others errs {held:.1f}x the "
                         "residual; the curve is uncertain between and beyond the data")
    return found
