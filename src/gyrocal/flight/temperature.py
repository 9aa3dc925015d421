"""The sensor temperature's course in time, from readings that may come in whole degrees.

Many IMUs report temperature in coarse steps (1 degC, 0.5 degC). Block means of such
readings are a staircase: off by up to half a step for minutes while the board warms
slowly, and a bias slope turns that into a bias error. Smoothing in time cannot remove a
step that lasts longer than the filter. But the instant a reading moves from one level to
the next is the instant the true temperature crossed the midpoint between them, so the
course is known there. The crossings are found on median-filtered half-second blocks, then
each one's time is counted from the raw readings around it to a fraction of a sample
(:func:`_refine`: a steep offset turns the blocks' time error, a good part of a block, into
an error of its curve larger than the noise's); gyrocal interpolates between the crossings
with a monotone cubic (PCHIP). Outside the first and last crossing the
temperature is only known to within half a step, so those samples are marked invalid.
Fine-grained readings are only lightly averaged (a zero-phase filter of 2 s).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import distinct, median
from ..errors import InputError
from ..thermal import smooth_temperature

__all__ = ["TemperatureCourse", "temperature_course"]

#: Readings taking fewer distinct values than one per this many samples count as quantised.
_SAMPLES_PER_LEVEL = 50
#: A crossing's window reaches this many crossings either way (readings past the midpoint counted in it).
_REACH = 2


@dataclass(frozen=True)
class TemperatureCourse:
    """Estimated true temperature per sample.

    Attributes
    ----------
    temp : ndarray, shape (N,)
        Temperature [degC] (NaN where not valid).
    valid : ndarray of bool, shape (N,)
        Where `temp` is known to better than half a reading step.
    quantum : float or None
        Step of the readings [degC] when they are quantised.
    method : str
        How the course was made, for the record.
    """

    temp: np.ndarray
    valid: np.ndarray
    quantum: float | None
    method: str


def _quantum(readings: np.ndarray) -> float | None:
    levels = distinct(readings)
    if len(levels) < 2 or len(levels) > len(readings) / _SAMPLES_PER_LEVEL:
        return None
    q = float(np.min(np.diff(levels)))
    on_grid = np.abs((levels - levels[0]) / q - np.round((levels - levels[0]) / q)) < 1e-3
    return q if on_grid.all() else None


def _crossings(level: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times (block index), temperatures and directions (+1 up, -1 down, 0 a touch) of the level changes.

    Back-and-forth across one midpoint is one crossing, at the mean time; its direction is the net
    change (0 where the level comes back to where it was).
    """
    idx = np.flatnonzero(np.diff(level) != 0)
    mid = 0.5 * (level[idx] + level[idx + 1])
    times, temps, signs = [], [], []
    i = 0
    while i < len(idx):
        j = i
        while j + 1 < len(idx) and mid[j + 1] == mid[i]:
            j += 1
        times.append(0.5 * (idx[i] + idx[j]) + 0.5)
        temps.append(mid[i])
        signs.append(np.sign(level[idx[j] + 1] - level[idx[i]]))
        i = j + 1
    return np.array(times), np.array(temps), np.array(signs)


def _refine(r: np.ndarray, times: np.ndarray, temps: np.ndarray, signs: np.ndarray, q: float) -> np.ndarray:
    """Crossing times (sample index) to a fraction of a sample, from the raw readings around each.

    A reading rounds to a level above the midpoint ``m`` exactly when the true temperature plus the
    reading noise exceeds ``m``, so the probability of a reading past ``m`` is the noise's CDF at
    ``T(t) - m``. Over a window ``[a, b)`` that starts well before the crossing and ends well after,
    the count of readings past ``m`` is then ``b - t_c`` in expectation (exactly where ``T`` is
    straight and the noise symmetric), whatever the noise: ``t_c = b - count - 1/2`` for samples at
    integer times. Each window reaches `_REACH` crossings (that many steps) either way, so the
    reading noise's tails at its ends are a step or more from ``m`` (:func:`_window`). The block medians'
    crossing times err by a good part of a block (their 0.5 s resolution and the running median's
    response to chatter), which a steep offset turns into an error of the fitted curve.
    """
    n = len(r)
    out = times.astype(float)
    for k in np.flatnonzero(signs != 0):
        window = _window(times, temps, signs, q, k)
        if window is None:
            continue
        a, b = (int(np.clip(round(e), 0, n)) for e in window)
        past = np.count_nonzero(signs[k] * (r[a:b] - temps[k]) > 0)
        out[k] = min(max(b - past - 0.5, a), b)
    return out


def _window(times, temps, signs, q: float, k: int) -> tuple[float, float] | None:
    """Start and end (sample index) of crossing `k`'s window, out to `_REACH` crossings either way.

    Only as far as the course runs one way, a step of `q` per crossing (a re-crossing of
    ``temps[k]`` must stay out); a window with no crossing on one side reaches as far there as on
    the other. None where neither side has one: that crossing keeps the block medians' time.
    """
    def steady(j: int) -> bool:
        return signs[j] == signs[k] and abs(temps[j] - temps[k] - signs[k] * (j - k) * q) < 1e-6 * q

    lo = k
    while lo > max(k - _REACH, 0) and steady(lo - 1):
        lo -= 1
    hi = k
    while hi < min(k + _REACH, len(times) - 1) and steady(hi + 1):
        hi += 1
    if lo == hi:
        return None
    reach = max(times[k] - times[lo], times[hi] - times[k])
    return (times[lo] if lo < k else times[k] - reach), (times[hi] if hi > k else times[k] + reach)


def temperature_course(readings, sample_rate: float, *, median_s: float = 5.0) -> TemperatureCourse:
    """The true temperature course behind temperature `readings` [degC] at `sample_rate` [Hz].

    Parameters
    ----------
    readings : array_like, shape (N,)
        Temperature readings [degC].
    sample_rate : float
        Sampling rate [Hz].
    median_s : float
        Running-median width [s] that removes reading chatter before crossings are found.
    """
    from scipy.interpolate import PchipInterpolator
    from scipy.ndimage import median_filter

    r = np.asarray(readings, dtype=float)
    q = _quantum(r)
    if q is None:
        return TemperatureCourse(smooth_temperature(r, sample_rate, 2.0), np.ones(len(r), bool), None,
                                 "fine readings: zero-phase smoothing, 2 s")
    # median per half-second block, then a running median over blocks: chatter gone, 0.5 s resolution
    size = max(1, int(round(0.5 * sample_rate)))
    nb = len(r) // size
    blocks = median(r[: nb * size].reshape(nb, size), axis=1) if nb else r[:1]
    blocks = r.min() + np.round((blocks - r.min()) / q) * q  # an even count's median may fall between levels
    level = median_filter(blocks, size=max(3, int(round(median_s / 0.5))) | 1, mode="nearest")
    times, temps, signs = _crossings(level)
    if len(times) < 2:
        raise InputError(f"the temperature readings (steps of {q:g} degC) change level fewer than twice; the log "
                         "does not warm enough to fit a bias against temperature")
    times = _refine(r, times * size, temps, signs, q)  # block boundaries in samples, then sub-sample
    n = np.arange(len(r))
    valid = (n >= times[0]) & (n <= times[-1])
    temp = np.full(len(r), np.nan)
    temp[valid] = PchipInterpolator(times, temps)(n[valid])
    return TemperatureCourse(temp, valid, q, f"readings in steps of {q:g} degC: interpolated (PCHIP) through the "
                                             "level crossings of the median-filtered readings")
