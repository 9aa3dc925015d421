"""Plain re-implementations of the numerical pieces that ``tests/naive_selfcheck.py`` builds on.

Written from the documented behaviour of gyrocal.observations.longrun, gyrocal.recording.timebase and gyrocal.recording.timegaps (their
docstrings are the specification), not from their code, and sharing no function with them: medians and
quantiles by sorting, least squares on designs built column by column, a line fit by centred normal
equations, the periodogram's taper, padding and bins spelled out. They are meant to be obviously right rather than fast
(yet fast enough for the benches' naive baseline on long logs), so that a slip in the library (a
constant, a window one sample off, a term dropped) shows as a difference.
The library's documented constants are restated below as literals: importing them would hide a change.
"""

from __future__ import annotations

import math

import numpy as np

# -- documented constants, restated (an import would follow a mutation of them) --
BLOCK_STEPS = 64  # gyrocal.recording.timebase._BLOCK: steps per block of the nominal period's median
ENVELOPE = 50  # gyrocal.recording.timebase._ENVELOPE: samples per block of the lower envelope, at least
ENVELOPE_S = 0.5  # gyrocal.recording.timebase._ENVELOPE_S [s]: and at least this long
LATE_EXTRA = 2.0  # gyrocal.recording.timebase._LATE_EXTRA: a late delivery exceeds the packet step by this many periods
LATE_HOLD = 0.01  # gyrocal.recording.timebase._LATE_HOLD [s]: ... and by this long
CANDIDATE_STEP = 1.5  # gyrocal.recording.timegaps.CANDIDATE_STEP: shorter steps (in periods) cannot hide a lost sample
LATE_STEP = 3.0  # gyrocal.recording.timegaps.LATE_STEP: a step this many periods long that lost nothing is late
MIN_SPAN = 8  # gyrocal.observations.longrun._MIN_SPAN: shortest span of the span-variance fit [samples]


def median(values) -> float:
    """The middle value of the sorted values (the mean of the middle two for an even count)."""
    s = np.sort(np.asarray(values, dtype=float))
    mid = len(s) // 2
    return float(s[mid]) if len(s) % 2 else float((s[mid - 1] + s[mid]) / 2)


# -- the time base --

