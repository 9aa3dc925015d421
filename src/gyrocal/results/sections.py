"""Optional sections of a calibration file: read-only, validated JSON objects.

A calibration carries a few sections that other parts of gyrocal fill in and that
old files lack: ``fit`` (how well the model fits), ``observed`` (what the data
looked like) and ``accelerometer`` (the accelerometer part of an IMU calibration).
Each is a :class:`Section`: a read-only mapping of JSON values, checked when it is
built and when it is read from a file. Its documented keys are listed in ``FIELDS``
with a check each; other keys are kept as they are, so the owner of a section can
add keys without changing the file code. None of them is required.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np

from ..errors import FileFormatError, InputError
from ..units import STANDARD_GRAVITY

__all__ = ["AccelerometerPart", "FitQuality", "Observed", "Section", "section"]

Check = Callable[[Any], Any]


def _freeze(value: Any, where: str) -> Any:
    """A JSON value made immutable (objects -> read-only mappings, lists -> tuples); numpy becomes Python."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    elif isinstance(value, np.generic):
        value = value.item()
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, float)):
        if not math.isfinite(value):
            raise InputError(f"{where} must be finite, got {value!r}")
        return value
    if isinstance(value, Mapping):
        if not all(isinstance(k, str) for k in value):
            raise InputError(f"{where} must have text keys, got {list(value)!r}")
        return MappingProxyType({k: _freeze(v, f"{where}.{k}") for k, v in value.items()})
    if isinstance(value, (list, tuple)):
        # plain numbers or text, the bulk of a long section (residuals of thousands of windows): as they are
        if all(type(v) in (float, int) for v in value) and all(map(math.isfinite, value)) or \
                all(type(v) is str for v in value):
            return tuple(value)
        return tuple(_freeze(v, f"{where}[{i}]") for i, v in enumerate(value))
    raise InputError(f"{where} must be a JSON value (number, text, list, object or null), got {type(value).__name__}")


def _thaw(value: Any) -> Any:
    """The plain JSON form of a frozen value."""
    if isinstance(value, Mapping):
        return {k: _thaw(v) for k, v in value.items()}
    if isinstance(value, tuple):
        return [_thaw(v) for v in value]
    return value


# -- checks for documented keys: each returns the value or raises ValueError -----------------------------------

def number(lo: float = -math.inf, hi: float = math.inf) -> Check:
    """A real number in [lo, hi]."""
    def check(v):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not lo <= v <= hi:
            raise ValueError(f"must be a number in [{lo:g}, {hi:g}], got {v!r}")
        return v
    return check


def integer(lo: int = 0) -> Check:
    """An integer >= lo."""
    def check(v):
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            raise ValueError(f"must be an integer >= {lo}, got {v!r}")
        return v
    return check


def instance(types, what: str) -> Check:
    """A value of one of `types` (described as `what` in messages)."""
    def check(v):
        if not isinstance(v, types):
            raise ValueError(f"must be {what}, got {_thaw(v)!r}")
        return v
    return check


boolean, text, obj = instance(bool, "true or false"), instance(str, "text"), instance(Mapping, "an object")


def texts(v):
    if not isinstance(v, tuple) or not all(isinstance(s, str) for s in v):
        raise ValueError(f"must be a list of text, got {_thaw(v)!r}")
    return v


def numbers(shape: tuple[int, ...], lo: float = -math.inf) -> Check:
    """Numbers of a given shape (-1: any length), each >= lo."""
    def check(v):
        try:
            arr = np.asarray(_thaw(v), dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"must be numbers of shape {shape}, got {_thaw(v)!r}") from None
        if arr.ndim != len(shape) or any(s not in (-1, n) for s, n in zip(shape, arr.shape)) or np.any(arr < lo):
            raise ValueError(f"must be numbers of shape {shape} (each >= {lo:g}), got shape {arr.shape}")
        return v
    return check


