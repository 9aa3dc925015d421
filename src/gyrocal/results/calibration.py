"""A calibration with its units and provenance, and its versioned document.

Document layout (``format: gyrocal.calibration``, ``version: 2``; see docs/files.md)::

    {
      "format": "gyrocal.calibration", "version": 2,
      "model": "scale-bias" | "affine",
      "method": "first-moment" | "algorithm1" | "lm" | ...,
      "units": {"input": "deg/s", "output": "deg/s", "sensitivity": null, "internal": "rad/s"},
      "correction": {"equation": "w_true = matrix @ (raw - offset)", "matrix": [[...]], "offset": [...]},
      "parameters": {"scale_bias": {"k": [...], "b": [...]}}
                  | {"affine": {"K": [[...]], "B": [...], "kg": [...], "kg_order": ["Kxx", ...]}},
      "std": {"kx": ..., ...} | null,       # 1-sigma of each parameter, internal units
      "covariance": [[...]] | null,         # same order as "std"
      "noise_std": [...] | null,            # per-sample noise behind the covariance, internal units
      "fit": {...} | null, "observed": {...} | null, "accelerometer": {...} | null,
      "windows": [{...}, ...],              # the windows the fit used
      "created_by": "gyrocal 0.2.0"
    }

``correction`` is in the user's units: ``offset`` in input units, ``matrix`` maps input
units to output units. ``parameters`` hold the model's own parameters in internal units
(rad/s, or raw counts when no sensitivity was given): the servo method of Wang et al.
(eq. 1, ``g = diag(k) (m + b)``) for ``scale_bias``, the full-temperature-range method
(eq. 11-14, ``w = K w~ + B``) for ``affine``. Version 1 files are upgraded on load by
:mod:`gyrocal.results.legacy`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

import numpy as np

from .._jsonfile import check_header, get, get_array
from .._validation import refuse_options
from .._version import __version__
from ..errors import FileFormatError, InputError, NonPhysicalEstimateError, UnitError
from ..models import KG_NAMES, Affine, CalibrationModel, ScaleBias
from ..recording import Recording
from ..units import InputUnit, RateUnit, input_scale, parse_input_unit, parse_rate_unit, unit_factor
from .sections import AccelerometerPart, FitQuality, Observed, section

__all__ = ["Calibration", "used_windows"]

#: Key of each model's parameters in the document.
_PARAMETERS_KEY = {"scale-bias": "scale_bias", "affine": "affine"}


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
    fit, observed, accelerometer : mapping, optional
        The optional sections (:class:`~gyrocal.results.sections.FitQuality`,
        :class:`~gyrocal.results.sections.Observed`, :class:`~gyrocal.results.sections.AccelerometerPart`);
        a plain mapping is checked and frozen into its section type.
    """

    FORMAT: ClassVar[str] = "gyrocal.calibration"
    VERSION: ClassVar[int] = 2
    #: Options :meth:`apply` accepts (none beyond the recording).
    APPLY_OPTIONS: ClassVar[tuple[str, ...]] = ()

    model: CalibrationModel
    input_units: InputUnit = "rad/s"
    output_units: RateUnit = "rad/s"
    sensitivity: float | None = None
    method: str = "first-moment"
    covariance: np.ndarray | None = None
    noise_std: np.ndarray | None = None
    windows: tuple[dict, ...] = field(default_factory=tuple)
    fit: FitQuality | None = None
    observed: Observed | None = None
    accelerometer: AccelerometerPart | None = None

    def __post_init__(self):
        object.__setattr__(self, "input_units", parse_input_unit(self.input_units, "input_units"))
        object.__setattr__(self, "output_units", parse_rate_unit(self.output_units, "output_units"))
        if self.sensitivity is not None:
            if self.input_units != "counts":
                raise UnitError("sensitivity applies only to input_units='counts'", param="sensitivity")
            if not (math.isfinite(self.sensitivity) and self.sensitivity > 0):
                raise InputError(f"{{param}} must be > 0 LSB per {self.output_units}, got {self.sensitivity}",
                                 param="sensitivity", value=self.sensitivity)
        p = len(self.model.params)
        if self.covariance is not None:
            cov = np.asarray(self.covariance, dtype=float)
            if cov.shape != (p, p):
                raise InputError(f"covariance must be ({p}, {p}) for a {self.model.kind} model, got {cov.shape}",
                                 param="covariance")
            object.__setattr__(self, "covariance", cov)
        if self.noise_std is not None:
            object.__setattr__(self, "noise_std", np.asarray(self.noise_std, dtype=float).reshape(3))
        object.__setattr__(self, "windows", tuple(dict(w) for w in self.windows))
        for name, cls in (("fit", FitQuality), ("observed", Observed), ("accelerometer", AccelerometerPart)):
            object.__setattr__(self, name, section(cls, getattr(self, name)))

    # --- views ---------------------------------------------------------------------------------------------
    @property
    def internal_units(self) -> str:
        """``rad/s``, or ``counts`` when raw counts come without a sensitivity."""
        return "counts" if self.input_units == "counts" and self.sensitivity is None else "rad/s"

    @property
    def input_scale(self) -> float:
        """Multiplier from input units to internal units (:func:`gyrocal.units.input_scale`)."""
        return input_scale(self.input_units, self.sensitivity, self.output_units)

    @property
    def correction(self) -> tuple[np.ndarray, np.ndarray]:
        """``(matrix, offset)`` in user units: ``w_out = matrix @ (raw - offset)``."""
        c, d = self.input_scale, unit_factor(self.output_units)
        return self.model.matrix * (c / d), self.model.offset / c

    @property
    def std(self) -> np.ndarray | None:
        """1-sigma of ``model.params`` [internal units], or None."""
        return None if self.covariance is None else np.sqrt(np.diag(self.covariance))

    # --- use -----------------------------------------------------------------------------------------------
    def correct(self, raw) -> np.ndarray:
        """Correct raw readings (..., 3) in input units; returns output units."""
        from ..models import correct

        matrix, offset = self.correction
        return correct(matrix, offset, raw)

    def apply(self, rec: Recording, **options) -> Recording:
        """The recording with its gyro (and accelerometer, when this calibration has a part for it) corrected.

        Parameters
        ----------
        rec : Recording
            Read in this calibration's input units: raw counts stay counts when the
            calibration has no sensitivity; with one, the recording may hold counts or
            rates converted with the same sensitivity.
        **options
            None are accepted (the interface is shared with other calibration kinds).

        Returns
        -------
        Recording
            ``gyro`` corrected [rad/s], ``source_units`` the calibration's output unit; every
            other column unchanged.
        """
        refuse_options(options, self.APPLY_OPTIONS, f"a {self.FORMAT} file")
        if not isinstance(rec, Recording):
            raise InputError(f"apply takes a Recording, got {type(rec).__name__}; use correct(raw) for arrays of readings")
        if rec.units == self.internal_units:
            raw = rec.gyro
        elif rec.units == "counts":  # counts and a calibration that knows their sensitivity
            raw = rec.gyro * self.input_scale
        else:
            raise UnitError(
                "the calibration works on raw counts but the recording was converted to rad/s; "
                "read it as counts without a sensitivity", param="units")
        fields: dict[str, Any] = {"gyro": self.model.correct(raw), "units": "rad/s",
                                  "source_units": self.output_units, "sensitivity": None}
        if self.accelerometer is not None and rec.accel is not None:
            fields.update(self.accelerometer.apply_to(rec))
            coupling = self.accelerometer.gyro_coupling(fields.get("accel"))
            if coupling is not None:  # the gyro's g-sensitivity, in input units
                fields["gyro"] = self.model.correct(raw - coupling * self.input_scale)
            fields.update(self._thermal_fields(rec, raw))
        return replace(rec, **fields)

    def _thermal_fields(self, rec: Recording, raw) -> dict[str, Any]:
        """Both sensors corrected at each sample's temperature by ``accelerometer.thermal`` (none: no change)."""
        thermal = self.accelerometer.get("thermal")
        if thermal is None or rec.temp is None:
            return {}
        if rec.accel_units != thermal["internal"]["accelerometer"]:
            raise UnitError(f"the accelerometer's model in temperature takes {thermal['internal']['accelerometer']} "
                            f"but the recording's accelerometer is in {rec.accel_units}", param="accel_units")
        from ..imu.thermal import correct_with_section

        gyro, accel = correct_with_section(thermal, raw, rec.accel, rec.temp)
        return {"gyro": gyro, "accel": accel}

    def c_header(self, prefix: str = "gyrocal") -> str:
        """Firmware header for ``gyrocal_correct`` (see :func:`gyrocal.firmware.header.calibration_header`)."""
        from ..firmware.header import calibration_header

        return calibration_header(self, prefix=prefix)

    # --- document ------------------------------------------------------------------------------------------
    def _parameters_document(self) -> dict:
        return {_PARAMETERS_KEY[self.model.kind]: self.model.to_dict()}

    def to_document(self) -> dict[str, Any]:
        """The JSON-ready document (format version 2)."""
        matrix, offset = self.correction
        std = self.std

        def opt(part):
            return None if part is None else part.to_document()

        return {
            "format": self.FORMAT,
            "version": self.VERSION,
            "model": self.model.kind,
            "method": self.method,
            "units": {"input": self.input_units, "output": self.output_units, "sensitivity": self.sensitivity,
                      "internal": self.internal_units},
            "correction": {"equation": "w_true = matrix @ (raw - offset)", "matrix": matrix.tolist(),
                           "offset": offset.tolist()},
            "parameters": self._parameters_document(),
            "std": None if std is None else dict(zip(self.model.param_names, std.tolist())),
            "covariance": None if self.covariance is None else self.covariance.tolist(),
            "noise_std": None if self.noise_std is None else self.noise_std.tolist(),
            "fit": opt(self.fit),
            "observed": opt(self.observed),
            "accelerometer": opt(self.accelerometer),
            "windows": list(self.windows),
            "created_by": f"gyrocal {__version__}",
        }

    @classmethod
    def from_document(cls, doc: dict, path: Any = "document") -> Calibration:
        """Validate a version-2 document and rebuild the calibration, naming any bad field.

        Older versions go through :func:`gyrocal.results.files.load` (or :func:`gyrocal.results.legacy.upgrade`) first.
        """
        if not isinstance(doc, dict):
            raise FileFormatError(f"{path}: expected a JSON object at the top level, got {type(doc).__name__}")
        check_header(doc, path, cls.FORMAT, (cls.VERSION,))
        model = _model_from_document(doc, path)
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
        parts = {name: None if doc.get(name) is None else kind.from_document(doc[name], path)
                 for name, kind in (("fit", FitQuality), ("observed", Observed), ("accelerometer", AccelerometerPart))}
        try:
            cal = cls(model=model, input_units=input_units, output_units=output_units, sensitivity=sensitivity,
                      method=method,
                      covariance=covariance, noise_std=get_array(doc, "noise_std", (3,), path, allow_none=True),
                      windows=tuple(windows), **parts)
        except InputError as exc:
            raise FileFormatError(f"{path}: field 'units': {exc}", "units") from None
        _check_correction(doc, cal, path)
        return cal


