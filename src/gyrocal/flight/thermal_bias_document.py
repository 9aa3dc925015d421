"""The thermal-bias file (``format: gyrocal.thermal-bias``, version 2).

Layout (internal units, recorded in ``units``)::

    {
      "format": "gyrocal.thermal-bias", "version": 2,
      "model": "bias(T) = sum_n coefs[n] * (clip(T, tmin, tmax) - tref)^n; corrected = reading - bias(T)",
      "units": {"bias": "rad/s", "coefs": "rad/s/degC^n", "temperature": "degC"},
      "tref": 20.0, "tmin": -8.9, "tmax": 49.0,
      "axes": {"x": {"order": 3, "coefs": [c0, c1, c2, c3], "covariance": [[...]], "cv_rms": [...],
                     "residual_rms": .., "noise_std": ..}, "y": {...}, "z": {...}},
      "sample_rate": 100.0, "duration": 2700.0,
      "fit": {...}, "source": {"file": ..., "imu": 0, "device_id": 2424842, ...},
      "warnings": [...], "created_by": "gyrocal 0.1.0",
      "accelerometer": null, or
        {"model": "change(T) = ... zero at tref", "units": {"change": "m/s^2", ...},
         "tref": .., "tmin": .., "tmax": .., "axes": {"x": {...as above, in m/s^2}, ...}, "fit": {...}}
    }

``coefs`` always hold four numbers (zero above the axis's order), ``cv_rms`` the
leave-one-segment-out error of each order 0..3 (0 where not tried). The accelerometer's
``coefs[0]`` is 0: what one orientation gives is the change from ``tref``, not the offset.
Version 1 (no ``accelerometer``) is upgraded by :mod:`gyrocal.results.legacy`; version 2 exists so
that a gyrocal that knows only the gyro refuses a file rather than drop its accelerometer.
"""

from __future__ import annotations

import math
import os

import numpy as np

from .._jsonfile import check_header, get, get_array
from .._version import __version__
from ..errors import FileFormatError, InputError
from ..results.files import load, save
from .thermal_bias import MAX_ORDER, AccelDrift, ThermalBias

__all__ = ["FORMAT", "VERSION", "from_document", "load_thermal_bias", "save_thermal_bias", "to_document"]

FORMAT = ThermalBias.FORMAT
VERSION = ThermalBias.VERSION
MODEL = "bias(T) = sum_n coefs[n] * (clip(T, tmin, tmax) - tref)^n; corrected = reading - bias(T)"
ACCEL_MODEL = ("change(T) = sum_{n>=1} coefs[n] * (clip(T, tmin, tmax) - tref)^n, zero at tref (one orientation: "
               "the change with temperature, not the offset); corrected = reading - change(T)")


def _axes(curve) -> dict:
    return {axis: {"order": int(curve.orders[a]), "coefs": curve.coefs[a].tolist(),
                   "covariance": curve.covariance[a].tolist(), "cv_rms": curve.cv_rms[:, a].tolist(),
                   "residual_rms": float(curve.residual_rms[a]), "noise_std": float(curve.noise_std[a])}
            for a, axis in enumerate("xyz")}


def _accel_document(drift: AccelDrift | None) -> dict | None:
    if drift is None:
        return None
    return {"model": ACCEL_MODEL,
            "units": {"change": "m/s^2", "coefs": "m/s^2/degC^n", "temperature": "degC", "noise_std": "m/s^2"},
            "tref": drift.tref, "tmin": drift.tmin, "tmax": drift.tmax, "axes": _axes(drift), "fit": dict(drift.fit)}


def to_document(tb: ThermalBias) -> dict:
    """The JSON-ready document of `tb`."""
    return {"format": FORMAT, "version": VERSION, "model": MODEL,
            "units": {"bias": "rad/s", "coefs": "rad/s/degC^n", "temperature": "degC", "noise_std": "rad/s"},
            "tref": tb.tref, "tmin": tb.tmin, "tmax": tb.tmax, "axes": _axes(tb),
            "sample_rate": tb.sample_rate, "duration": tb.duration, "fit": dict(tb.fit), "source": dict(tb.source),
            "warnings": list(tb.warnings), "created_by": f"gyrocal {__version__}",
            "accelerometer": _accel_document(tb.accel)}


def _number(doc, dotted, path) -> float:
    value = get(doc, dotted, path)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise FileFormatError(f"{path}: field '{dotted}' must be a finite number, got {value!r}", dotted)
    return float(value)


def _read_axes(doc: dict, prefix: str, path) -> dict:
    """The per-axis arrays under ``{prefix}axes``, each field named on error."""
    k = MAX_ORDER + 1
    cols = {name: [] for name in ("coefs", "covariance", "cv_rms", "residual_rms", "noise_std", "order")}
    for axis in "xyz":
        base = f"{prefix}axes.{axis}"
        order = get(doc, f"{base}.order", path)
        if type(order) is not int or not 0 <= order <= MAX_ORDER:
            raise FileFormatError(f"{path}: field '{base}.order' must be an integer 0..{MAX_ORDER}", f"{base}.order")
        coefs = get_array(doc, f"{base}.coefs", (k,), path)
        if np.any(coefs[order + 1:] != 0):
            raise FileFormatError(f"{path}: field '{base}.coefs' has terms above order {order}", f"{base}.coefs")
        cols["order"].append(order)
        cols["coefs"].append(coefs)
        cols["covariance"].append(get_array(doc, f"{base}.covariance", (k, k), path))
        cols["cv_rms"].append(get_array(doc, f"{base}.cv_rms", (k,), path))
        cols["residual_rms"].append(_number(doc, f"{base}.residual_rms", path))
        cols["noise_std"].append(_number(doc, f"{base}.noise_std", path))
    out = {name: np.array(v) for name, v in cols.items()}
    out["cv_rms"] = out["cv_rms"].T
    return out


def _read_accel(doc: dict, path) -> AccelDrift | None:
    section = get(doc, "accelerometer", path)
    if section is None:
        return None
    if not isinstance(section, dict):
        raise FileFormatError(f"{path}: field 'accelerometer' must be an object or null", "accelerometer")
    c = _read_axes(doc, "accelerometer.", path)
    return AccelDrift(c["coefs"], c["covariance"], c["order"], _number(doc, "accelerometer.tref", path),
                      _number(doc, "accelerometer.tmin", path), _number(doc, "accelerometer.tmax", path),
                      c["cv_rms"], c["residual_rms"], c["noise_std"], dict(section.get("fit") or {}))


def from_document(doc: dict, path="file") -> ThermalBias:
    """Validate a document and rebuild the fit, naming any bad field."""
    check_header(doc, path, FORMAT, (VERSION,))
    c = _read_axes(doc, "", path)
    try:
        return ThermalBias(c["coefs"], c["covariance"], c["order"], _number(doc, "tref", path),
                           _number(doc, "tmin", path), _number(doc, "tmax", path), c["cv_rms"], c["residual_rms"],
                           c["noise_std"], _number(doc, "sample_rate", path), _number(doc, "duration", path),
                           dict(doc.get("fit") or {}), dict(doc.get("source") or {}),
                           tuple(str(w) for w in doc.get("warnings") or ()), _read_accel(doc, path))
    except InputError as exc:
        raise FileFormatError(f"{path}: {exc}") from None




def save_thermal_bias(tb: ThermalBias, path: str | os.PathLike) -> None:
    """Write `tb` as versioned JSON, atomically."""
    save(tb, path)


def load_thermal_bias(path: str | os.PathLike) -> ThermalBias:
    """Read and validate a ``gyrocal.thermal-bias`` file."""
    return load(path, ThermalBias)
