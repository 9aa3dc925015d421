"""Standard errors of window means that hold for correlated noise and speed ripple.

``sigma / sqrt(n)`` holds for white noise only. A plateau of a servo turn also carries the
servo's speed ripple, and a MEMS gyro's noise is not white at every time scale; both make
the window mean scatter more. Its variance is the zero-frequency spectral density of the
readings divided by the window length, estimated here by batch means.
"""

from __future__ import annotations

import numpy as np

__all__ = ["batch_means_var", "newey_west_var"]


def batch_means_var(x: np.ndarray, batches: int = 10) -> np.ndarray:
    """Variance of the mean of `x` (n, k) along axis 0 from `batches` non-overlapping batch means."""
    x = np.asarray(x, dtype=float)
    n = len(x)
    b = max(2, min(batches, n // 2))
    size = n // b
    m = x[: b * size].reshape(b, size, -1).mean(axis=1)
    return m.var(axis=0, ddof=1) / b


def newey_west_var(x: np.ndarray, lags: int | None = None, *, prewhiten: bool = True) -> np.ndarray:
    """Variance of the mean of `x` (n, k) along axis 0 from its long-run variance (Newey-West).

    The long-run variance (the zero-frequency spectral density) is the Bartlett-weighted sum of
    the autocovariances up to `lags` (default ``4 (n / 100)^(2/9)``). With `prewhiten` the series
    is first filtered by its own AR(1) fit and the result recoloured (Andrews and Monahan, 1992),
    which keeps smooth correlated noise and differenced (blue) noise from being over- or
    under-counted by a short window of lags.
    """
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


def _periodogram(y: np.ndarray, pad: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Hann-tapered periodogram of `y` (n,) at frequencies [cycles per sample], zero-padded `pad` times."""
    n = len(y)
    h = np.sin(np.pi * (np.arange(n) + 0.5) / n) ** 2
    h /= np.sqrt(np.sum(h * h))
    spec = np.abs(np.fft.rfft((y - y.mean()) * h, pad * n)) ** 2
    return np.fft.rfftfreq(pad * n), spec


def find_lines(y: np.ndarray, *, max_lines: int = 3, threshold: float = 25.0, min_cycles: float = 1.0) -> list[float]:
    """Frequencies [cycles per sample] of sinusoids standing out of the noise of `y` (n,).

    A line is a periodogram peak at least `threshold` times the median background (``median /
    ln 2`` estimates the mean of an exponential), with at least `min_cycles` periods in the window.
    Each line found is regressed out before the next is sought.
    """
    n = len(y)
    t = np.arange(n, dtype=float)
    lines: list[float] = []
    resid = y - y.mean()
    for _ in range(max_lines):
        f, spec = _periodogram(resid)
        usable = f * n >= min_cycles
        if not usable.any():
            break
        background = np.median(spec[usable]) / np.log(2.0)
        i = int(np.flatnonzero(usable)[np.argmax(spec[usable])])
        if spec[i] < threshold * background or i + 1 >= len(spec):
            break
        a, b, c = np.log(spec[i - 1:i + 2] + 1e-300)
        shift = 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c < 0 else 0.0
        lines.append(float(f[i] + shift * (f[1] - f[0])))
        X = _design(t, lines)
        resid = y - X @ np.linalg.lstsq(X, y, rcond=None)[0]
    return lines


def _design(t: np.ndarray, lines: list[float]) -> np.ndarray:
    cols = [np.ones_like(t)]
    for f in lines:
        cols += [np.cos(2 * np.pi * f * t), np.sin(2 * np.pi * f * t)]
    return np.stack(cols, axis=1)


def plateau_mean(x: np.ndarray, t: np.ndarray | None = None, *,
                 lines: list[float] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Level and its variance [units, units^2] of a steady stretch `x` (n, 3) with a periodic ripple.

    A servo's or robot joint's speed ripple is a sinusoid on top of the level. It is found on the
    axis that turns (the largest mean) and regressed out together with the level; the level's
    variance is then that of a regression coefficient under the residuals' long-run variance
    (Newey-West), so correlated noise counts too.

    Parameters
    ----------
    x : ndarray, shape (n, 3)
        Readings.
    t : ndarray, shape (n,), optional
        Sample times [s]; the regression then weighs each sample by the time it stands for
        (trapezoid) and places the sinusoids on the stamps. Default: evenly spaced.
    lines : list of float, optional
        Ripple frequencies [cycles per mean sample step]; found with :func:`find_lines` by default.
    """
    x = np.asarray(x, dtype=float)
    n = len(x)
    if lines is None:
        a = int(np.argmax(np.abs(x.mean(axis=0))))
        lines = find_lines(x[:, a])
    if t is None or n < 3:
        tt, w = np.arange(n, dtype=float), np.ones(n)
    else:
        step = np.diff(t)
        tt = (t - t[0]) / step.mean()
        w = np.concatenate(([step[0]], (step[:-1] + step[1:]) / 2, [step[-1]])) / step.mean()
    X = _design(tt, lines)
    sw = np.sqrt(w)[:, None]
    coef, *_ = np.linalg.lstsq(X * sw, x * sw, rcond=None)
    resid = x - X @ coef
    XtX_inv = np.linalg.inv((X * w[:, None]).T @ X)
    lrv = newey_west_var(resid) * n  # long-run variance per sample
    # var of the weighted coefficient: (X'WX)^-1 X'W S W X (X'WX)^-1 with S = lrv I, ~ lrv (X'WX)^-1 for w ~ 1
    return coef[0], lrv * XtX_inv[0, 0]
