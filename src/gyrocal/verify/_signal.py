"""The few signal-processing steps alignment needs, in numpy: ``scipy.signal`` costs more to import than they run.

Each reproduces the ``scipy.signal`` call it replaces for the arguments used here (tests/test_verify_signal.py
compares them over random and edge cases):

* :func:`correlate` is ``correlate(a, b, mode, method="fft")`` for real 1-D arrays, a zero-padded real FFT;
  :func:`correlation_lags` its lags;
* :func:`find_peaks` is ``find_peaks(x, height=h, distance=d)[0]``: local maxima (the middle of a flat top),
  then the height threshold, then the minimum distance, keeping the higher peak first;
* :func:`savgol_slope` is ``savgol_filter(x, n, 2, deriv=1, delta=dt, axis=0, mode="interp")`` for odd `n`.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["correlate", "correlation_lags", "find_peaks", "savgol_slope"]


def _fast_length(n: int) -> int:
    """Smallest ``2^i 3^j 5^k >= n``: a length the FFT splits into small factors."""
    best = 1 << max(0, (n - 1).bit_length())  # the power of two
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            size = p35
            while size < n:
                size *= 2
            best = min(best, size)
            p35 *= 3
        p5 *= 5
    return best


def correlate(a: np.ndarray, b: np.ndarray, mode: str = "full") -> np.ndarray:
    """Cross-correlation ``c[k] = sum_n a[n + k] b[n]`` of real 1-D arrays by FFT.

    ``mode="full"``: every overlap, lags ``-(len(b) - 1) .. len(a) - 1`` (:func:`correlation_lags`);
    ``mode="valid"``: only lags where `b` lies wholly inside `a` (``len(a) >= len(b)``), ``0 .. len(a) - len(b)``.
    """
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    n_full = len(a) + len(b) - 1
    size = _fast_length(n_full)
    full = np.fft.irfft(np.fft.rfft(a, size) * np.fft.rfft(b[::-1], size), size)[:n_full]
    if mode == "full":
        return full
    if mode == "valid":
        if len(a) < len(b):
            raise ValueError("mode 'valid' needs len(a) >= len(b)")
        return full[len(b) - 1:len(a)]
    raise ValueError(f"unknown mode {mode!r}")


def correlation_lags(n_a: int, n_b: int) -> np.ndarray:
    """Lags of the samples of ``correlate(a, b, "full")`` for arrays of lengths `n_a` and `n_b`."""
    return np.arange(-n_b + 1, n_a)


def _local_maxima(x: np.ndarray) -> np.ndarray:
    """Indices of local maxima: samples above both neighbours, or the middle (rounded down) of a flat top.

    A top that touches either end of `x` is no maximum.
    """
    if len(x) < 3:
        return np.zeros(0, dtype=np.intp)
    starts = np.concatenate([[0], np.flatnonzero(x[1:] != x[:-1]) + 1])  # runs of equal values
    ends = np.concatenate([starts[1:] - 1, [len(x) - 1]])
    v = x[starts]
    top = np.flatnonzero((v[1:-1] > v[:-2]) & (v[1:-1] > v[2:])) + 1
    return (starts[top] + ends[top]) // 2


def find_peaks(x: np.ndarray, height: float, distance: int) -> np.ndarray:
    """Indices, increasing, of the local maxima of `x` at least `height` high and `distance` samples apart.

    Where two are closer than `distance`, the higher one stays (scipy's order of ties: ``np.argsort``).
    """
    x = np.asarray(x, dtype=float)
    if distance < 1:
        raise ValueError("distance must be at least 1")
    peaks = _local_maxima(x)
    peaks = peaks[x[peaks] >= height]
    keep = np.ones(len(peaks), dtype=bool)
    gap = math.ceil(distance)
    for j in np.argsort(x[peaks])[::-1]:
        if not keep[j]:
            continue
        lo = np.searchsorted(peaks, peaks[j] - gap, side="right")
        hi = np.searchsorted(peaks, peaks[j] + gap, side="left")
        keep[lo:j] = False
        keep[j + 1:hi] = False
    return peaks[keep]


def _edge_weights(n: int, rows: np.ndarray) -> np.ndarray:
    """Weights (len(rows), n) giving the slope, at positions `rows`, of the quadratic least-squares fit to `n` samples."""
    pos = np.arange(n, dtype=float)
    vander = pos[:, None] ** np.arange(3)
    rows = np.asarray(rows, dtype=float)
    derivative = np.stack([np.zeros(len(rows)), np.ones(len(rows)), 2.0 * rows], axis=1)
    return derivative @ np.linalg.pinv(vander)


def savgol_slope(x: np.ndarray, n: int, delta: float) -> np.ndarray:
    """Savitzky-Golay first derivative (quadratic, `n` samples, odd) along axis 0 of `x`, per unit of `delta`.

    Inside, the slope of the quadratic fit centred on each sample, ``sum_k k x[i + k] / (delta sum_k k^2)``
    for ``k = -(n // 2) .. n // 2``; within ``n // 2`` samples of an end, the slope of one quadratic fitted to
    the first (last) `n` samples, as scipy's ``mode="interp"``.
    """
    x = np.asarray(x, dtype=float)
    if n % 2 == 0 or n < 3 or n > len(x):
        raise ValueError("the window must be odd, at least 3 and at most the length of x")
    m = n // 2
    norm = delta * m * (m + 1) * (2 * m + 1) / 3.0
    y = np.empty_like(x)
    inner = np.zeros_like(x[m:len(x) - m])
    for k in range(1, m + 1):
        inner += k * (x[m + k:len(x) - m + k] - x[m - k:len(x) - m - k])
    y[m:len(x) - m] = inner / norm
    y[:m] = np.tensordot(_edge_weights(n, np.arange(m)), x[:n], axes=1) / delta
    y[len(x) - m:] = np.tensordot(_edge_weights(n, np.arange(n - m, n)), x[len(x) - n:], axes=1) / delta
    return y
