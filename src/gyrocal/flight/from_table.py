"""The bias part of a turntable calibration (the full-temperature-range method) as a :class:`ThermalBias`.

A ``gyrocal.thermal`` file holds the full-temperature-range method's 12 parameters (eq. 11-14)
at each temperature and a smooth polynomial of each in temperature. PX4 and ArduPilot
compensate the bias alone, so only ``Bx, By, Bz`` (the reading at rest, eq. 12 with ``w~ = 0``)
travel; a warning says how much scale and misalignment change over the range, since those
firmwares cannot carry it.
"""

from __future__ import annotations

import warnings

import numpy as np

from .._arrays import median
from ..errors import GyrocalWarning, InputError
from ..thermal import ThermalCalibration
from .thermal_bias import MAX_ORDER, ThermalBias

__all__ = ["ScaleNotCarriedWarning", "bias_from_thermal"]

_BIAS = slice(9, 12)  # Bx, By, Bz in the eq. 14 order


class ScaleNotCarriedWarning(GyrocalWarning):
    """A turntable calibration's scale and misalignment change with temperature, and the export drops them."""


def bias_from_thermal(cal: ThermalCalibration) -> ThermalBias:
    """The smooth bias polynomials of `cal`, with the covariance propagated from each point's 1-sigma.

    Raises
    ------
    InputError
        A bias polynomial above the third order (what PX4 and ArduPilot evaluate).
    """
    sm = cal.smooth
    orders = np.asarray(sm.orders)[_BIAS]
    if np.any(orders > MAX_ORDER):
        raise InputError(f"the thermal file's bias polynomials have orders {orders.tolist()}; PX4 and ArduPilot "
                         f"evaluate cubics: calibrate again with a maximum order of {MAX_ORDER} (CLI --max-order 3)")
    k = MAX_ORDER + 1
    u = (cal.temps - sm.centre) / sm.scale
    scale = sm.scale ** -np.arange(k)  # from powers of u to powers of (T - centre)
    coefs = np.zeros((3, k))
    cov = np.zeros((3, k, k))
    sd = cal.std if cal.std is not None else cal.std_noise
    for a, p in enumerate(orders):
        coefs[a, : p + 1] = sm.coefs[9 + a, : p + 1] * scale[: p + 1]
        if sd is not None:  # the smooth fit is unweighted least squares: c = pinv(V) y
            A = np.linalg.pinv(np.vander(u, p + 1, increasing=True)) * scale[: p + 1, None]
            cov[a, : p + 1, : p + 1] = A @ np.diag(sd[:, 9 + a] ** 2) @ A.T
    notes = []
    if sd is None:
        notes.append("the thermal file holds no 1-sigma per point: the bias curve's uncertainty is unknown (0)")
    K = cal.kg[:, :9]
    ppm = float(np.max(np.abs(K - K[cal.reference_index]))) * 1e6
    notes.append(f"scale factors and misalignment change with temperature in this calibration (up to {ppm:.0f} ppm "
                 "over the range); PX4 and ArduPilot thermal parameters carry the bias only, so only it is exported")
    for note in notes:
        warnings.warn(note, ScaleNotCarriedWarning, stacklevel=2)
    tmin, tmax = cal.range
    residual = np.sqrt(np.mean((sm(cal.temps)[:, _BIAS] - cal.kg[:, _BIAS]) ** 2, axis=0))
    cv = np.zeros((k, 3))
    cv[: sm.loto_rms.shape[0]] = sm.loto_rms[:k, _BIAS]
    noise = np.zeros(3) if cal.residual_rms is None else median(cal.residual_rms, axis=0)
    return ThermalBias(coefs, cov, orders, float(sm.centre), tmin, tmax, cv, residual, noise,
                       sample_rate=float(cal.settings.get("sample_rate", 1.0) or 1.0), duration=0.0,
                       fit={"from": "gyrocal.thermal smooth bias polynomials"},
                       source={"file": cal.settings.get("source", "a gyrocal.thermal file"), "kind": "turntable"},
                       warnings=tuple(notes))
