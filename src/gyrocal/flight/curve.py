"""One sensor's offset against temperature: the polynomial fit shared by the gyro and the accelerometer.

A warming log is cut into blocks once (:class:`BlockGrid`, from the temperature course); each
sensor's readings then go through :func:`fit_sensor`: block means, the order of each axis by
leave-one-temperature-segment-out error (:func:`.polyfit.choose_orders`), the polynomial and the
1-sigma of its coefficients under white noise plus a Gauss-Markov wander
(:func:`.polyfit.ar1_covariance`). :class:`TemperaturePolynomial` evaluates the result.

``relative=True`` (the accelerometer) fits the *change* from the reference temperature: a board
that holds one orientation sees gravity plus the offset, so the constant term is not the offset
and is dropped. Dropping it from the coefficients and from their covariance gives exactly the
change ``f(T) - f(tref)`` and its 1-sigma, zero at ``tref``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._arrays import distinct
from .._validation import finite_array
from .._white import robust_difference_std
from ..errors import InputError
from .polyfit import ar1_covariance, choose_orders, segment_cv, vander

__all__ = ["AccelDrift", "BlockGrid", "SensorFit", "TemperaturePolynomial", "check_curve", "fit_sensor"]

#: Highest order PX4 (X0..X3) and ArduPilot (constant + GYR1..GYR3) evaluate.
MAX_ORDER = 3


class TemperaturePolynomial:
    """Evaluation of ``coefs`` (3, MAX_ORDER + 1) in powers of ``(clip(T) - tref)``, with ``covariance``.

    A mixin: the class provides ``coefs``, ``covariance``, ``tref``, ``tmin`` and ``tmax``.
    """

    def clip(self, temp) -> np.ndarray:
        """Temperatures [degC] clipped to the fitted range, as PX4 and ArduPilot clip them."""
        return np.clip(np.asarray(temp, dtype=float), self.tmin, self.tmax)

    def value_at(self, temp) -> np.ndarray:
        """The polynomials (N, 3) at temperatures (N,) [degC], clipped to ``[tmin, tmax]``."""
        d = self.clip(np.atleast_1d(temp)) - self.tref
        return vander(d, MAX_ORDER) @ self.coefs.T

    def std_at(self, temp) -> np.ndarray:
        """1-sigma (N, 3) of :meth:`value_at`."""
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


def check_curve(obj, extra: tuple[tuple[str, tuple], ...] = ()) -> None:
    """Validate and freeze the arrays, orders and range of a frozen dataclass holding a curve."""
    k = MAX_ORDER + 1
    for name, shape in (("coefs", (3, k)), ("covariance", (3, k, k)), ("cv_rms", (k, 3)),
                        ("residual_rms", (3,)), ("noise_std", (3,)), *extra):
        arr = finite_array(name, getattr(obj, name))
        if arr.shape != shape:
            raise InputError(f"{name} must have shape {shape}, got {arr.shape}")
        arr.setflags(write=False)
        object.__setattr__(obj, name, arr)
    orders = np.asarray(obj.orders, dtype=int)
    if orders.shape != (3,) or np.any(orders < 0) or np.any(orders > MAX_ORDER):
        raise InputError(f"orders must be 3 integers in 0..{MAX_ORDER}, got {obj.orders!r}")
    orders.setflags(write=False)
    object.__setattr__(obj, "orders", orders)
    if not (obj.tmin <= obj.tref <= obj.tmax and obj.tmax > obj.tmin):
        raise InputError(f"need tmin <= tref <= tmax and tmax > tmin, got {obj.tmin}, {obj.tref}, {obj.tmax}")


@dataclass(frozen=True)
class AccelDrift(TemperaturePolynomial):
    """The accelerometer offsets' change from ``tref`` against temperature, per axis, with its 1-sigma.

    ``change(T) = sum_{n >= 1} coefs[n] (clip(T, tmin, tmax) - tref)^n`` [m/s^2]: zero at ``tref``
    (``coefs[:, 0]`` and the covariance's first row and column are 0). The compensated reading is
    ``reading - change(T)``; the absolute offset at ``tref`` is the ordinary six-pose calibration's.
    Fields as for :class:`~.thermal_bias.ThermalBias`, in m/s^2; ``fit`` holds the noise model.
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
    fit: dict = field(default_factory=dict)

    def __post_init__(self):
        check_curve(self)
        if np.any(self.coefs[:, 0] != 0) or np.any(self.covariance[:, 0, :] != 0) or np.any(
                self.covariance[:, :, 0] != 0):
            raise InputError("an accelerometer change from tref has no constant term: coefs[:, 0] and the "
                             "covariance's first row and column must be 0")

    def change_at(self, temp) -> np.ndarray:
        """Change (N, 3) [m/s^2] of the offsets from ``tref`` at temperatures (N,) [degC], clipped."""
        return self.value_at(temp)


@dataclass(frozen=True)
class BlockGrid:
    """The blocks of a warming log, made once from its temperature course and used by every sensor.

    ``keep`` marks the blocks whose temperature is known; ``u`` is their temperature scaled to
    [-1, 1] about ``tref`` (``half`` degrees per unit), ``seg`` their temperature segment.
    """

    size: int
    keep: np.ndarray
    u: np.ndarray
    seg: np.ndarray
    tref: float
    half: float

    def means(self, x: np.ndarray) -> np.ndarray:
        """Block means (blocks kept, 3) of readings (N, 3)."""
        nb = len(self.keep)
        return x[: nb * self.size].reshape(nb, self.size, 3).mean(axis=1)[self.keep]


@dataclass(frozen=True)
class SensorFit:
    """What :func:`fit_sensor` found for one sensor (arrays as :class:`TemperaturePolynomial` reads them)."""

    coefs: np.ndarray
    covariance: np.ndarray
    orders: np.ndarray
    cv_rms: np.ndarray
    residual_rms: np.ndarray
    noise_std: np.ndarray
    noise_model: list
    warnings: list


def check_axes(x: np.ndarray, sensor: str) -> None:
    """Refuse a constant column: it holds no offset to fit."""
    for j, axis in enumerate("xyz"):
        if x[:, j].min() == x[:, j].max():
            raise InputError(f"{sensor} axis {axis} reads {float(x[0, j]):g} in every sample: a constant column "
                             "holds no offset to fit (a dead sensor, or the wrong column mapped?)")


def fit_sensor(x: np.ndarray, grid: BlockGrid, max_order: int, *, label: str = "", relative: bool = False
               ) -> SensorFit:
    """Each axis's polynomial of its chosen order for readings `x` (N, 3) on `grid`.

    `label` starts the warnings (``"accelerometer "``); `relative` drops the constant term (the
    change from ``tref``, see the module note).
    """
    means = grid.means(x)
    cv = np.full((MAX_ORDER + 1, 3), np.nan)
    cv[: max_order + 1] = segment_cv(grid.u, means, grid.seg, int(max_order))
    orders = choose_orders(cv[: max_order + 1], len(distinct(grid.seg)))
    size = grid.size
    d = np.diff(x[: len(x) // size * size].reshape(-1, size, 3), axis=1).reshape(-1, 3)
    noise = robust_difference_std(d)  # white, robust to drift
    coefs, cov, resid_rms, wander = _fit_axes(grid.u, means, orders, noise**2 / size, grid.half)
    if relative:
        coefs[:, 0] = 0.0
        cov[:, 0, :] = cov[:, :, 0] = 0.0
    found = _quality(resid_rms, noise, size, cv, orders, label)
    return SensorFit(coefs, cov, orders, np.nan_to_num(cv, nan=0.0), resid_rms, noise, wander, found)


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


def _quality(resid_rms, noise, size, cv, orders, label) -> list[str]:
    """Warnings where the residuals or the left-out predictions exceed what the noise explains."""
    found = []
    white = noise / math.sqrt(size)
    for a, axis in enumerate("xyz"):
        ratio = resid_rms[a] / max(white[a], 1e-300)
        if ratio > 3:
            found.append(f"{label}axis {axis}: the block residuals are {ratio:.1f}x the white noise (bias instability "
                         "or temperature lag); the 1-sigma is taken from the residuals")
        held = cv[orders[a], a] / max(resid_rms[a], 1e-300)
        if held > 3:
            found.append(f"{label}axis {axis}: predicting each temperature segment from the others errs {held:.1f}x "
                         "the residual; the curve is uncertain between and beyond the data")
    return found