def nominal_period(t: np.ndarray) -> float:
    """Median of the mean step of consecutive blocks of 64 steps (fewer on short logs: an eighth of
    them, at least one); the mean step when the log holds fewer than two blocks."""
    steps = len(t) - 1
    block = min(BLOCK_STEPS, max(1, steps // 8))
    if steps < 2 * block:
        return float(t[-1] - t[0]) / steps
    means = [(float(t[j + block]) - float(t[j])) / block for j in range(0, steps - block + 1, block)]
    return median(means)


def block_size(period: float, n: int) -> int:
    """Samples per block of the lower envelope: 50 and at least half a second, never more than the log."""
    return int(min(n, max(ENVELOPE, round(ENVELOPE_S / period))))


def least_delayed(x) -> float:
    """The tenth quantile of `x`: the value with a tenth of the others below it (sorted, index n // 10)."""
    return float(np.sort(x)[len(x) // 10])


def fit_clock(t0: float, period: float, floor, k) -> tuple[float, float] | None:
    """Least-squares line through the envelope points ``(k, floor)`` (centred normal equations); the clock
    ``(t0 + intercept, period + slope)``, or None when the points' residuals span half a period or more."""
    if len(floor) < 2:
        return t0, period
    k, floor = [float(v) for v in k], [float(v) for v in floor]
    kbar, fbar = math.fsum(k) / len(k), math.fsum(floor) / len(floor)
    slope = (math.fsum((a - kbar) * (b - fbar) for a, b in zip(k, floor))
             / math.fsum((a - kbar) ** 2 for a in k))
    icept = fbar - slope * kbar
    resid = [b - (icept + slope * a) for a, b in zip(k, floor)]
    if max(resid) - min(resid) >= 0.5 * period:
        return None
    return t0 + icept, period + slope


# -- plateau fits and long-run variances --

def block_means(x: np.ndarray, d: int) -> np.ndarray:
    """Mean of each whole block of `d` rows (the rows laid out as blocks x d); a short tail is dropped."""
    if d <= 1:
        return x
    m = len(x) // d
    return x[: m * d].reshape(m, d, *x.shape[1:]).mean(axis=1)


def design(t: np.ndarray, lines) -> np.ndarray:
    """Columns: a constant, then for each line f the cosine and the sine of 2 pi f t."""
    columns = [np.ones(len(t))]
    for f in lines:
        columns += [np.cos(2 * np.pi * f * t), np.sin(2 * np.pi * f * t)]
    return np.column_stack(columns)


def periodogram(y: np.ndarray, pad: int = 4) -> np.ndarray:
    """|DFT|^2 of the mean-removed, Hann-tapered (unit energy) `y`, zero-padded to `pad` n, at the
    frequencies j / (pad n), j = 0 .. pad n / 2."""
    n = len(y)
    taper = np.array([math.sin(math.pi * (i + 0.5) / n) ** 2 for i in range(n)])
    padded = np.zeros(pad * n)
    padded[:n] = (y - y.mean()) * taper / math.sqrt(float(np.sum(taper * taper)))
    # an FFT (numpy's, on the explicitly padded series): a direct sum per bin costs n^2 on the benches' long plateaus
    return np.abs(np.fft.fft(padded)[: pad * n // 2 + 1]) ** 2


def find_lines(y: np.ndarray, *, max_lines: int = 3, threshold: float = 25.0, min_cycles: float = 1.0,
               pad: int = 4) -> list[float]:
    """Frequencies [cycles per sample] of up to `max_lines` periodogram peaks, each `threshold` times the
    background (median / ln 2 of the bins with `min_cycles` periods in the window), placed between bins by a
    parabola through the log spectrum; each line is regressed out before the next is sought."""
    n = len(y)
    t = np.arange(n, dtype=float)
    lines: list[float] = []
    resid = y - y.mean()
    for _ in range(max_lines):
        spec = periodogram(resid, pad)
        usable = [j for j in range(len(spec)) if j / pad >= min_cycles]  # j / (pad n) cycles per sample, n samples
        if not usable:
            break
        background = median(spec[usable]) / math.log(2.0)
        i = max(usable, key=lambda j: spec[j])
        if spec[i] < threshold * background or i + 1 >= len(spec):
            break
        a, b, c = (math.log(spec[j] + 1e-300) for j in (i - 1, i, i + 1))
        shift = 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c < 0 else 0.0
        lines.append((i + shift) / (pad * n))
        X = design(t, lines)
        resid = y - X @ np.linalg.lstsq(X, y, rcond=None)[0]
    return lines


def span_variance(residuals, *, min_span: int = MIN_SPAN, spans: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """``(a, b)`` of ``V(L) = (a + b L) s(L)``, V the mean square of every sum of L consecutive residuals and
    s(L) the mean of (1 - L / n) over those sums, at `spans` lengths spread geometrically from `min_span` to a
    third of the shortest window; fitted by relative least squares (each V weighted by count / L, divided by
    V), falling back to the one term that is positive."""
    top = max(min_span + 1, min(len(r) for r in residuals) // 3)
    lengths = sorted(set(np.geomspace(min(min_span, max(1, top - 1)), top, spans).astype(int).tolist()))
    k = residuals[0].shape[1]
    rows, values, weights = [], [], []
    for L in lengths:
        total, count, shrink = np.zeros(k), 0, 0.0
        for r in residuals:
            if len(r) <= L:
                continue
            running = np.vstack([np.zeros((1, k)), np.cumsum(r, axis=0)])
            sums = running[L:] - running[:-L]  # each sum of L consecutive rows: a difference of running sums
            total += (sums * sums).sum(axis=0)
            count += len(sums)
            shrink += len(sums) * (1 - L / len(r))
        if count:
            rows.append((shrink / count, L * shrink / count))
            values.append(total / count)
            weights.append(count / L)
    X, V, w = np.array(rows), np.array(values), np.array(weights)
    a, b = np.zeros(k), np.zeros(k)
    for j in range(k):
        s = np.sqrt(w) / np.maximum(V[:, j], 1e-300)
        coef = np.linalg.lstsq(X * s[:, None], V[:, j] * s, rcond=None)[0]
        if coef[0] < 0:  # b alone: weighted least squares of V on L s(L)
            coef = [0.0, np.sum(s**2 * X[:, 1] * V[:, j]) / np.sum((s * X[:, 1]) ** 2)]
        elif coef[1] < 0:  # a alone
            coef = [np.sum(s**2 * X[:, 0] * V[:, j]) / np.sum((s * X[:, 0]) ** 2), 0.0]
        a[j], b[j] = coef
    return a, b
