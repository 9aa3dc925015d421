"""Still intervals of a hand session, found from both sensors with thresholds measured from the data.

The detector follows the idea of Tedaldi et al. (ICRA 2014, "A robust and easy to implement
method for IMU calibration without external equipments"): the board is still where the
variance of the accelerometer over a short moving window is at the sensor's own noise level.
Their threshold is a multiple of the variance seen during an initial still period; here no
initial period is needed:

* the per-axis noise variance of each sensor is the median moving variance of the quietest
  windows (those within a factor 3 of the 5th percentile: standstill in any session in which
  the board rests a few percent of the time, since moving raises the variance by orders of
  magnitude);
* the spread of those quiet variances (robust relative deviation) gives the effective number
  of degrees of freedom of a window variance, and the threshold is its chi-square quantile at
  ``1 - 1e-4``: a still window is flagged as moving once in ten thousand;
* a window is still when both sensors' variances, summed over axes in noise units, are below
  their thresholds and the gyro's window mean is within the same band of its still level
  (a slow steady rotation has little variance but a mean rate).

Still runs shorter than ``min_duration`` are dropped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

from .._arrays import median, percentile
from .._validation import finite_array, positive
from ..errors import InputError
from ..units import MAD_TO_SIGMA

__all__ = ["Static", "StaticDetection", "detect_statics", "long_run_ratio", "summarise_statics"]

_QUIET_PERCENTILE = 5.0
_QUIET_FACTOR = 3.0
_FALSE_MOTION = 1e-4
#: Smallest long-run over per-sample variance ratio taken (tremor's zero-mean swings average out in a pose).
LRV_FLOOR = 0.1


@dataclass(frozen=True)
class Static:
    """One still interval, reduced to what the fits need.

    Attributes
    ----------
    start, stop : int
        Sample indices, stop exclusive.
    t_start, t_stop : float
        Times of the first and last sample [s].
    accel_mean, gyro_mean : ndarray, shape (3,)
        Means [accelerometer and gyro internal units].
    accel_se, gyro_se : ndarray, shape (3,)
        Standard errors of those means, for correlated noise (long-run variance) [same units].
    accel_std, gyro_std : ndarray, shape (3,)
        Per-sample standard deviations inside the interval [same units].
    label : str
        Free text (a windows file's name, such as imucal's ``x_p``).
    """

    start: int
    stop: int
    t_start: float
    t_stop: float
    accel_mean: np.ndarray
    gyro_mean: np.ndarray
    accel_se: np.ndarray
    gyro_se: np.ndarray
    accel_std: np.ndarray
    gyro_std: np.ndarray
    label: str = ""

    @property
    def count(self) -> int:
        return self.stop - self.start

    @property
    def duration(self) -> float:
        """[s]."""
        return self.t_stop - self.t_start

    def to_dict(self) -> dict:
        """JSON-ready record (lists, internal units)."""
        return {"start": self.start, "stop": self.stop, "t_start": self.t_start, "t_stop": self.t_stop,
                "label": self.label, "accel_mean": self.accel_mean.tolist(), "gyro_mean": self.gyro_mean.tolist()}


@dataclass(frozen=True)
class StaticDetection:
    """What the detector measured and found.

    Attributes
    ----------
    statics : tuple of Static
    accel_noise, gyro_noise : ndarray, shape (3,)
        Per-sample noise standard deviations measured on the quiet windows [internal units].
    accel_threshold, gyro_threshold : float
        Thresholds on the window variance summed over axes in noise units (3 on average when still).
    window : int
        Moving-window length [samples].
    still : ndarray of bool, shape (N,)
        Samples whose centred window is still.
    multiplier : float
        Factor on both thresholds (variances) and on the band of the gyro's still level (its square root).
    sweep : tuple of (float, int, float)
        Multipliers tried, with the poses each found and the accelerometer fit's residual in noise
        units (Birge ratio; NaN where no fit) (:func:`~gyrocal.imu.sweep.sweep_statics`); empty when one was given.
    """

    statics: tuple[Static, ...]
    accel_noise: np.ndarray
    gyro_noise: np.ndarray
    accel_threshold: float
    gyro_threshold: float
    window: int
    still: np.ndarray
    multiplier: float = 1.0
    sweep: tuple = ()


def _moving(x: np.ndarray, w: int) -> tuple[np.ndarray, np.ndarray]:
    """Centred moving mean and variance (N, 3) over `w` samples (odd), edges repeating the nearest full window."""
    n, h = len(x), w // 2
    x = x - median(x[:: max(1, n // 10000)], axis=0)  # centring keeps the cumulative sums accurate
    c1 = np.concatenate([np.zeros((1, 3)), np.cumsum(x, axis=0)])
    c2 = np.concatenate([np.zeros((1, 3)), np.cumsum(x * x, axis=0)])
    s1, s2 = (c1[w:] - c1[:-w]) / w, (c2[w:] - c2[:-w]) / w
    mean, var = np.empty((n, 3)), np.empty((n, 3))
    mean[h:n - h], var[h:n - h] = s1, np.maximum(s2 - s1 * s1, 0.0) * w / (w - 1)
    for arr in (mean, var):
        arr[:h], arr[n - h:] = arr[h], arr[n - h - 1]
    return mean, var


def _variance_floor(x: np.ndarray) -> np.ndarray:
    """Smallest noise variance an axis can show (3,): its rounding, ``q^2 / 12``, or 1e-12 of its range squared.

    Quantised readings at rest can be constant for seconds; without a floor their variance is 0.
    """
    sub = x[:: max(1, len(x) // 100000)]
    step = np.abs(np.diff(sub, axis=0))
    quantum = np.array([np.min(s[s > 0]) if np.any(s > 0) else 0.0 for s in step.T])
    span = np.ptp(sub, axis=0)
    return np.maximum(quantum**2 / 12.0, (1e-6 * np.maximum(span, np.abs(sub).max(axis=0))) ** 2) + 1e-300


def _noise_and_threshold(var: np.ndarray, floor_var: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Per-axis noise variance, the normalised statistic (N,) and its threshold, from moving variances."""
    var = np.maximum(var, floor_var)
    total = var.sum(axis=1)
    floor = percentile(total, _QUIET_PERCENTILE)
    quiet = total <= _QUIET_FACTOR * floor
    noise = median(var[quiet], axis=0)
    stat = (var / noise).sum(axis=1)
    q = stat[quiet]
    med = float(median(q))
    spread = MAD_TO_SIGMA * float(median(np.abs(q - med))) / max(med, 1e-300)
    dof = float(np.clip(2.0 / max(spread, 1e-3) ** 2, 1.0, 1e6))
    threshold = med * float(stats.chi2.ppf(1.0 - _FALSE_MOTION, dof)) / dof
    return noise, stat, threshold


