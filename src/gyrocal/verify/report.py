"""The verification report and its versioned JSON document (``gyrocal.verify``).

Document layout (``version: 1``; rates in ``units.rates``, MSE in its square)::

    {
      "format": "gyrocal.verify", "version": 1,
      "units": {"rates": "deg/s", "mse": "(deg/s)^2", ...},
      "clock": "t_test = t_ref * (1 + clock_drift_ppm * 1e-6) + time_offset_s",
      "time_offset_s": ..., "time_offset_s_std": ..., "clock_drift_ppm": ..., "clock_drift_ppm_std": ...,
      "offset_at_centre_s": ..., "offset_at_centre_s_std": ..., "drift_fitted": true,
      "mounting": "w_test = mounting_rotation @ w_ref",
      "mounting_rotation": [[...], [...], [...]], "mounting_rotation_deg": ..., "mounting_rotation_deg_std": ...,
      "alignment": {"covariance": [[...]], "covariance_order": [...], "correlation_peak": ..., ...},
      "noise": {"reference": [...], "reference_std": [...], "test_after": [...]},
      "axes": {"x": {"mse_before": ..., "mse_before_std": ..., "mse_after": ..., ...}, "y": {...}, "z": {...}},
      "bootstrap": {"block_samples": ..., "blocks": ..., "replicates": ..., "seed": ...},
      "inputs": {...}, "warnings": [...], "created_by": "gyrocal X.Y.Z"
    }

A figure that cannot be computed (before calibration, for raw counts without a
sensitivity) is ``null``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from .._jsonfile import check_header, get, get_array
from .._version import __version__
from ..errors import FileFormatError
from ..units import RateUnit, parse_rate_unit, unit_factor
from .alignment import Alignment
from .metrics import FIGURES, Metrics

__all__ = ["FORMAT", "VERSION", "VerifyReport"]

FORMAT = "gyrocal.verify"
VERSION = 1
AXES = ("x", "y", "z")
COVARIANCE_ORDER = ("time_offset_s", "clock_drift_ppm", "phi_x_rad", "phi_y_rad", "phi_z_rad")


@dataclass(frozen=True)
class VerifyReport:
    """A calibration checked against a reference gyro.

    Attributes
    ----------
    alignment : Alignment
        Clock and mounting relation (rates inside it in rad/s).
    metrics : Metrics
        Per-axis error figures [units, units^2].
    units : {"rad/s", "deg/s"}
        Unit of the figures: the calibration's output unit.
    reference_noise, reference_noise_std : ndarray, shape (3,)
        White noise of the reference per reference axis, and its 1-sigma [units].
    test_noise : ndarray, shape (3,)
        White noise of the calibrated test log per test axis [units].
    seed : int
        Seed of the bootstrap.
    inputs : dict
        What was compared (file names, reading settings), for the record.
    warnings : tuple of str
        Everything that does not hold together.
    """

    alignment: Alignment
    metrics: Metrics
    units: RateUnit
    reference_noise: np.ndarray
    reference_noise_std: np.ndarray
    test_noise: np.ndarray
    seed: int
    inputs: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()

    FORMAT: ClassVar[str] = FORMAT
    VERSION: ClassVar[int] = VERSION

    def to_document(self) -> dict:
        """The JSON-ready document (see the module docstring)."""
        a, u = self.alignment, unit_factor(self.units)
        std = a.std
        return {
            "format": FORMAT, "version": VERSION,
            "units": {"rates": self.units, "mse": f"({self.units})^2", "time": "s", "drift": "ppm", "angles": "deg",
                      "reduction": "%"},
            "clock": "t_test = t_ref * (1 + clock_drift_ppm * 1e-6) + time_offset_s",
            "time_offset_s": a.time_offset_s, "time_offset_s_std": float(std[0]),
            "clock_drift_ppm": a.clock_drift_ppm, "clock_drift_ppm_std": float(std[1]), "drift_fitted": a.drift_fitted,
            "offset_at_centre_s": a.offset_at_centre_s, "offset_at_centre_s_std": a.offset_at_centre_std_s,
            "mounting": "w_test = mounting_rotation @ w_ref",
            "mounting_rotation": a.mounting_rotation.tolist(),
            "mounting_rotation_deg": a.rotation_deg, "mounting_rotation_deg_std": a.rotation_deg_std,
            "alignment": {
                "covariance": a.covariance.tolist(), "covariance_order": list(COVARIANCE_ORDER),
                "correlation_peak": a.correlation_peak, "residual_rms": (a.residual_rms / u).tolist(),
                "n_samples": a.n_samples, "overlap_s": a.overlap_s, "block_samples": a.block,
                "iterations": a.iterations,
            },
            "noise": {"reference": self.reference_noise.tolist(), "reference_std": self.reference_noise_std.tolist(),
                      "test_after": self.test_noise.tolist(), "estimator": "second differences, median absolute deviation"},
            "axes": {ax: {k: _finite_or_none(v) for k, v in self.metrics.axis(j).items()} for j, ax in enumerate(AXES)},
            "bootstrap": {"block_samples": self.metrics.block, "blocks": self.metrics.blocks,
                          "replicates": self.metrics.replicates, "seed": self.seed},
            "inputs": dict(self.inputs),
            "warnings": list(self.warnings),
            "created_by": f"gyrocal {__version__}",
        }

    @classmethod
    def from_document(cls, doc: dict, path="file") -> VerifyReport:
        """Validate a document and rebuild the report, naming any bad field."""
        if not isinstance(doc, dict):
            raise FileFormatError(f"{path}: expected a JSON object at the top level")
        check_header(doc, path, FORMAT, (VERSION,))
        units = parse_rate_unit(get(doc, "units.rates", path), "units.rates")
        u = unit_factor(units)
        alignment = Alignment(
            time_offset_s=_number(doc, "time_offset_s", path), clock_drift_ppm=_number(doc, "clock_drift_ppm", path),
            offset_at_centre_s=_number(doc, "offset_at_centre_s", path),
            mounting_rotation=get_array(doc, "mounting_rotation", (3, 3), path),
            covariance=get_array(doc, "alignment.covariance", (5, 5), path),
            offset_at_centre_std_s=_number(doc, "offset_at_centre_s_std", path),
            correlation_peak=_number(doc, "alignment.correlation_peak", path),
            residual_rms=get_array(doc, "alignment.residual_rms", (3,), path) * u,
            noise_test=get_array(doc, "noise.test_after", (3,), path) * u,
            noise_ref=get_array(doc, "noise.reference", (3,), path) * u,
            n_samples=int(_number(doc, "alignment.n_samples", path)),
            overlap_s=_number(doc, "alignment.overlap_s", path), drift_fitted=bool(get(doc, "drift_fitted", path)),
            block=int(_number(doc, "alignment.block_samples", path)),
            iterations=int(_number(doc, "alignment.iterations", path)))
        metrics = Metrics(values={k: _axis_values(doc, k, path) for k in FIGURES},
                          std={k: _axis_values(doc, f"{k}_std", path) for k in FIGURES},
                          block=int(_number(doc, "bootstrap.block_samples", path)),
                          blocks=int(_number(doc, "bootstrap.blocks", path)),
                          replicates=int(_number(doc, "bootstrap.replicates", path)))
        warnings = get(doc, "warnings", path)
        if not isinstance(warnings, list) or not all(isinstance(w, str) for w in warnings):
            raise FileFormatError(f"{path}: field 'warnings' must be a list of strings", "warnings")
        return cls(alignment=alignment, metrics=metrics, units=units,
                   reference_noise=get_array(doc, "noise.reference", (3,), path),
                   reference_noise_std=_axis_array(get(doc, "noise.reference_std", path), "noise.reference_std", path),
                   test_noise=get_array(doc, "noise.test_after", (3,), path),
                   seed=int(_number(doc, "bootstrap.seed", path)), inputs=dict(get(doc, "inputs", path) or {}),
                   warnings=tuple(warnings))


def _finite_or_none(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _number(doc: dict, dotted: str, path) -> float:
    value = get(doc, dotted, path)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise FileFormatError(f"{path}: field '{dotted}' must be a finite number, got {value!r}", dotted)
    return float(value)


def _axis_array(values, dotted: str, path) -> np.ndarray:
    """Three numbers or nulls (NaN) at `dotted`."""
    if not isinstance(values, list) or len(values) != 3:
        raise FileFormatError(f"{path}: field '{dotted}' must list 3 numbers or nulls", dotted)
    out = []
    for v in values:
        if v is None:
            out.append(math.nan)
        elif isinstance(v, bool) or not isinstance(v, (int, float)):
            raise FileFormatError(f"{path}: field '{dotted}' must list 3 numbers or nulls, got {v!r}", dotted)
        else:
            out.append(float(v))
    return np.asarray(out)


def _axis_values(doc: dict, key: str, path) -> np.ndarray:
    axes = get(doc, "axes", path)
    if not isinstance(axes, dict):
        raise FileFormatError(f"{path}: field 'axes' must be an object with x, y and z", "axes")
    return _axis_array([get(doc, f"axes.{ax}.{key}", path) for ax in AXES], f"axes.*.{key}", path)
