"""Moments of many windows of a recording, all at once.

A calibration reduces hundreds to thousands of windows (turns, plateaus, standstills) to their
means, mean squares and white-noise variances. Window by window, every reduction pays numpy's
call overhead and a copy of the window; here the windows of one stretch of the recording are
reduced together, by ``np.add.reduceat`` over their boundaries, a bounded stretch at a time.
The results are those of :func:`gyrocal.observations.observe` up to rounding (the sums run in
another order); ``tests/test_moments.py`` compares them with the window-by-window reduction.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._arrays import distinct
from ..errors import InputError

__all__ = ["Moments", "window_moments"]

#: Samples reduced together: temporaries of a few MB, whatever the recording's length.
_STRETCH = 1 << 17


class Moments(NamedTuple):
    """Per-window reductions, one row per window.

    Attributes
    ----------
    mean : ndarray, shape (W, 3)
        Mean of the readings, weighted by the time each sample stands for when times are given
        [reading units].
    mean_sq : ndarray, shape (W, 3)
        Mean of the squared readings, weighted alike [reading units^2].
    noise_var : ndarray, shape (W, 3)
        Half the mean squared first difference: the per-sample white-noise variance [reading units^2].
    duration : ndarray, shape (W,)
        Time spanned [s] (the sum of the weights); the sample count when no times are given.
    """

    mean: np.ndarray
    mean_sq: np.ndarray
    noise_var: np.ndarray
    duration: np.ndarray


def _weights(t: np.ndarray, first: np.ndarray, last: np.ndarray) -> np.ndarray:
    """Trapezoid weights [s]: half of each neighbouring step, the whole step at each window's ends."""
    step = t[1:] - t[:-1]
    if len(step) and not step.min() > 0:
        raise InputError("t must increase strictly inside a window")
    w = np.empty(len(t))
    np.add(step[:-1], step[1:], out=w[1:-1])
    w[1:-1] /= 2
    w[first] = step[first]
    w[last] = step[last - 1]
    return w


def _stretch(x: np.ndarray, t: np.ndarray | None, starts: np.ndarray, stops: np.ndarray) -> Moments:
    """Moments of windows ``starts[i]:stops[i]`` (sorted, disjoint, relative to `x`, the last ending at ``len(x)``).

    Axis by axis: each pass then runs over one contiguous column, whatever the layout of `x`.
    """
    bounds = np.stack([starts, stops], axis=1).ravel()[:-1]  # the last window runs to the end
    diff_bounds = np.stack([starts, stops - 1], axis=1).ravel()[:-1]  # first differences starts .. stops - 2
    count = (stops - starts).astype(float)
    w = None if t is None else _weights(t, starts, stops - 1)
    duration = count if w is None else np.add.reduceat(w, bounds)[::2]
    total, total_sq, noise = (np.empty((len(starts), x.shape[1])) for _ in range(3))
    columns = np.ascontiguousarray(x.T)  # no copy for column-major readings (as read); one pass for others
    for j, c in enumerate(columns):
        square = c * c
        if w is not None:
            square *= w
        total[:, j] = np.add.reduceat(c if w is None else c * w, bounds)[::2]
        total_sq[:, j] = np.add.reduceat(square, bounds)[::2]
        d = c[1:] - c[:-1]
        d *= d
        noise[:, j] = np.add.reduceat(d, diff_bounds)[::2]
    return Moments(total / duration[:, None], total_sq / duration[:, None], noise / (count - 1)[:, None] / 2.0,
                   duration)


def window_moments(x: np.ndarray, starts, stops, t: np.ndarray | None = None) -> Moments:
    """Mean, mean of squares, white-noise variance and duration of windows ``starts[i]:stops[i]`` of `x`.

    Parameters
    ----------
    x : ndarray, shape (N, 3)
        Readings [reading units], finite (a :class:`~gyrocal.recording.Recording`'s are).
    starts, stops : array_like of int, shape (W,)
        Window bounds (stop exclusive), each window at least 2 samples. Windows that are sorted and
        do not overlap are reduced a stretch at a time; others one by one.
    t : ndarray, shape (N,), optional
        Sample times [s], strictly increasing inside each window: means are then weighted by the
        time each sample stands for (trapezoid weights) and the duration is the time spanned.

    Returns
    -------
    Moments
    """
    starts, stops = np.asarray(starts, dtype=np.int64), np.asarray(stops, dtype=np.int64)
    if len(starts) == 0:
        empty = np.empty((0, 3))
        return Moments(empty, empty, empty, np.empty(0))
    if np.any(stops - starts < 2):
        raise InputError("a window needs at least 2 samples")
    if len(starts) > 1 and np.any(starts[1:] < stops[:-1]):  # overlapping or unsorted: one at a time
        parts = [window_moments(x, starts[i:i + 1], stops[i:i + 1], t) for i in range(len(starts))]
        return Moments(*(np.concatenate(p) for p in zip(*parts)))
    # group consecutive windows into stretches of at most _STRETCH samples (a longer window is its own)
    group = np.zeros(len(starts), dtype=np.int64)
    first = 0
    for i in range(1, len(starts)):
        if stops[i] - starts[first] > _STRETCH:
            first = i
        group[i] = first
    parts = []
    for first in distinct(group):
        sel = np.flatnonzero(group == first)
        a, b = int(starts[sel[0]]), int(stops[sel[-1]])
        parts.append(_stretch(x[a:b], None if t is None else t[a:b], starts[sel] - a, stops[sel] - a))
    return Moments(*(np.concatenate(p) for p in zip(*parts)))
