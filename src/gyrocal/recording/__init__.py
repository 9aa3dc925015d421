"""The recording and its time base: the first stage every job passes through.

Owns :class:`Recording` (time, three rates, optional side channels, here), the clock a log was
sampled on and its gaps (:mod:`.timebase`, :mod:`.timegaps`), where a log is not contiguous
(:mod:`.breaks`) and samples stuck at full scale (:mod:`.saturation`).

Layer 1 (the recording and its time base) of docs/architecture.md: imports only the package root.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .._arrays import readonly
from .._validation import finite_array, positive
from ..choices import AccelUnit, values
from ..errors import InputError
from .timebase import TimeBase, analyse_time, nominal_period

__all__ = ["Recording"]


_LOWER_X, _LOWER_Z = ord("x"), ord("z")


def _axis_letters(values) -> np.ndarray | None:
    """Axis labels as lower-case ``x``, ``y``, ``z`` (None when one is anything else).

    One-letter labels are checked on their character codes (setting bit 5 lower-cases X, Y, Z and
    moves no other character into x..z), which is many times faster than string functions on long logs.
    """
    axis = np.asarray(values, dtype=str)
    if axis.dtype.itemsize != 4:
        axis = np.char.lower(axis)
        return axis.astype("<U1") if np.isin(axis, ("x", "y", "z")).all() else None
    codes = axis.view(np.uint32)
    lower = codes | 0x20
    if not ((lower >= _LOWER_X) & (lower <= _LOWER_Z)).all():
        return None
    return axis if np.array_equal(lower, codes) else lower.view("<U1")


@dataclass(frozen=True)
class Recording:
    """Samples of one gyro, in gyrocal's internal units.

    The arrays are read-only views of what was passed in (no copy is made), so a
    caller should not modify its own arrays after building a recording.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Sample times [s], strictly increasing.
    gyro : ndarray, shape (N, 3)
        Readings [rad/s], or raw counts when ``units == "counts"`` (no sensitivity known).
    units : {"rad/s", "counts"}
        Internal unit of ``gyro``.
    source_units : str
        Unit the data were declared in (``rad/s``, ``deg/s`` or ``counts``), for output.
    sample_rate : float
        Nominal sampling rate [Hz]: given, or the mean rate of the sensor clock measured on the
        stamps (:func:`gyrocal.recording.timebase.nominal_period`), never the median of bursty steps.
    has_time : bool
        Whether ``t`` came from the data (False: built from ``sample_rate``).
    temp : ndarray, shape (N,), or None
        Sensor temperature [degC].
    table_rate : ndarray, shape (N,), or None
        Signed turntable rate [rad/s].
    axis : ndarray of str, shape (N,), or None
        Body axis (``"x"``, ``"y"``, ``"z"``) along the table axis, positive up.
    extra : dict of str to ndarray
        Other columns, passed through unchanged by ``apply``.
    sensitivity : float or None
        LSB per output rate unit, when raw counts were converted to rad/s.
    accel : ndarray, shape (N, 3), or None
        Accelerometer readings [m/s^2], or raw counts when ``accel_units == "counts"``.
    accel_units : {"m/s^2", "counts"} or None
        Internal unit of ``accel`` (counts only when no sensitivity was known).
    accel_source_units : {"m/s^2", "g", "counts"} or None
        Unit the accelerometer data were declared in, for output.
    accel_sensitivity : float or None
        LSB per g, when raw accelerometer counts were converted to m/s^2.
    breaks : tuple of int
        Samples that start a new part of a log that is not contiguous (:mod:`gyrocal.recording.breaks`):
        no window, pose or turn spans one.
    """

    t: np.ndarray
    gyro: np.ndarray
    units: Literal["rad/s", "counts"] = "rad/s"
    source_units: str = "rad/s"
    sample_rate: float = 0.0
    has_time: bool = True
    temp: np.ndarray | None = None
    table_rate: np.ndarray | None = None
    axis: np.ndarray | None = None
    extra: dict[str, np.ndarray] = field(default_factory=dict)
    sensitivity: float | None = None
    accel: np.ndarray | None = None
    accel_units: Literal["m/s^2", "counts"] | None = None
    accel_source_units: str | None = None
    accel_sensitivity: float | None = None
    breaks: tuple[int, ...] = ()

    def __post_init__(self):
        gyro = finite_array("gyro", self.gyro, shape_tail=(3,), ndim=2)
        n = len(gyro)
        t = finite_array("t", self.t, ndim=1)
        if t.shape != (n,):
            raise InputError(f"t has {len(t)} samples but gyro has {n}")
        steps_ok = t[1:] > t[:-1]
        if not steps_ok.all():
            i = int(np.argmin(steps_ok))
            raise InputError(f"time does not increase at sample {i + 1} (t={t[i]} then {t[i + 1]}); sort or deduplicate the log")
        if self.units not in ("rad/s", "counts"):
            raise InputError(f"units must be 'rad/s' or 'counts' inside gyrocal, got {self.units!r}")
        fs = self.sample_rate or (1.0 / nominal_period(t) if n >= 2 else 0.0)
        object.__setattr__(self, "sample_rate", positive("sample_rate", fs))
        object.__setattr__(self, "t", readonly(t, None, copy=False))
        object.__setattr__(self, "gyro", readonly(gyro, None, copy=False))
        for name in ("temp", "table_rate"):
            value = getattr(self, name)
            if value is not None:
                arr = finite_array(name, value, ndim=1)
                if arr.shape != (n,):
                    raise InputError(f"{name} has {len(arr)} samples but gyro has {n}")
                object.__setattr__(self, name, readonly(arr, None, copy=False))
        if self.axis is not None:
            axis = _axis_letters(self.axis)
            if axis is None or axis.shape != (n,):
                raise InputError("axis must hold one of 'x', 'y', 'z' for every sample")
            object.__setattr__(self, "axis", readonly(axis, None, copy=False))
        self._check_accel(n)
        breaks = tuple(sorted({int(b) for b in self.breaks}))
        if breaks and not 0 < breaks[0] <= breaks[-1] < n:
            raise InputError(f"breaks must lie between samples 1 and {n - 1}, got {breaks[0]}..{breaks[-1]}")
        object.__setattr__(self, "breaks", breaks)

    def _check_accel(self, n: int) -> None:
        if self.accel is None:
            if self.accel_units is not None or self.accel_source_units is not None or self.accel_sensitivity is not None:
                raise InputError("accel_units, accel_source_units and accel_sensitivity need accel data")
            return
        accel = finite_array("accel", self.accel, shape_tail=(3,), ndim=2)
        if len(accel) != n:
            raise InputError(f"accel has {len(accel)} samples but gyro has {n}")
        units = self.accel_units or "m/s^2"
        if units not in ("m/s^2", "counts"):
            raise InputError(f"accel_units must be 'm/s^2' or 'counts' inside gyrocal, got {units!r}",
                             param="accel_units", value=units)
        source = self.accel_source_units or units
        if source not in values(AccelUnit):
            raise InputError(f"accel_source_units must be one of {', '.join(values(AccelUnit))}, got {source!r}",
                             param="accel_source_units", value=source)
        if self.accel_sensitivity is not None:
            positive("accel_sensitivity", self.accel_sensitivity)
        object.__setattr__(self, "accel", readonly(accel, None, copy=False))
        object.__setattr__(self, "accel_units", units)
        object.__setattr__(self, "accel_source_units", source)

    def __len__(self) -> int:
        return len(self.gyro)

    @classmethod
    def from_rate(cls, gyro, sample_rate: float, t0: float = 0.0, **kwargs) -> "Recording":
        """A recording without a time column: ``t = t0 + i / sample_rate``."""
        g = np.asarray(gyro, dtype=float)
        fs = positive("sample_rate", sample_rate)
        return cls(t=t0 + np.arange(len(g)) / fs, gyro=g, sample_rate=fs, has_time=False, **kwargs)

    def time_base(self) -> TimeBase:
        """Facts about the time stamps: nominal rate, jitter, late deliveries and real gaps."""
        return analyse_time(self.t, has_time=self.has_time, breaks=self.breaks)

    def slice(self, start: int, stop: int) -> np.ndarray:
        """Readings of samples ``start:stop`` (N, 3)."""
        return self.gyro[start:stop]
