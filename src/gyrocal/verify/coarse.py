"""Coarse time alignment of two logs from their rate magnitudes.

The magnitude ``|w|`` of the angular rate is the same in every frame, so the two logs can
be compared before the mounting rotation between the sensors is known. Both magnitudes are
resampled onto grids of one rate; their normalised cross-correlation peaks at the clock
offset. Over long logs a clock drift smears that peak, so the offset is also found
segment by segment and a straight line through the segment offsets gives the drift.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._signal import correlate, correlation_lags, find_peaks

__all__ = ["CoarseAlignment", "coarse_offsets", "grid_rate_for", "magnitude_grid", "segment_drift"]

#: Highest grid rate of the coarse search [Hz]; the least-squares refinement does the rest.
MAX_GRID_RATE = 100.0
#: Peaks of the magnitude correlation closer than this are one peak [s].
PEAK_SEPARATION_S = 1.0
#: Largest clock drift the segment search looks for [ppm].
MAX_DRIFT_PPM = 2000.0


@dataclass(frozen=True)
class CoarseAlignment:
    """Candidate clock offsets from the magnitude cross-correlation.

    Attributes
    ----------
    offsets : ndarray, shape (n,)
        Candidate offsets ``t_test - t_ref`` [s], highest correlation first.
    peaks : ndarray, shape (n,)
        Normalised correlation of each candidate (1 = identical magnitude profiles).
    grid_rate : float
        Rate of the common grid [Hz].
    """

    offsets: np.ndarray
    peaks: np.ndarray
    grid_rate: float


def grid_rate_for(rate_test: float, rate_ref: float) -> float:
    """Rate of the common grid [Hz]: the slower log's rate, at most :data:`MAX_GRID_RATE`."""
    return float(min(rate_test, rate_ref, MAX_GRID_RATE))


def magnitude_grid(t: np.ndarray, w: np.ndarray, rate: float) -> np.ndarray:
    """``|w|`` linearly interpolated onto ``t[0] + k / rate`` over the log's span."""
    n = math.floor((t[-1] - t[0]) * rate) + 1
    grid = t[0] + np.arange(n) / rate
    return np.interp(grid, t, np.sqrt(np.einsum("ij,ij->i", w, w)))


def _normalised(x: np.ndarray) -> np.ndarray:
    x = x - x.mean()
    norm = math.sqrt(float(x @ x))
    return x / norm if norm > 0 else x


def _parabolic(y: np.ndarray, k: int) -> float:
    """Sub-sample position of the peak of `y` at index `k` (a parabola through three points)."""
    if k <= 0 or k >= len(y) - 1:
        return float(k)
    den = y[k - 1] - 2.0 * y[k] + y[k + 1]
    return float(k) if den >= 0 else k + 0.5 * float(y[k - 1] - y[k + 1]) / float(den)


def coarse_offsets(t_test, w_test, t_ref, w_ref, rate: float, max_candidates: int = 5) -> CoarseAlignment:
    """Offsets ``t_test - t_ref`` [s] where the rate magnitudes of both logs correlate best.

    Parameters
    ----------
    t_test, t_ref : ndarray, shape (N,), (M,)
        Sample times of each log on its own clock [s].
    w_test, w_ref : ndarray, shape (N, 3), (M, 3)
        Angular rates [rad/s], each in its own frame.
    rate : float
        Grid rate [Hz] (:func:`grid_rate_for`).
    max_candidates : int
        Most peaks returned; peaks under half the highest are dropped.
    """
    a = _normalised(magnitude_grid(t_test, w_test, rate))
    b = _normalised(magnitude_grid(t_ref, w_ref, rate))
    rho = correlate(a, b, "full")
    lags = correlation_lags(len(a), len(b))
    top = float(rho.max())
    found = find_peaks(rho, 0.5 * top, max(1, int(PEAK_SEPARATION_S * rate)))
    if len(found) == 0:  # the maximum sits on an end of the lag range
        found = np.array([int(np.argmax(rho))])
    found = found[np.argsort(rho[found])[::-1]][:max_candidates]
    frac = np.array([_parabolic(rho, int(k)) - k for k in found])
    offsets = t_test[0] - t_ref[0] + (lags[found] + frac) / rate
    return CoarseAlignment(offsets=offsets, peaks=rho[found], grid_rate=rate)


def _window_norms(y: np.ndarray, n: int) -> np.ndarray:
    """Root of the centred sum of squares of every window of `n` consecutive values of `y`."""
    c1 = np.concatenate([[0.0], np.cumsum(y)])
    c2 = np.concatenate([[0.0], np.cumsum(y * y)])
    s1, s2 = c1[n:] - c1[:-n], c2[n:] - c2[:-n]
    return np.sqrt(np.maximum(s2 - s1 * s1 / n, 0.0))


def segment_drift(t_test, w_test, t_ref, w_ref, offset: float, rate: float,
                  segment_s: float = 60.0, min_peak: float = 0.5) -> tuple[float, float, float] | None:
    """Local offsets ``t_test - t_ref`` along the test log, fitted by a straight line.

    The test log is cut into segments of at least `segment_s` seconds (at most 50 of
    them); each is matched against the reference within the lag a drift of
    :data:`MAX_DRIFT_PPM` could cause. Segments without a clear match (static stretches)
    are skipped. Returns ``(t0, offset_at_t0, slope)`` with ``t0`` the test log's first
    time [s] and the slope of the local offset against test time [s/s], or None when
    fewer than three segments match (a short log keeps the plain offset).
    """
    a = magnitude_grid(t_test, w_test, rate)
    b = magnitude_grid(t_ref, w_ref, rate)
    seg = max(int(segment_s * rate), len(a) // 50)
    reach = math.ceil(MAX_DRIFT_PPM * 1e-6 * (t_test[-1] - t_test[0]) * rate) + 2
    times, offs, weights = [], [], []
    for start in range(0, len(a) - seg + 1, seg):
        x = a[start:start + seg] - a[start:start + seg].mean()
        # grid index in b of the segment's first sample under the plain offset, less the reach
        j0 = round(start + (t_test[0] - t_ref[0] - offset) * rate) - reach
        if j0 < 0 or j0 + seg + 2 * reach > len(b) or not x.any():
            continue
        y = b[j0:j0 + seg + 2 * reach]
        c = correlate(y, x, "valid")
        rho = c / np.maximum(_window_norms(y, seg) * math.sqrt(float(x @ x)), np.finfo(float).tiny)
        k = int(np.argmax(rho))
        if rho[k] < min_peak:
            continue
        lag = j0 + _parabolic(rho, k) - start  # index in b minus index in a
        times.append((start + seg / 2) / rate)
        offs.append(t_test[0] - t_ref[0] - lag / rate)
        weights.append(float(x @ x))
    if len(times) < 3:
        return None
    slope, intercept = np.polyfit(times, offs, 1, w=np.sqrt(weights))
    return float(t_test[0]), float(intercept), float(slope)
