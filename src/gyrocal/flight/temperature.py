"""The sensor temperature's course in time, from readings that may come in whole degrees.

Many IMUs report temperature in coarse steps (1 degC, 0.5 degC). Block means of such
readings are a staircase: off by up to half a step for minutes while the board warms
slowly, and a bias slope turns that into a bias error. Smoothing in time cannot remove a
step that lasts longer than the filter. But the instant a (median-filtered) reading moves
from one level to the next is the instant the true temperature crossed the midpoint
between them, so the course is known exactly there; gyrocal interpolates between those
crossings with a monotone cubic (PCHIP). Outside the first and last crossing the
temperature is only known to within half a step, so those samples are marked invalid.
Fine-grained readings are only lightly averaged (a zero-phase filter of 2 s).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..thermal import smooth_temperature

__all__ = ["TemperatureCourse", "temperature_course"]

#: Readings taking fewer distinct values than one per this many samples count as quantised.
_SAMPLES_PER_LEVEL = 50


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
    levels = np.unique(readings)
    if len(levels) < 2 or len(levels) > len(readings) / _SAMPLES_PER_LEVEL:
        return None
    q = float(np.min(np.diff(levels)))
    on_grid = np.abs((levels - levels[0]) / q - np.round((levels - levels[0]) / q)) < 1e-3
    return q if on_grid.all() else None


def _crossings(level: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Times (sample index) and temperatures of the level changes, chatter merged."""
    idx = np.flatnonzero(np.diff(level) != 0)
    mid = 0.5 * (level[idx] + level[idx + 1])
    times, temps = [], []
    i = 0
    while i < len(idx):  # back-and-forth across one midpoint is one crossing, at the mean time
        j = i
        while j + 1 < len(idx) and mid[j + 1] == mid[i]:
            j += 1
        times.append(0.5 * (idx[i] + idx[j]) + 0.5)
        temps.append(mid[i])
        i = j + 1
    return np.array(times), np.array(temps)


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
    blocks = np.median(r[: nb * size].reshape(nb, size), axis=1) if nb else r[:1]
    blocks = r.min() + np.round((blocks - r.min()) / q) * q  # an even count's median may fall between levels
    level = median_filter(blocks, size=max(3, int(round(median_s / 0.5))) | 1, mode="nearest")
    times, temps = _crossings(level)
    times = times * size  # block boundaries in samples
    if len(times) < 2:
        raise InputError(f"the temperature readings (steps of {q:g} degC) change level fewer than twice; the log "
                         "does not warm enough to fit a bias against temperature")
    n = np.arange(len(r))
    valid = (n >= times[0]) & (n <= times[-1])
    temp = np.full(len(r), np.nan)
    temp[valid] = PchipInterpolator(times, temps)(n[valid])
    return TemperatureCourse(temp, valid, q, f"readings in steps of {q:g} degC: interpolated (PCHIP) through the "
                                             "level crossings of the median-filtered readings")