def _near_still_level(mean_g: np.ndarray, quiet: np.ndarray, band: float = 6.0) -> np.ndarray:
    """Windows whose mean gyro reading is within 6 robust deviations of the quiet windows' level.

    A slow steady turn has little variance but a mean rate. The quiet windows' spread holds the
    noise of a window mean and the bias drift between poses, so neither is taken for motion.
    """
    if quiet.sum() < 3:
        return quiet
    q = mean_g[quiet]
    level = median(q, axis=0)
    spread = MAD_TO_SIGMA * median(np.abs(q - level), axis=0)
    spread = np.maximum(spread, 1e-9 * max(float(np.abs(q).max()), np.finfo(float).tiny))
    return np.all(np.abs(mean_g - level) <= band * spread, axis=1)


def long_run_ratio(x: np.ndarray, segments, lags: int) -> np.ndarray:
    """Long-run over per-sample variance of each column of `x` (3,), pooled over `segments`.

    Bartlett-weighted autocovariances (Newey and West) up to `lags`, summed over the still
    segments after removing each segment's mean; 1 for white noise, more for low-pass filtered
    noise, less (down to :data:`LRV_FLOOR`) for oscillations such as a hand's tremor. The standard error of a segment mean is ``std * sqrt(ratio / n)``.
    """
    g = np.zeros((lags + 1, 3))
    for a, b in segments:
        d = x[a:b] - x[a:b].mean(axis=0)
        for k in range(min(lags, b - a - 1) + 1):
            g[k] += np.einsum("ij,ij->j", d[: b - a - k], d[k:])
    if not g[0].all():
        return np.ones(3)
    w = 1.0 - np.arange(lags + 1) / (lags + 1.0)
    lrv = g[0] + 2.0 * (w[1:, None] * g[1:]).sum(axis=0)
    # below 1 where the noise averages out faster than white noise (a hand's tremor, a periodic ripple)
    return np.clip(lrv / g[0], LRV_FLOOR, None)


