"""Window reductions: what the estimators see of a recording.

A window of raw samples is reduced to its mean, its mean of squares, a white-noise
variance, its sample count and its duration, together with its reference:

* ``speed``: a known constant rate magnitude during the window;
* ``angle``: a known angle turned inside the window, giving ``rate = angle / duration``;
* ``static``: no rotation (rate zero).

:class:`ObservationSet` stacks windows into arrays, optionally with a leading batch
axis (many gyros measured with one design), which is what the estimators consume.

The package owns the reductions: many windows' moments at once (:mod:`.moments`), honest variances of
window means under correlated noise and ripple (:mod:`.longrun`, :mod:`.partial_cycles`,
:mod:`.window_stats`), a turn's angle from attitude kinematics (:mod:`.turn_angle`) and what a
calibration saw of its data (:mod:`.observed`).

Layer 3 (reading files and observations) of docs/architecture.md: imports the package root and layers 1 to 3
only.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._arrays import readonly
from .._validation import finite_array, positive
from ..errors import InputError
from .moments import window_moments

__all__ = ["Observation", "ObservationSet", "ReferenceKind", "observe", "observe_many"]

ReferenceKind = Literal["speed", "angle", "static"]
_KINDS = ("speed", "angle", "static")


@dataclass(frozen=True)
class Observation:
    """One window's reductions and reference.

    Attributes
    ----------
    mean : ndarray, shape (3,)
        Window mean of the readings [reading units].
    mean_sq : ndarray, shape (3,)
        Window mean of the squared readings [reading units^2] (the servo method of Wang et al., eq. 8 regressors).
    noise_var : ndarray, shape (3,)
        Per-sample white-noise variance, from first differences [reading units^2].
        Differencing removes the rotation itself, ramps and slow vibration.
    count : int
        Number of samples.
    duration : float
        Window length [s], ``count / sample_rate``.
    kind : {"speed", "angle", "static"}
        Reference type.
    rate : float
        Reference mean rate magnitude [rad/s]; 0 for static windows.
    angle : float
        Angle turned inside the window [rad]; NaN unless ``kind == "angle"``.
    mean_var : ndarray, shape (3,), or None
        Variance of the window mean [reading units^2] when it was measured on the window itself
        (long-run variance: correlated noise, speed ripple); None to take white noise,
        ``sigma^2 / count``, with sigma pooled over the windows by the estimator.
    rate_var : float
        Variance of the reference `rate` [rad^2/s^2]: zero for a declared speed or an exact
        angle; a turn with a gap in its time stamps has an angle known only within a bound.
    """

    mean: np.ndarray
    mean_sq: np.ndarray
    noise_var: np.ndarray
    count: int
    duration: float
    kind: ReferenceKind
    rate: float
    angle: float = math.nan
    mean_var: np.ndarray | None = None
    rate_var: float = 0.0

    def __post_init__(self):
        if not (math.isfinite(self.rate_var) and self.rate_var >= 0):
            raise InputError(f"rate_var must be finite and >= 0, got {self.rate_var!r}")
        for name in ("mean", "mean_sq", "noise_var") + (("mean_var",) if self.mean_var is not None else ()):
            object.__setattr__(self, name, _vector3(name, getattr(self, name)))
        if self.kind not in _KINDS:
            raise InputError(f"kind={self.kind!r} is not one of {_KINDS}")
        if int(self.count) < 2:
            raise InputError(f"a window needs at least 2 samples, got count={self.count}")
        positive("duration", self.duration)
        if self.kind == "static" and self.rate != 0:
            raise InputError(f"a static window has rate 0, got {self.rate}")
        if self.kind != "static":
            positive("rate", self.rate)


def _vector3(name: str, value) -> np.ndarray:
    """A read-only copy of a finite 3-vector; anything else goes through :func:`finite_array` for its message.

    Windows are reduced by the thousand: the plain case is checked in a few operations.
    """
    arr = value.astype(float) if isinstance(value, np.ndarray) and value.dtype.kind in "fiu" else None
    if arr is None or arr.shape != (3,) or not (math.isfinite(arr[0]) and math.isfinite(arr[1])
                                                 and math.isfinite(arr[2])):
        arr = np.array(finite_array(name, value, shape_tail=(3,), ndim=1))
    return readonly(arr, copy=False)


def _magnitude(name: str, value) -> float:
    """|value|, refusing zero and non-numbers: a turn's sense does not matter to the norm equations."""
    try:
        magnitude = abs(float(value))
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a non-zero number, got {value!r}") from None
    return positive(name, magnitude)


