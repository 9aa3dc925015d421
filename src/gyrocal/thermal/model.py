"""The temperature table: per-point Kg, its interpolation, compensation and document.

Document layout (``format: gyrocal.thermal``, ``version: 2``; see docs/files.md)::

    {
      "format": "gyrocal.thermal", "version": 2, "model": "affine-thermal",
      "units": {"input": "deg/s", "output": "deg/s", "internal": "rad/s", "temperature": "degC"},
      "range": [Tmin, Tmax],
      "interpolation": {"rule": "...", "out_of_range": "refuse"},
      "reference_temp": 25.0,      # traditional baseline: the point nearest to it
      "temp_tau_s": 20.0,          # smoothing of per-sample temperature before lookup
      "kg_order": ["Kxx", ..., "Bz"],
      "points": [{"temp": ..., "kg": [...], "kg_user": [...], "std": [...], "std_noise": [...],
                  "residual_rms": [...], "correction": {"matrix": [[...]], "offset": [...]}}, ...],
      "smooth": {"centre": ..., "scale": ..., "orders": [...], "coefs": [[...]], ...},
      "fit": {...} | null,
      "settings": {...}, "created_by": "gyrocal 0.2.0"
    }

``kg`` is internal (K dimensionless, B in rad/s, the full-temperature-range method's eq. 14
order); ``kg_user`` has B in input units and K scaled by output/input unit factors, so
``w_in = K_user w_out + B_user``; ``correction`` is the canonical
``w_out = matrix @ (raw - offset)`` in user units. The smooth model is stored for internal
``kg``. Version 1 files are upgraded on load by :mod:`gyrocal.results.legacy`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

import numpy as np

from .._arrays import readonly
from .._jsonfile import check_header, get, get_array
from .._validation import at_least, finite_array, refuse_options, temperature
from .._version import __version__
from ..choices import OutOfRange, TableModel, values
from ..errors import FileFormatError, InputError, UnitError
from ..models import KG_NAMES, kg_to_kb
from ..recording import Recording
from ..results.sections import FitQuality, section
from ..units import RateUnit, parse_rate_unit, unit_factor
from ._warn import ThermalRangeWarning
from .lagrange import check_nodes, interpolate, range_policy
from .smooth import SmoothModel
from .tempfilter import DEFAULT_TEMP_TAU, smooth_temperature

__all__ = ["RULE", "TableModel", "ThermalCalibration"]

_MODELS = values(TableModel)
#: Samples compensated at a time.
_CHUNK = 1 << 16
RULE = ("3-node Lagrange (the full-temperature-range method, eq. 21-22): i = first node >= T, stencil nodes s..s+2 "
        "with s = clip(i-2, 0, n-3)")


def _solve3(K: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``K^-1 y`` for stacks of 3 x 3 matrices (N, 3, 3) and vectors (N, 3), by Cramer's rule.

    Elementwise numpy is several times faster than a LAPACK call per tiny matrix; the tables are
    near the identity (condition numbers close to 1), where Cramer's rule is as accurate.
    """
    k0, k1, k2 = K[:, 0], K[:, 1], K[:, 2]  # rows
    c01, c12, c20 = np.cross(k0, k1), np.cross(k1, k2), np.cross(k2, k0)
    det = np.einsum("ij,ij->i", k0, c12)
    return (c12 * y[:, :1] + c20 * y[:, 1:2] + c01 * y[:, 2:]) / det[:, None]