class Section(Mapping):
    """A read-only JSON object with documented optional keys.

    Build it from a mapping (or keywords); ``FIELDS`` maps documented keys to their
    checks. Values must be JSON: numbers (finite), text, booleans, null, lists and objects;
    numpy arrays and scalars are turned into lists and numbers.
    """

    NAME: ClassVar[str] = "section"
    FIELDS: ClassVar[dict[str, Check]] = {}

    def __init__(self, data: Mapping[str, Any] | None = None, /, **values: Any):
        frozen = _freeze({**dict(data or {}), **values}, self.NAME)
        problem = self._problem(frozen)
        if problem is not None:
            key, detail = problem
            raise InputError(f"{self.NAME}.{key} {detail}", param=key, value=_thaw(frozen.get(key.split(".")[0])))
        self._data = frozen

    @classmethod
    def _problem(cls, frozen: Mapping[str, Any]) -> tuple[str, str] | None:
        """``(key, what is wrong)`` for the first documented key that fails its check, else None."""
        for key, check in cls.FIELDS.items():
            if key in frozen and frozen[key] is not None:
                try:
                    check(frozen[key])
                except ValueError as exc:
                    return key, str(exc)
        return None

    def __getitem__(self, key: str) -> Any:
        return self._data[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __repr__(self) -> str:
        return f"{type(self).__name__}({_thaw(self._data)!r})"

    def __setattr__(self, name, value):
        if name != "_data" or "_data" in self.__dict__:
            raise AttributeError(f"{type(self).__name__} is read-only")
        super().__setattr__(name, value)

    def to_document(self) -> dict[str, Any]:
        """The section as plain JSON (dicts and lists)."""
        return _thaw(self._data)

    @classmethod
    def from_document(cls, doc: Any, path: Any = "file"):
        """Rebuild from a file's section, naming the field at fault in a :class:`FileFormatError`."""
        if not isinstance(doc, Mapping):
            raise FileFormatError(f"{path}: field '{cls.NAME}' must be an object or null, got {doc!r}", cls.NAME)
        try:
            frozen = _freeze(doc, cls.NAME)
        except InputError as exc:
            raise FileFormatError(f"{path}: field '{cls.NAME}': {exc}", cls.NAME) from None
        problem = cls._problem(frozen)
        if problem is not None:
            field = f"{cls.NAME}.{problem[0]}"
            raise FileFormatError(f"{path}: field '{field}' {problem[1]}", field)
        return cls(frozen)


def _residuals(v):
    """Residuals in noise units: numbers, one list of numbers per window (of any length), or one
    ``{"window", "label", "z": [numbers]}`` object per window."""
    if isinstance(v, tuple) and v and all(isinstance(z, (tuple, Mapping)) for z in v):
        for r in v:  # plain Python: thousands of windows, a few numbers each
            z = r.get("z", ()) if isinstance(r, Mapping) else r
            if not isinstance(z, tuple) or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in z):
                raise ValueError(f"must hold numbers in every window, got {_thaw(z)!r}")
        return v
    return numbers((-1,))(v)


class FitQuality(Section):
    """How well the model fits the data (``fit`` section; :class:`gyrocal.checks.quality.GoodnessOfFit` writes it).

    Documented keys: ``chi2``, ``dof`` (0: no residual degrees of freedom, nothing checked),
    ``chi2_per_dof``, ``p_value`` (null without dof), ``birge_ratio`` (sqrt(chi2 / dof)),
    ``covariance_scaled`` (whether ``covariance`` and ``std`` hold more than the noise: the windows'
    scatter beyond it (first-moment), or chi2 / dof when p < 0.001 (the paper's methods)), ``residuals`` (one list per window, in the order of ``windows``, in noise units:
    one value for a turn, three for a static window), ``labels`` (the windows' names),
    ``disagree`` (the windows that disagree most, when flagged), ``warnings`` (list of text),
    ``excess`` (the scatter beyond the noise the covariance carries: ``turn_reference_sd`` in
    ``turn_reference_unit``, ``static_level_sd`` per axis in ``static_level_unit``, and ``groups``, each
    group's noise-only ``chi2`` for its ``dof``; null for the paper's methods), ``notes`` (list of text) and
    ``sigma_covers`` (``{"k": text, "b": text}``: what each 1-sigma holds; older files lack it).
    """

    NAME = "fit"
    FIELDS = {"chi2": number(0), "dof": integer(0), "chi2_per_dof": number(0), "p_value": number(0, 1),
              "birge_ratio": number(0), "covariance_scaled": boolean, "residuals": _residuals,
              "labels": texts, "disagree": numbers((-1,), 0), "warnings": texts, "notes": texts,
              "sigma_covers": obj}


class Observed(Section):
    """What the calibration data looked like (``observed`` section), used to catch unit mistakes later.

    Documented keys: ``sample_rate`` [Hz], ``noise_std`` per axis and ``max_abs_rate`` per axis
    [input units], ``units`` (the input unit they are in), ``time_base`` (``nominal_rate`` [Hz],
    ``has_time``, ``mean_step``, ``median_step``, ``jitter`` [s], ``late_deliveries``, ``gaps``,
    ``lost_samples``, ``regular_clock``: :meth:`gyrocal.recording.timebase.TimeBase.to_document`).
    """

    NAME = "observed"
    FIELDS = {"sample_rate": number(0), "noise_std": numbers((3,), 0), "max_abs_rate": numbers((3,), 0),
              "units": text, "time_base": obj}


