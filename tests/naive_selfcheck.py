"""The straightforward implementations that the calibration's fast paths replaced, kept as their reference.

Each function here is the code gyrocal ran before the speed work (window by window, full-rate passes,
one whole-recording array after another), unchanged but for imports. ``tests/test_fast_paths.py``
compares the fast paths with them on seeded data (equal to rounding), and ``bench/bench_selfcheck.py``
times them as its naive baseline in the same process. :func:`install` swaps them into the library,
so that a whole calibration runs the old way.
"""

from __future__ import annotations

import math

import numpy as np

from gyrocal._validation import finite_array, positive
from gyrocal.errors import InputError
from gyrocal.longrun import _design, block_means, find_lines
from gyrocal.observations import Observation


def _time_weights(t: np.ndarray, n: int) -> np.ndarray:
    if t.shape != (n,):
        raise InputError(f"t has {len(t)} sample times but the window has {n} samples")
    step = np.diff(t)
    if np.any(step <= 0):
        raise InputError("t must increase strictly inside a window")
    w = np.empty(n)
    w[0], w[-1] = step[0], step[-1]
    w[1:-1] = (step[:-1] + step[1:]) / 2
    return w


def observe(samples, sample_rate, kind, *, speed=None, angle=None, t=None, level=None, mean_var=None) -> Observation:
    """One window reduced with ``np.average`` and ``np.diff`` (gyrocal.observations.observe as it was)."""
    m = finite_array("samples", samples, shape_tail=(3,), ndim=2)
    fs = positive("sample_rate", sample_rate)
    if t is None:
        weights, duration = None, len(m) / fs
    else:
        weights = _time_weights(finite_array("t", t, ndim=1), len(m))
        duration = float(weights.sum())
    if kind == "speed":
        rate, ang = abs(float(speed)), math.nan
    elif kind == "angle":
        ang = 2 * math.pi if angle is None else abs(float(angle))
        rate = ang / duration
    else:
        rate, ang = 0.0, math.nan
    d = np.diff(m, axis=0)
    return Observation(
        mean=np.average(m, axis=0, weights=weights) if level is None else level, mean_var=mean_var,
        mean_sq=np.average(m * m, axis=0, weights=weights), noise_var=(d * d).mean(axis=0) / 2.0,
        count=len(m), duration=duration, kind=kind, rate=rate, angle=ang,
    )


def observe_windows(rec, windows, reference, speed, *, long_run=True, ripple=True, times=None):
    """Every window reduced on its own (gyrocal.window_stats.observe_windows as it was)."""
    times = rec.t if times is None else times
    stats = {}
    if long_run or ripple:
        stats = window_stats(rec, windows, reference, times, long_run=long_run, ripple=ripple)
    out = []
    for i, w in enumerate(windows):
        samples = rec.gyro[w.start:w.stop]
        samples = samples if rec.gyro.flags.f_contiguous else np.asfortranarray(samples)
        t, extra = times[w.start:w.stop], stats.get(i, {})
        if w.kind == "static":
            out.append(observe(samples, rec.sample_rate, "static", t=t, **extra))
        elif reference == "speed":
            out.append(observe(samples, rec.sample_rate, "speed", speed=speed, t=t, **extra))
        else:
            out.append(observe(samples, rec.sample_rate, "angle", angle=w.angle, t=t))
    return tuple(out)


def newey_west_var(x, lags=None, *, prewhiten=True):
    """Long-run variance of the mean, column by column of an (n, k) array (gyrocal.longrun as it was)."""
    x = np.asarray(x, dtype=float)
    n = len(x)
    d = x - x.mean(axis=0)
    rho = np.zeros(d.shape[1])
    if prewhiten and n > 3:
        den = np.einsum("ij,ij->j", d[:-1], d[:-1])
        rho = np.clip(np.einsum("ij,ij->j", d[1:], d[:-1]) / np.where(den > 0, den, 1.0), -0.97, 0.97)
        d = d[1:] - rho * d[:-1]
    m = len(d)
    if lags is None:
        lags = int(np.floor(4 * (m / 100.0) ** (2.0 / 9.0)))
    lags = max(0, min(lags, m - 1))
    s = np.einsum("ij,ij->j", d, d) / m
    for h in range(1, lags + 1):
        s = s + 2 * (1 - h / (lags + 1)) * np.einsum("ij,ij->j", d[h:], d[:-h]) / m
    return np.maximum(s, 0.0) / (1.0 - rho) ** 2 / n


def fit_level(x, t, lines):
    """One plateau's regression on its own design matrix (gyrocal.longrun as it was)."""
    if not lines:
        level = x.mean(axis=0)
        return level, 1.0 / len(x), x - level
    X = _design(t, lines)
    inv = np.linalg.inv(X.T @ X)
    coef = inv @ (X.T @ x)
    return coef[0], float(inv[0, 0]), x - X @ coef


def _pooled_lrv(residuals):
    total = sum(len(r) for r in residuals)
    step = max(1, int(np.ceil(total / 20_000)))
    chosen = np.concatenate(residuals[::step])
    return newey_west_var(chosen) * len(chosen)


def window_stats(rec, windows, reference, times, *, long_run, ripple):
    """Plateau levels and long-run variances, plateau by plateau (gyrocal.window_stats as it was)."""
    d = max(1, int(round(rec.sample_rate / 200.0)))
    gyro = block_means(rec.gyro, d)
    clock = block_means(np.asarray(times, dtype=float), d)
    span = {i: (-(-w.start // d), w.stop // d) for i, w in enumerate(windows)}
    blocks = {i: gyro[a:b] for i, (a, b) in span.items() if b - a >= 4}
    plateaus = [i for i in blocks if windows[i].kind == "rotation" and reference == "speed"]
    statics = [i for i in blocks if windows[i].kind == "static"]
    lines = []
    if ripple and plateaus:
        b = blocks[max(plateaus, key=lambda i: len(blocks[i]))]
        lines = find_lines(b[:, int(np.argmax(np.abs(b.mean(axis=0))))])
    out, resid, factor = {}, {}, {}
    for i in plateaus:
        t = clock[span[i][0]:span[i][1]]
        t = (t - t[0]) / ((t[-1] - t[0]) / (len(t) - 1))
        level, factor[i], resid[i] = fit_level(blocks[i], t, lines)
        if ripple:
            out[i] = {"level": level}
    if long_run and plateaus:
        lrv = _pooled_lrv([resid[i] for i in plateaus])
        for i in plateaus:
            out.setdefault(i, {})["mean_var"] = lrv * factor[i]
    if long_run and statics:
        lrv = _pooled_lrv([blocks[i] - blocks[i].mean(axis=0) for i in statics])
        for i in statics:
            out[i] = {"mean_var": lrv / len(blocks[i])}
    return out