def used_windows(windows, rates) -> tuple[dict, ...]:
    """The windows a fit used, as the file records them: each window's own fields and its reference rate."""
    return tuple({**w.to_dict(), "rate": rate} for w, rate in zip(windows, rates))


def _model_from_document(doc: dict, path) -> CalibrationModel:
    kind = get(doc, "model", path)
    if kind not in _PARAMETERS_KEY:
        raise FileFormatError(f"{path}: field 'model' is {kind!r}; expected 'scale-bias' or 'affine'", "model")
    key = f"parameters.{_PARAMETERS_KEY[kind]}"
    try:
        if kind == "scale-bias":
            return ScaleBias(k=get_array(doc, f"{key}.k", (3,), path), b=get_array(doc, f"{key}.b", (3,), path))
        if get(doc, f"{key}.kg_order", path) != list(KG_NAMES):
            raise FileFormatError(f"{path}: field '{key}.kg_order' must be {list(KG_NAMES)}", f"{key}.kg_order")
        model = Affine.from_kg(get_array(doc, f"{key}.kg", (12,), path))
        K, B = get_array(doc, f"{key}.K", (3, 3), path), get_array(doc, f"{key}.B", (3,), path)
    except (InputError, NonPhysicalEstimateError) as exc:
        raise FileFormatError(f"{path}: field 'parameters' does not describe a gyro: {exc}", "parameters") from None
    if not (np.array_equal(K, model.K) and np.array_equal(B, model.B)):
        raise FileFormatError(f"{path}: fields '{key}.K' and '{key}.B' disagree with '{key}.kg'", f"{key}.K")
    return model


def _check_correction(doc: dict, cal: Calibration, path) -> None:
    matrix = get_array(doc, "correction.matrix", (3, 3), path)
    offset = get_array(doc, "correction.offset", (3,), path)
    want_m, want_o = cal.correction
    if not (np.allclose(matrix, want_m, rtol=1e-9, atol=0) and np.allclose(offset, want_o, rtol=1e-9, atol=1e-12)):
        raise FileFormatError(
            f"{path}: field 'correction' disagrees with 'parameters'; the file was edited inconsistently", "correction"
        )


def _is_covariance(cov: np.ndarray) -> bool:
    """Symmetric and positive semi-definite, to rounding."""
    scale = max(float(np.abs(cov).max()), np.finfo(float).tiny)
    return bool(np.allclose(cov, cov.T, rtol=0, atol=1e-12 * scale)
                and np.linalg.eigvalsh((cov + cov.T) / 2).min() >= -1e-9 * scale)
