"""A gyro recording in memory: time, three rates, and optional side channels."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from ._validation import finite_array, positive
from .errors import InputError
from .timebase import TimeBase, analyse_time, nominal_period

__all__ = ["Recording"]


def _readonly(arr: np.ndarray) -> np.ndarray:
    # A read-only view, not a copy: copying 10-million-sample logs costs more than parsing them.
    view = np.asarray(arr).view()
    view.setflags(write=False)
    return view


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
        stamps (:func:`gyrocal.timebase.nominal_period`), never the median of bursty steps.
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
        object.__setattr__(self, "t", _readonly(t))
        object.__setattr__(self, "gyro", _readonly(gyro))
        for name in ("temp", "table_rate"):
            value = getattr(self, name)
            if value is not None:
                arr = finite_array(name, value, ndim=1)
                if arr.shape != (n,):
                    raise InputError(f"{name} has {len(arr)} samples but gyro has {n}")
                object.__setattr__(self, name, _readonly(arr))
        if self.axis is not None:
            axis = np.char.lower(np.asarray(self.axis, dtype=str))
            if axis.shape != (n,) or not np.isin(axis, ("x", "y", "z")).all():
                raise InputError("axis must hold one of 'x', 'y', 'z' for every sample")
            object.__setattr__(self, "axis", _readonly(axis))

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
        return analyse_time(self.t, has_time=self.has_time)

    def slice(self, start: int, stop: int) -> np.ndarray:
        """Readings of samples ``start:stop`` (N, 3)."""
        return self.gyro[start:stop]