def summarise_statics(t, gyro, accel, spans, labels=None, *, lags: int | None = None) -> tuple[Static, ...]:
    """Reduce still spans ``[(start, stop), ...]`` of a session to :class:`Static` records.

    The standard errors of the means use one long-run variance ratio per sensor and axis,
    pooled over all spans (:func:`long_run_ratio`), so short statics get a stable figure.
    """
    spans = [(int(a), int(b)) for a, b in spans]
    if any(b - a < 2 for a, b in spans):
        raise InputError("every still interval needs at least 2 samples")
    labels = list(labels) if labels is not None else [""] * len(spans)
    fs = (len(t) - 1) / (t[-1] - t[0])
    lags = lags if lags is not None else max(2, int(round(0.1 * fs)))
    ratio_a, ratio_g = long_run_ratio(accel, spans, lags), long_run_ratio(gyro, spans, lags)
    out = []
    for (a, b), label in zip(spans, labels):
        sa, sg = accel[a:b].std(axis=0, ddof=1), gyro[a:b].std(axis=0, ddof=1)
        n = b - a
        out.append(Static(
            start=a, stop=b, t_start=float(t[a]), t_stop=float(t[b - 1]),
            accel_mean=accel[a:b].mean(axis=0), gyro_mean=gyro[a:b].mean(axis=0),
            accel_se=sa * np.sqrt(ratio_a / n), gyro_se=sg * np.sqrt(ratio_g / n),
            accel_std=sa, gyro_std=sg, label=str(label)))
    return tuple(out)


def detect_statics(t, gyro, accel, *, window_s: float = 0.5, min_duration: float = 1.0, breaks=(),
                   multiplier: float = 1.0) -> StaticDetection:
    """Find the still intervals of a session from its accelerometer and gyro.

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s], increasing.
    gyro, accel : array_like, shape (N, 3)
        Readings [any units; the thresholds are measured in the data's own units].
    window_s : float
        Moving-window length [s].
    min_duration : float
        Shortest still interval kept [s].
    breaks : sequence of int
        Samples that start a new part of a log that is not contiguous: no interval spans one.
    multiplier : float
        Factor on the thresholds measured at rest: a hand's tremor needs more than a table's rest.

    Returns
    -------
    StaticDetection
    """
    t = finite_array("t", t, ndim=1)
    gyro = finite_array("gyro", gyro, shape_tail=(3,), ndim=2)
    accel = finite_array("accel", accel, shape_tail=(3,), ndim=2)
    if not (len(t) == len(gyro) == len(accel)):
        raise InputError(f"t, gyro and accel must have one row per sample, got {len(t)}, {len(gyro)}, {len(accel)}")
    fs = (len(t) - 1) / (t[-1] - t[0]) if len(t) > 1 else 0.0
    w = max(5, int(round(positive("window_s", window_s) * fs)) | 1)
    if len(t) < 4 * w:
        raise InputError(f"the session has {len(t)} samples; detecting still poses needs at least {4 * w}")
    mean_a, var_a = _moving(accel, w)
    mean_g, var_g = _moving(gyro, w)
    noise_a, stat_a, thr_a = _noise_and_threshold(var_a, _variance_floor(accel))
    noise_g, stat_g, thr_g = _noise_and_threshold(var_g, _variance_floor(gyro))
    m = positive("multiplier", multiplier)
    thr_a, thr_g = thr_a * m, thr_g * m
    quiet = (stat_a <= thr_a) & (stat_g <= thr_g)
    still = quiet & _near_still_level(mean_g, (stat_a <= thr_a / m) & (stat_g <= thr_g / m), 6.0 * np.sqrt(m))
    for b in breaks:  # a window straddling a break is never still
        still[max(0, int(b) - w // 2):int(b) + w // 2] = False
    edges = np.flatnonzero(np.diff(np.concatenate(([0], still.view(np.int8), [0]))))
    spans = [(a, b) for a, b in edges.reshape(-1, 2) if t[b - 1] - t[a] >= min_duration]
    statics = summarise_statics(t, gyro, accel, spans) if spans else ()
    return StaticDetection(statics, np.sqrt(noise_a), np.sqrt(noise_g), thr_a, thr_g, w, still, m)