def observe(
    samples,
    sample_rate: float,
    kind: ReferenceKind,
    *,
    speed: float | None = None,
    angle: float | None = None,
    t=None,
    level=None,
    mean_var=None,
) -> Observation:
    """Reduce a window of readings to an :class:`Observation`.

    Parameters
    ----------
    samples : array_like, shape (n, 3)
        Readings inside the window [reading units].
    sample_rate : float
        Sampling rate [Hz].
    kind : {"speed", "angle", "static"}
        Reference type.
    speed : float, optional
        Known rate magnitude [rad/s]; required for ``kind="speed"``.
    angle : float, optional
        Angle turned inside the window [rad] for ``kind="angle"``; default one revolution (2 pi).
    t : array_like, shape (n,), optional
        Sample times [s] of a log with gaps (dropped samples). The means are then weighted
        by the time each sample stands for, and the duration is the time spanned, so an
        angle reference still gives ``angle = mean rate x duration``. Without it the
        samples are taken as evenly spaced at `sample_rate`.
    level : array_like, shape (3,), optional
        The window's level when it is not its plain mean [reading units]: a plateau with its
        speed ripple regressed out (:func:`gyrocal.observations.longrun.fit_level`).
    mean_var : array_like, shape (3,), optional
        Variance of that level, measured on the data [reading units^2] (see :class:`Observation`).
    """
    m = finite_array("samples", samples, shape_tail=(3,), ndim=2)
    if len(m) < 2:
        raise InputError(f"a window needs at least 2 samples, got {len(m)}")
    if t is not None:
        t = finite_array("t", t, ndim=1)
        if t.shape != (len(m),):
            raise InputError(f"t has {len(t)} sample times but the window has {len(m)} samples")
    return observe_many(m, [0], [len(m)], sample_rate, [kind], speed=speed, angles=[angle], t=t,
                        levels=[level], mean_vars=[mean_var])[0]


def _reference(kind: str, speed, angle, duration: float) -> tuple[float, float]:
    """``(rate, angle)`` of a window of `kind` lasting `duration` [s]."""
    if kind == "speed":
        if speed is None:
            raise InputError("kind='speed' needs speed [rad/s]")
        return _magnitude("speed", speed), math.nan
    if kind == "angle":
        ang = 2 * math.pi if angle is None else _magnitude("angle", angle)
        return ang / duration, ang
    if kind == "static":
        return 0.0, math.nan
    raise InputError(f"kind={kind!r} is not one of {_KINDS}")


def observe_many(x: np.ndarray, starts, stops, sample_rate: float, kinds: Sequence[ReferenceKind], *,
                 speed: float | None = None, angles=None, t: np.ndarray | None = None, period: float | None = None,
                 levels=None, mean_vars=None) -> tuple[Observation, ...]:
    """:func:`observe` for windows ``starts[i]:stops[i]`` of one recording `x` (N, 3), reduced together.

    `x` (and `t`, strictly increasing) are taken as checked, as a :class:`~gyrocal.recording.Recording`'s
    are; `kinds`, `angles`, `levels` and `mean_vars` hold one entry per window (None where :func:`observe`
    takes its default). Without `t`, a window lasts ``count x period`` [s] (default ``1 / sample_rate``).
    The reductions are :func:`gyrocal.observations.moments.window_moments`'s.
    """
    fs = positive("sample_rate", sample_rate)
    n = len(kinds)
    angles, levels, mean_vars = ([None] * n if v is None else v for v in (angles, levels, mean_vars))
    moments = window_moments(x, starts, stops, t)
    counts = np.asarray(stops) - np.asarray(starts)
    out = []
    for i, kind in enumerate(kinds):
        duration = (int(counts[i]) / fs if period is None else int(counts[i]) * period) if t is None \
            else float(moments.duration[i])
        rate, ang = _reference(kind, speed, angles[i], duration)
        out.append(Observation(mean=moments.mean[i] if levels[i] is None else levels[i], mean_var=mean_vars[i],
                               mean_sq=moments.mean_sq[i], noise_var=moments.noise_var[i], count=int(counts[i]),
                               duration=duration, kind=kind, rate=rate, angle=ang))
    return tuple(out)


