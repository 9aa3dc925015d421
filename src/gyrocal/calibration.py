"""A calibration with its units and provenance, and its versioned JSON file.

File layout (``format: gyrocal.calibration``, ``version: 1``)::

    {
      "format": "gyrocal.calibration", "version": 1,
      "model": "scale-bias" | "affine",
      "method": "first-moment" | "algorithm1" | "lm" | ...,
      "units": {"input": "deg/s", "output": "deg/s", "sensitivity": null, "internal": "rad/s"},
      "correction": {"equation": "w_true = matrix @ (raw - offset)", "matrix": [[...]], "offset": [...]},
      "parameters": {...},            # the paper's own, in internal units (see below)
      "std": {"kx": ..., ...},        # 1-sigma of each parameter, internal units, or null
      "covariance": [[...]] | null,   # same order as "std"
      "noise_std": [...] | null,      # per-sample noise behind the covariance, internal units
      "windows": [{...}, ...],        # the windows the fit used
      "created_by": "gyrocal 0.1.0"
    }

``correction`` is in the user's units: ``offset`` in input units, ``matrix`` maps input
units to output units. ``parameters`` hold seed 000's ``k, b`` (``b`` in internal
units) or seed 001's ``Kg`` 12-vector (eq. 14 order). Internal units are rad/s,
or raw counts when no sensitivity was given.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import __version__
from ._jsonfile import check_header, get, get_array, read_json, write_json
from .errors import FileFormatError, InputError, NonPhysicalEstimateError, UnitError
from .models import Affine, CalibrationModel, ScaleBias
from .units import InputUnit, RateUnit, parse_input_unit, parse_rate_unit, unit_factor

__all__ = ["FORMAT", "VERSION", "Calibration", "load_calibration", "save_calibration"]

FORMAT = "gyrocal.calibration"
VERSION = 1


@dataclass(frozen=True)
class Calibration:
    """A fitted model together with the units it applies to.

    Parameters
    ----------
    model : ScaleBias or Affine
        Maps internal readings (rad/s, or counts without a sensitivity) to rad/s.
    input_units : {"rad/s", "deg/s", "counts"}
        Unit of the raw data the calibration is applied to.
    output_units : {"rad/s", "deg/s"}
        Unit of the corrected rates.
    sensitivity : float, optional
        For counts: LSB per output unit. Without it, counts stay counts inside and the
        scale factors absorb the sensitivity.
    method : str
        Estimator that produced the model.
    covariance : ndarray, optional
        Covariance of ``model.params`` [internal units].
    noise_std : ndarray, shape (3,), optional
        Per-sample noise standard deviation behind the covariance [internal units].
    windows : tuple of dict
        The windows used: ``start``, ``stop`` (sample indices), ``kind``, and when known
        ``axis``, ``sign``, ``angle_deg``, ``rate`` [rad/s].
    """

    model: CalibrationModel
    input_units: InputUnit = "rad/s"
    output_units: RateUnit = "rad/s"
    sensitivity: float | None = None
    method: str = "first-moment"
    covariance: np.ndarray | None = None
    noise_std: np.ndarray | None = None
    windows: tuple[dict, ...] = field(default_factory=tuple)

    def __post_init__(self):
        object.__setattr__(self, "input_units", parse_input_unit(self.input_units, "input_units"))
        object.__setattr__(self, "output_units", parse_rate_unit(self.output_units, "output_units"))
        if self.sensitivity is not None:
            if self.input_units != "counts":
                raise UnitError("sensitivity applies only to input_units='counts'")
            if not (math.isfinite(self.sensitivity) and self.sensitivity > 0):
                raise InputError(f"sensitivity must be > 0 LSB per {self.output_units}, got {self.sensitivity}")
        p = len(self.model.params)
        if self.covariance is not None:
            cov = np.asarray(self.covariance, dtype=float)
            if cov.shape != (p, p):
                raise InputError(f"covariance must be ({p}, {p}) for a {self.model.kind} model, got {cov.shape}")
            object.__setattr__(self, "covariance", cov)
        if self.noise_std is not None:
            object.__setattr__(self, "noise_std", np.asarray(self.noise_std, dtype=float).reshape(3))
        object.__setattr__(self, "windows", tuple(dict(w) for w in self.windows))

    @property
    def internal_units(self) -> str:
        """``rad/s``, or ``counts`` when raw counts come without a sensitivity."""
        return "counts" if self.input_units == "counts" and self.sensitivity is None else "rad/s"

    @property
    def input_scale(self) -> float:
        """Multiplier from input units to internal units."""
        if self.input_units == "counts":
            return 1.0 if self.sensitivity is None else unit_factor(self.output_units) / self.sensitivity
        return unit_factor(self.input_units)

    @property
    def correction(self) -> tuple[np.ndarray, np.ndarray]:
        """``(matrix, offset)`` in user units: ``w_out = matrix @ (raw - offset)``."""
        c, d = self.input_scale, unit_factor(self.output_units)
        return self.model.matrix * (c / d), self.model.offset / c

    @property
    def std(self) -> np.ndarray | None:
        """1-sigma of ``model.params`` [internal units], or None."""
        return None if self.covariance is None else np.sqrt(np.diag(self.covariance))

    def apply(self, raw) -> np.ndarray:
        """Correct raw readings (..., 3) in input units; returns output units."""
        from .models import correct

        matrix, offset = self.correction
        return correct(matrix, offset, raw)


def _parameters_doc(model: CalibrationModel) -> dict:
    if isinstance(model, ScaleBias):
        return {"seed000": model.to_dict()}
    return {"seed001": model.to_dict()}


def to_document(cal: Calibration) -> dict[str, Any]:
    """The JSON-ready document of a calibration."""
    matrix, offset = cal.correction
    std = cal.std
    return {
        "format": FORMAT,
        "version": VERSION,
        "model": cal.model.kind,
        "method": cal.method,
        "units": {
            "input": cal.input_units,
            "output": cal.output_units,
            "sensitivity": cal.sensitivity,
            "internal": cal.internal_units,
        },
        "correction": {"equation": "w_true = matrix @ (raw - offset)", "matrix": matrix.tolist(), "offset": offset.tolist()},
        "parameters": _parameters_doc(cal.model),
        "std": None if std is None else dict(zip(cal.model.param_names, std.tolist())),
        "covariance": None if cal.covariance is None else cal.covariance.tolist(),
        "noise_std": None if cal.noise_std is None else cal.noise_std.tolist(),
        "windows": list(cal.windows),
        "created_by": f"gyrocal {__version__}",
    }


def _is_covariance(cov: np.ndarray) -> bool:
    """Symmetric and positive semi-definite, to rounding."""
    scale = max(float(np.abs(cov).max()), np.finfo(float).tiny)
    return bool(np.allclose(cov, cov.T, rtol=0, atol=1e-12 * scale)
                and np.linalg.eigvalsh((cov + cov.T) / 2).min() >= -1e-9 * scale)


def from_document(doc: dict, path="file") -> Calibration:
    """Validate a document and rebuild the :class:`Calibration`, naming any bad field."""
    if not isinstance(doc, dict):
        raise FileFormatError(f"{path}: expected a JSON object at the top level, got {type(doc).__name__}")
    check_header(doc, path, FORMAT, (VERSION,))
    kind = get(doc, "model", path)
    try:
        if kind == "scale-bias":
            model: CalibrationModel = ScaleBias(
                k=get_array(doc, "parameters.seed000.k", (3,), path), b=get_array(doc, "parameters.seed000.b", (3,), path)
            )
        elif kind == "affine":
            model = Affine.from_kg(get_array(doc, "parameters.seed001.kg", (12,), path))
        else:
            raise FileFormatError(f"{path}: field 'model' is {kind!r}; expected 'scale-bias' or 'affine'", "model")
    except (InputError, NonPhysicalEstimateError, ValueError) as exc:
        if isinstance(exc, FileFormatError):
            raise
        raise FileFormatError(f"{path}: field 'parameters' does not describe a gyro: {exc}", "parameters") from None
    n = len(model.params)
    input_units, output_units = get(doc, "units.input", path), get(doc, "units.output", path)
    sensitivity = get(doc, "units.sensitivity", path)
    if sensitivity is not None and (isinstance(sensitivity, bool) or not isinstance(sensitivity, (int, float))):
        raise FileFormatError(f"{path}: field 'units.sensitivity' must be a number or null, got {sensitivity!r}",
                              "units.sensitivity")
    method = get(doc, "method", path)
    if not isinstance(method, str):
        raise FileFormatError(f"{path}: field 'method' must be a string, got {method!r}", "method")
    covariance = get_array(doc, "covariance", (n, n), path, allow_none=True)
    if covariance is not None and not _is_covariance(covariance):
        raise FileFormatError(f"{path}: field 'covariance' must be symmetric positive semi-definite", "covariance")
    windows = get(doc, "windows", path)
    if not isinstance(windows, list) or not all(isinstance(w, dict) for w in windows):
        raise FileFormatError(f"{path}: field 'windows' must be a list of objects", "windows")
    try:
        cal = Calibration(
            model=model,
            input_units=input_units,
            output_units=output_units,
            sensitivity=sensitivity,
            method=method,
            covariance=covariance,
            noise_std=get_array(doc, "noise_std", (3,), path, allow_none=True),
            windows=tuple(windows),
        )
    except InputError as exc:
        raise FileFormatError(f"{path}: field 'units': {exc}", "units") from None
    matrix = get_array(doc, "correction.matrix", (3, 3), path)
    offset = get_array(doc, "correction.offset", (3,), path)
    want_m, want_o = cal.correction
    if not (np.allclose(matrix, want_m, rtol=1e-9, atol=0) and np.allclose(offset, want_o, rtol=1e-9, atol=1e-12)):
        raise FileFormatError(
            f"{path}: field 'correction' disagrees with 'parameters'; the file was edited inconsistently", "correction"
        )
    return cal


def save_calibration(cal: Calibration, path: str | os.PathLike) -> None:
    """Write `cal` to `path` as versioned JSON, atomically."""
    write_json(path, to_document(cal))


def load_calibration(path: str | os.PathLike) -> Calibration:
    """Read and validate a calibration file."""
    return from_document(read_json(path), path)