@dataclass(frozen=True)
class ThermalCalibration:
    """A gyro calibrated at several temperatures (the full-temperature-range method).

    Parameters
    ----------
    temps : array_like, shape (n,)
        Temperature points [degC], strictly increasing, n >= 3.
    kg : array_like, shape (n, 12)
        Eq. 14 vectors in internal units (K dimensionless, B [rad/s]).
    smooth : SmoothModel
        Per-element polynomials of ``kg`` in temperature.
    input_units, output_units : {"rad/s", "deg/s"}
        Units of the raw data and of the corrected rates.
    reference_temp : float
        Temperature of the traditional single-temperature baseline [degC]; the
        nearest point is used.
    std, std_noise : array_like, shape (n, 12), optional
        1-sigma of ``kg`` from residuals and from the step noise (internal units).
    residual_rms : array_like, shape (n, 3), optional
        RMS step residual of each fit [rad/s].
    temp_tau : float
        Time constant of the temperature smoothing applied in :meth:`apply` [s].
    settings : dict
        How the table was made (settling time, tolerances), for the record.
    fit : FitQuality or mapping, optional
        How well the per-temperature fits hold together (the ``fit`` section).
    """

    FORMAT: ClassVar[str] = "gyrocal.thermal"
    VERSION: ClassVar[int] = 2
    #: Options :meth:`apply` accepts.
    APPLY_OPTIONS: ClassVar[tuple[str, ...]] = ("model", "out_of_range", "temp_tau")

    temps: np.ndarray
    kg: np.ndarray
    smooth: SmoothModel
    input_units: RateUnit = "rad/s"
    output_units: RateUnit = "rad/s"
    reference_temp: float = 25.0
    std: np.ndarray | None = None
    std_noise: np.ndarray | None = None
    residual_rms: np.ndarray | None = None
    temp_tau: float = DEFAULT_TEMP_TAU
    settings: dict = field(default_factory=dict)
    fit: FitQuality | None = None

    def __post_init__(self):
        temps = check_nodes(self.temps)
        n = len(temps)
        object.__setattr__(self, "temps", readonly(temps, copy=True))
        object.__setattr__(self, "kg", readonly(finite_array("kg", self.kg, shape_tail=(12,), ndim=2), copy=True))
        object.__setattr__(self, "fit", section(FitQuality, self.fit))
        if self.kg.shape[0] != n:
            raise InputError(f"kg has {self.kg.shape[0]} rows but there are {n} temperature points")
        for name, width in (("std", 12), ("std_noise", 12), ("residual_rms", 3)):
            value = getattr(self, name)
            if value is not None:
                arr = finite_array(name, value, ndim=2)
                if arr.shape != (n, width):
                    raise InputError(f"{name} must have shape ({n}, {width}), got {arr.shape}")
                object.__setattr__(self, name, readonly(arr, copy=True))
        object.__setattr__(self, "input_units", parse_rate_unit(self.input_units, "input_units"))
        object.__setattr__(self, "output_units", parse_rate_unit(self.output_units, "output_units"))
        temperature("reference_temp", self.reference_temp)
        at_least("temp_tau", self.temp_tau, 0.0, " s")
        K, _ = kg_to_kb(self.kg)
        cond = np.linalg.cond(K)
        if np.any(~np.isfinite(cond) | (cond > 1e12)):
            bad = int(np.argmax(~np.isfinite(cond) | (cond > 1e12)))
            raise InputError(f"K at {temps[bad]:g} degC is singular; it cannot be inverted")

    # --- views ------------------------------------------------------------
    @property
    def range(self) -> tuple[float, float]:
        """Calibrated temperature range (Tmin, Tmax) [degC]."""
        return float(self.temps[0]), float(self.temps[-1])

    @property
    def reference_index(self) -> int:
        """Index of the point nearest to :attr:`reference_temp` (the traditional baseline)."""
        return int(np.argmin(np.abs(self.temps - self.reference_temp)))

    def to_user(self, kg: np.ndarray) -> np.ndarray:
        """Kg-ordered values (n, 12) in user units: K terms times output/input factor, B in input
        units. Linear, so it serves Kg and its 1-sigma alike."""
        c, d = unit_factor(self.input_units), unit_factor(self.output_units)
        return np.concatenate([kg[:, :9] * (d / c), kg[:, 9:] / c], axis=1)

    @property
    def kg_user(self) -> np.ndarray:
        """Kg (n, 12) in user units (:meth:`to_user`)."""
        return self.to_user(self.kg)

    @property
    def correction(self) -> tuple[np.ndarray, np.ndarray]:
        """Canonical ``(matrix (n, 3, 3), offset (n, 3))`` per point in user units: ``w_out = matrix @ (raw - offset)``."""
        K, B = kg_to_kb(self.kg_user)
        return np.linalg.inv(K), B

    # --- evaluation -------------------------------------------------------
    def kg_at(self, temp, model: TableModel = "lagrange", out_of_range: OutOfRange = "refuse") -> np.ndarray:
        """Kg (N, 12) [internal units] at temperatures (N,) [degC]."""
        t = finite_array("temp", np.atleast_1d(np.asarray(temp, dtype=float)), ndim=1)
        if model == "traditional":
            return np.broadcast_to(self.kg[self.reference_index], (len(t), 12)).copy()
        if model == "lagrange":
            return interpolate(self.temps, self.kg, t, out_of_range)
        if model == "smooth":
            return self.smooth(range_policy(self.temps, t, out_of_range))  # same range policy as the table
        raise InputError(f"{{param}}={model!r} is not one of {', '.join(_MODELS)}", param="model", value=model)

    def compensate(self, gyro, temp, model: TableModel = "lagrange", out_of_range: OutOfRange = "refuse") -> np.ndarray:
        """True rates (N, 3) [rad/s] from readings (N, 3) [rad/s] at temperatures (N,) [degC] (eq. 12 inverted)."""
        w = finite_array("gyro", gyro, shape_tail=(3,), ndim=2)
        t = np.broadcast_to(np.asarray(temp, dtype=float), (len(w),))
        if model not in _MODELS:
            raise InputError(f"{{param}}={model!r} is not one of {', '.join(_MODELS)}", param="model", value=model)
        if model != "traditional":  # the range policy once for the record: one refusal or one warning
            t = range_policy(self.temps, finite_array("temp", t, ndim=1), out_of_range)
        out = np.empty_like(w)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ThermalRangeWarning)  # already said above
            # a chunk at a time: the per-sample tables (N, 3, 12) would outgrow the recording itself
            for start in range(0, len(w), _CHUNK):
                stop = start + _CHUNK
                K, B = kg_to_kb(self.kg_at(t[start:stop], model, "extrapolate"))
                out[start:stop] = _solve3(K, w[start:stop] - B)
        return out

    def apply(self, rec: Recording, **options) -> Recording:
        """The recording with its gyro compensated in temperature.

        The temperature is first smoothed in time (:func:`smooth_temperature`, time
        constant `temp_tau`, default :attr:`temp_tau`), so quantised or noisy readings
        do not make the output jump.

        Parameters
        ----------
        rec : Recording
            Rates [rad/s] with a per-sample ``temp`` [degC].
        **options
            ``model`` ({"lagrange", "smooth", "traditional"}, default "lagrange"),
            ``out_of_range`` ({"refuse", "clamp", "extrapolate"}, default "refuse"),
            ``temp_tau`` [s] (default :attr:`temp_tau`).

        Returns
        -------
        Recording
            ``gyro`` compensated [rad/s], ``source_units`` the table's output unit.
        """
        refuse_options(options, self.APPLY_OPTIONS, f"a {self.FORMAT} file")
        if not isinstance(rec, Recording):
            raise InputError(f"apply takes a Recording, got {type(rec).__name__}; use compensate(gyro, temp) for arrays")
        if rec.temp is None:
            raise InputError("thermal compensation needs a temperature for every sample; the recording has no "
                             "'temp' column", param="columns", hint="map one with {param} temp=NAME")
        if rec.units != "rad/s":
            raise UnitError("the recording is in raw counts without a sensitivity", param="sensitivity",
                            hint="give its {param} in LSB per unit")
        tau = options.get("temp_tau")
        temp = smooth_temperature(rec.temp, rec.sample_rate, self.temp_tau if tau is None else tau)
        gyro = self.compensate(rec.gyro, temp, options.get("model", "lagrange"), options.get("out_of_range", "refuse"))
        return replace(rec, gyro=gyro, source_units=self.output_units, sensitivity=None)

    def c_header(self, prefix: str = "gyrocal") -> str:
        """Firmware header for ``gyrocal_thermal_correct`` (see :func:`gyrocal.firmware.header.thermal_header`)."""
        from ..firmware.header import thermal_header

        return thermal_header(self, prefix=prefix)

    # --- document ---------------------------------------------------------
    def to_document(self) -> dict[str, Any]:
        """The JSON-ready document (format version 2)."""
        matrix, offset = self.correction
        user = self.kg_user

        def row(arr, i):
            return None if arr is None else arr[i].tolist()

        points = [{"temp": float(t), "kg": self.kg[i].tolist(), "kg_user": user[i].tolist(),
                   "std": row(self.std, i), "std_noise": row(self.std_noise, i),
                   "residual_rms": row(self.residual_rms, i),
                   "correction": {"matrix": matrix[i].tolist(), "offset": offset[i].tolist()}}
                  for i, t in enumerate(self.temps)]
        return {
            "format": self.FORMAT, "version": self.VERSION, "model": "affine-thermal",
            "units": {"input": self.input_units, "output": self.output_units, "internal": "rad/s",
                      "temperature": "degC"},
            "range": list(self.range),
            "interpolation": {"rule": RULE, "out_of_range": "refuse"},
            "reference_temp": self.reference_temp,
            "temp_tau_s": self.temp_tau,
            "kg_order": list(KG_NAMES),
            "points": points,
            "smooth": self.smooth.to_dict(),
            "fit": None if self.fit is None else self.fit.to_document(),
            "settings": self.settings,
            "created_by": f"gyrocal {__version__}",
        }

    @classmethod
    def from_document(cls, doc: dict, path: Any = "document") -> ThermalCalibration:
        """Validate a version-2 document and rebuild the table, naming any bad field."""
        if not isinstance(doc, dict):
            raise FileFormatError(f"{path}: expected a JSON object at the top level, got {type(doc).__name__}")
        check_header(doc, path, cls.FORMAT, (cls.VERSION,))
        if get(doc, "kg_order", path) != list(KG_NAMES):
            raise FileFormatError(f"{path}: field 'kg_order' must be {list(KG_NAMES)}", "kg_order")
        pts = get(doc, "points", path)
        if not isinstance(pts, list) or len(pts) < 3:
            raise FileFormatError(f"{path}: field 'points' must list at least 3 temperature points", "points")
        named = {f"points[{i}]": p for i, p in enumerate(pts)}  # so messages say points[2].kg
        cols = {}
        for key, width in (("temp", 1), ("kg", 12), ("std", 12), ("std_noise", 12), ("residual_rms", 3)):
            rows = [get_array(named, f"{name}.{key}", (width,) if key != "temp" else (), path,
                              allow_none=key not in ("kg", "temp")) for name in named]
            cols[key] = None if any(r is None for r in rows) else np.stack(rows)
        fit = doc.get("fit")
        try:
            return cls(
                temps=cols["temp"], kg=cols["kg"], smooth=_smooth_from_document(doc, path),
                input_units=get(doc, "units.input", path), output_units=get(doc, "units.output", path),
                reference_temp=float(get(doc, "reference_temp", path)), std=cols["std"],
                std_noise=cols["std_noise"], residual_rms=cols["residual_rms"],
                temp_tau=float(doc.get("temp_tau_s", DEFAULT_TEMP_TAU)), settings=dict(doc.get("settings") or {}),
                fit=None if fit is None else FitQuality.from_document(fit, path))
        except (InputError, TypeError, ValueError) as exc:
            if isinstance(exc, FileFormatError):
                raise
            raise FileFormatError(f"{path}: {exc}") from None


def _smooth_from_document(doc: dict, path) -> SmoothModel:
    raw = get(doc, "smooth.coefs", path)
    width = len(raw[0]) if isinstance(raw, list) and raw and isinstance(raw[0], list) else 0
    coefs = get_array(doc, "smooth.coefs", (12, width), path)
    loto = get(doc, "smooth", path).get("loto_rms") or np.zeros((1, 12))
    return SmoothModel(centre=float(get(doc, "smooth.centre", path)), scale=float(get(doc, "smooth.scale", path)),
                       orders=np.asarray(get(doc, "smooth.orders", path), int), coefs=coefs,
                       loto_rms=np.asarray(loto, float))