@dataclass(frozen=True)
class ObservationSet:
    """Windows stacked into arrays, optionally for a batch of gyros.

    Shapes use ``n`` for windows and an optional leading batch axis ``B``:
    ``mean``, ``mean_sq``, ``noise_var`` are (n, 3) or (B, n, 3); ``rate`` is (n,)
    or (B, n); ``count``, ``duration`` and ``static`` are (n,) and shared by the batch
    (one design). Reference rates are in rad/s. ``mean_var`` (optional, the shape of
    ``mean``) holds each window mean's own variance [reading units^2], NaN where the
    estimator is to use pooled white noise (see :class:`Observation`); ``rate_var``
    (optional, (n,)) the variance of each reference rate [rad^2/s^2].
    """

    mean: np.ndarray
    mean_sq: np.ndarray
    noise_var: np.ndarray
    rate: np.ndarray
    count: np.ndarray
    duration: np.ndarray
    static: np.ndarray
    mean_var: np.ndarray | None = None
    rate_var: np.ndarray | None = None

    def __post_init__(self):
        mean = finite_array("mean", self.mean, shape_tail=(3,))
        if mean.ndim not in (2, 3):
            raise InputError(f"mean must have shape (n, 3) or (B, n, 3), got {mean.shape}")
        n = mean.shape[-2]
        for name in ("mean_sq", "noise_var"):
            arr = finite_array(name, getattr(self, name))
            if arr.shape != mean.shape:
                raise InputError(f"{name} must have the shape of mean {mean.shape}, got {arr.shape}")
            object.__setattr__(self, name, arr)
        rate = finite_array("rate", self.rate)
        if rate.shape not in ((n,), mean.shape[:-1]):
            raise InputError(f"rate must have shape ({n},) or {mean.shape[:-1]}, got {rate.shape}")
        for name in ("count", "duration"):
            arr = finite_array(name, getattr(self, name), ndim=1)
            if arr.shape != (n,) or np.any(arr <= 0):
                raise InputError(f"{name} must be {n} positive values, got shape {arr.shape}")
            object.__setattr__(self, name, arr)
        static = np.asarray(self.static, dtype=bool)
        if static.shape != (n,):
            raise InputError(f"static must be {n} flags, got shape {static.shape}")
        if self.mean_var is not None:
            mv = np.asarray(self.mean_var, dtype=float)
            if mv.shape != mean.shape or np.any(mv[np.isfinite(mv)] < 0) or np.any(np.isinf(mv)):
                raise InputError(f"mean_var must be >= 0 (or NaN) with the shape of mean {mean.shape}, got {mv.shape}")
            object.__setattr__(self, "mean_var", mv)
        if self.rate_var is not None:
            rv = finite_array("rate_var", self.rate_var, ndim=1)
            if rv.shape != (n,) or np.any(rv < 0):
                raise InputError(f"rate_var must be {n} values >= 0, got shape {rv.shape}")
            object.__setattr__(self, "rate_var", rv)
        object.__setattr__(self, "mean", mean)
        object.__setattr__(self, "rate", np.broadcast_to(rate, mean.shape[:-1]) if rate.ndim == 1 else rate)
        object.__setattr__(self, "static", static)

    @classmethod
    def from_observations(cls, observations: Sequence[Observation]) -> ObservationSet:
        """Stack single-gyro observations."""
        obs = list(observations)
        if not obs:
            raise InputError("no observations given; a calibration needs at least six")
        return cls(
            mean=np.stack([o.mean for o in obs]),
            mean_sq=np.stack([o.mean_sq for o in obs]),
            noise_var=np.stack([o.noise_var for o in obs]),
            rate=np.array([o.rate for o in obs]),
            count=np.array([o.count for o in obs], dtype=float),
            duration=np.array([o.duration for o in obs]),
            static=np.array([o.kind == "static" for o in obs]),
            mean_var=None if all(o.mean_var is None for o in obs) else np.stack(
                [np.full(3, np.nan) if o.mean_var is None else o.mean_var for o in obs]),
            rate_var=None if all(o.rate_var == 0 for o in obs) else np.array([o.rate_var for o in obs]),
        )

    @property
    def batched(self) -> bool:
        return self.mean.ndim == 3

    def as_batch(self) -> ObservationSet:
        """This set with a leading batch axis (of length 1 if it had none)."""
        if self.batched:
            return self
        return ObservationSet(self.mean[None], self.mean_sq[None], self.noise_var[None], self.rate[None],
                              self.count, self.duration, self.static,
                              None if self.mean_var is None else self.mean_var[None], self.rate_var)

    def take(self, index) -> ObservationSet:
        """The gyros at `index` (a slice, an int array or a boolean mask), still batched."""
        b = self.as_batch()
        idx = index if isinstance(index, slice) else np.asarray(index)
        return ObservationSet(b.mean[idx], b.mean_sq[idx], b.noise_var[idx], b.rate[idx],
                              self.count, self.duration, self.static,
                              None if b.mean_var is None else b.mean_var[idx], self.rate_var)

    @property
    def batch_size(self) -> int:
        """Number of gyros (1 for an unbatched set)."""
        return self.mean.shape[0] if self.batched else 1

    def __len__(self) -> int:
        return self.mean.shape[-2]