class AccelerometerPart(Section):
    """The accelerometer part of an IMU calibration (``accelerometer`` section).

    Documented keys: ``units`` ``{input, output, sensitivity, gravity}``, ``correction``
    ``{matrix (3, 3), offset (3,)}`` with ``a_true = matrix @ (raw - offset)`` in those units,
    ``parameters``, ``std``, ``covariance``, ``fit``, ``gyro_g_sensitivity`` (null or ``{matrix (3, 3)}``
    [gyro input units per m/s^2]: the gyro correction becomes ``matrix @ (raw - offset - G a_true)``).
    The whole-IMU calibration (:mod:`gyrocal.imu.filedoc`) adds ``model``, ``sensor_axes``, ``poses``.
    """

    NAME = "accelerometer"
    FIELDS = {"units": obj, "correction": obj, "parameters": obj, "std": obj, "covariance": numbers((-1, -1)),
              "fit": obj, "gyro_g_sensitivity": obj}

    @classmethod
    def _problem(cls, frozen: Mapping[str, Any]) -> tuple[str, str] | None:
        problem = super()._problem(frozen)
        for key, inner in (("units", ("input", "output")), ("correction", ("matrix", "offset"))):
            # what apply and the exporters need: a part without them could only be skipped, or crash
            if problem is None and (frozen.get(key) is None or any(k not in frozen[key] for k in inner)):
                problem = key, f"must be an object with {' and '.join(inner)} (the file is not a gyrocal imu result)"
        corr = frozen.get("correction")
        if problem is None and corr is not None:
            for key, shape in (("matrix", (3, 3)), ("offset", (3,))):
                try:
                    numbers(shape)(corr.get(key))
                except ValueError as exc:
                    return f"correction.{key}", str(exc)
        coupling = frozen.get("gyro_g_sensitivity")
        if problem is None and coupling is not None:
            try:
                numbers((3, 3))(coupling.get("matrix"))
            except ValueError as exc:
                return "gyro_g_sensitivity.matrix", str(exc)
        return problem

    def apply_to(self, rec) -> dict[str, Any]:
        """The corrected accelerometer fields of a :class:`~gyrocal.recording.Recording` (for ``replace``).

        ``correction`` works in ``units.input`` -> ``units.output`` (``m/s^2``, ``g`` with gravity
        ``units.gravity``, default 9.80665 m/s^2, or ``counts`` in; never counts out); without a
        correction the readings pass unchanged.
        """
        corr = self.get("correction")
        if corr is None:
            return {}
        units = self.get("units") or {}
        gravity = float(units.get("gravity") or STANDARD_GRAVITY)
        factor = {"m/s^2": 1.0, "g": gravity}
        u_in, u_out = units.get("input", "m/s^2"), units.get("output", "m/s^2")
        if u_out not in factor or (u_in not in factor and u_in != "counts"):
            raise InputError(f"accelerometer units {_thaw(units)!r} are not m/s^2, g or counts in; "
                             "this gyrocal cannot apply that correction", param="accelerometer")
        if (u_in == "counts") != (rec.accel_units == "counts"):
            raise InputError(f"the accelerometer correction takes {u_in} but the recording's accelerometer "
                             f"is in {rec.accel_units}; read it in {u_in}", param="accel_units")
        raw = rec.accel if u_in == "counts" else rec.accel / factor[u_in]
        matrix, offset = np.asarray(_thaw(corr["matrix"]), float), np.asarray(_thaw(corr["offset"]), float)
        return {"accel": ((raw - offset) @ matrix.T) * factor[u_out], "accel_units": "m/s^2",
                "accel_source_units": u_out, "accel_sensitivity": None}

    def gyro_coupling(self, accel_true) -> np.ndarray | None:
        """The gyro's g-sensitivity term ``G a_true`` (N, 3) [gyro input units], or None without one.

        `accel_true` is the corrected specific force [m/s^2] (``apply_to(rec)["accel"]``); the gyro
        correction then reads ``w_true = matrix @ (raw - offset - G a_true)``.
        """
        g = self.get("gyro_g_sensitivity")
        if g is None or accel_true is None:
            return None
        return np.asarray(accel_true, dtype=float) @ np.asarray(_thaw(g["matrix"]), dtype=float).T


def section(cls: type[Section], value: Any) -> Section | None:
    """`value` as a `cls` section: None stays None, a mapping is checked and frozen."""
    if value is None or isinstance(value, cls):
        return value
    if isinstance(value, Mapping):
        return cls(value)
    raise InputError(f"{cls.NAME} must be a mapping or None, got {type(value).__name__}", param=cls.NAME)
