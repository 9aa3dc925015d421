"""Standard errors of window means that hold for correlated noise and speed ripple.

``sigma / sqrt(n)`` holds for white noise only. A plateau of a servo turn also carries the
servo's speed ripple, and a MEMS gyro's noise is not white at every time scale; both make
the window mean scatter more. Here: the ripple's lines found and regressed out of each plateau
(:func:`find_lines`, :func:`fit_levels`), a Newey-West long-run variance (:func:`newey_west_var`), and the
variance of span sums that separates sensor noise from a servo's bounded vibration (:func:`span_variance`).
"""

from __future__ import annotations

import numpy as np

from .._arrays import distinct, median

__all__ = ["block_means", "find_lines", "fit_level", "fit_levels", "line_mean", "newey_west_var", "ramp_end",
           "span_variance"]


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
    # one contiguous row per column: the lagged products then run along memory (several times faster)
    rows = np.ascontiguousarray(x.T)
    d = rows - rows.mean(axis=1, keepdims=True)
    rho = np.zeros(len(d))
    if prewhiten and n > 3:
        den = np.einsum("ji,ji->j", d[:, :-1], d[:, :-1])
        rho = np.clip(np.einsum("ji,ji->j", d[:, 1:], d[:, :-1]) / np.where(den > 0, den, 1.0), -0.97, 0.97)
        d = d[:, 1:] - rho[:, None] * d[:, :-1]
    m = d.shape[1]
    if lags is None:
        lags = int(np.floor(4 * (m / 100.0) ** (2.0 / 9.0)))
    lags = max(0, min(lags, m - 1))
    s = np.einsum("ji,ji->j", d, d) / m
    for h in range(1, lags + 1):
        s = s + 2 * (1 - h / (lags + 1)) * np.einsum("ji,ji->j", d[:, h:], d[:, :-h]) / m
    return np.maximum(s, 0.0) / (1.0 - rho) ** 2 / n


#: Shortest span [samples] of the span-variance fit: a servo's vibration decorrelates within it.
_MIN_SPAN = 8


def span_variance(residuals: list[np.ndarray], *, min_span: int = _MIN_SPAN, spans: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Long-run variance and bounded-angle variance of residuals, from the variance of their sums over spans.

    A plateau's residual (its level and periodic ripple removed) is sensor noise plus whatever is
    left of the motion's own error. The sensor's part integrates to a random walk, the motion's is
    a bounded angle error (a position-controlled servo's vibration: its rate has no zero-frequency
    power, but lag windows such as Newey-West's count its short-lag covariance and not the negative
    one beyond, and overstate the plateau's variance many times). The variance of the sum of `L`
    consecutive residuals separates them: ``V(L) = a + b L`` once `L` exceeds the vibration's
    correlation time, with ``b`` the long-run variance per sample and ``a`` twice the bounded error's
    variance. The mean of ``n`` residuals then has variance ``(a + b n) / n^2``.

    Parameters
    ----------
    residuals : list of ndarray, shape (n_i, k)
        Each window's residuals (mean zero within the window).
    min_span : int
        Shortest span [samples].
    spans : int
        Span lengths, spread geometrically from `min_span` to a third of the shortest window.

    Returns
    -------
    a, b : ndarray, shape (k,)
        ``a`` [units^2 samples^2] and ``b`` [units^2 samples] (per sample of the residuals).
    """
    n_min = min(len(r) for r in residuals)
    top = max(min_span + 1, n_min // 3)
    lengths = distinct(np.geomspace(min(min_span, max(1, top - 1)), top, spans).astype(int))
    k = residuals[0].shape[1]
    rows, values, weights = [], [], []
    for L in lengths.tolist():
        total, count, shrink = np.zeros(k), 0, 0.0
        for r in residuals:
            if len(r) <= L:
                continue
            c = np.concatenate([np.zeros((1, k)), np.cumsum(r, axis=0)])
            d = c[L:] - c[:-L]  # every sum of L consecutive residuals
            total += np.einsum("ij,ij->j", d, d)
            count += len(d)
            # removing each window's mean shortens its sums' variance by about (1 - L / n)
            shrink += len(d) * (1 - L / len(r))
        if count:
            rows.append((shrink / count, L * shrink / count))
            values.append(total / count)
            weights.append(count / L)  # roughly independent sums of L
    X, V, w = np.array(rows), np.array(values), np.array(weights)
    a, b = np.zeros(k), np.zeros(k)
    for j in range(k):
        # relative least squares: each V(L) has a relative spread of about sqrt(L / count)
        sw = np.sqrt(w) / np.maximum(V[:, j], 1e-300)
        coef = np.linalg.lstsq(X * sw[:, None], V[:, j] * sw, rcond=None)[0]
        if coef[0] < 0 or coef[1] < 0:  # one term only: the other is not in the data
            only_b = float(np.sum(sw**2 * X[:, 1] * V[:, j]) / np.sum((sw * X[:, 1]) ** 2))
            coef = np.array([0.0, only_b]) if coef[0] < 0 else np.array([float(np.sum(sw**2 * X[:, 0] * V[:, j])
                                                                                  / np.sum((sw * X[:, 0]) ** 2)), 0.0])
        a[j], b[j] = coef
    return a, b


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
        usable = f * n >= min_cycles - 1e-9  # rfftfreq's bin of exactly one cycle can land an ulp short
        if not usable.any():
            break
        background = median(spec[usable]) / np.log(2.0)
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
    """Regressors (n, 1 + 2 L): a constant, then the cosine and sine of each line at times `t`."""
    X = np.empty((len(t), 1 + 2 * len(lines)))
    X[:, 0] = 1.0
    if lines:
        phase = np.exp(2j * np.pi * np.multiply.outer(t, lines))  # (n, L)
        X[:, 1::2], X[:, 2::2] = phase.real, phase.imag
    return X


def _solve(x: np.ndarray, X: np.ndarray, inv: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    coef = inv @ (X.T @ x)
    return coef[0], float(inv[0, 0]), x - X @ coef


def fit_level(x: np.ndarray, t: np.ndarray, lines: list[float]) -> tuple[np.ndarray, float, np.ndarray]:
    """Level of `x` (n, 3) at times `t` [in mean sample steps] with sinusoids at `lines` regressed out.

    Returns the level (3,), the factor that turns a per-sample long-run variance into the level's
    variance (``[(X^T X)^-1]_00``, 1/n without lines), and the residuals (n, 3).
    """
    if not lines:
        level = x.mean(axis=0)
        return level, 1.0 / len(x), x - level
    X = _design(t, lines)
    return _solve(x, X, np.linalg.inv(X.T @ X))


#: Sample times within this many mean steps of whole numbers are a regular clock up to rounding.
_REGULAR = 1e-9


def fit_levels(xs: list[np.ndarray], ts: list[np.ndarray], lines: list[float]) -> list[tuple]:
    """:func:`fit_level` of many stretches with the same `lines`, each ``(level, factor, residuals)``.

    Stretches on a regular clock (times whole numbers of steps up to rounding, as on a sensor's clock)
    share one design matrix, cut to their length, and its inverse per length: the sines and cosines
    of the lines, most of the cost of a fit, are then computed once rather than once a plateau.
    """
    if not lines:
        return [fit_level(x, t, lines) for x, t in zip(xs, ts)]
    regular = [bool(np.abs(t - np.arange(len(t))).max() <= _REGULAR) for t in ts]
    longest = max((len(t) for t, r in zip(ts, regular) if r), default=0)
    shared = _design(np.arange(longest, dtype=float), lines)
    inverses: dict[int, np.ndarray] = {}
    out = []
    for x, t, r in zip(xs, ts, regular):
        if not r:
            out.append(fit_level(x, t, lines))
            continue
        X = shared[: len(t)]
        if len(t) not in inverses:
            inverses[len(t)] = np.linalg.inv(X.T @ X)
        out.append(_solve(x, X, inverses[len(t)]))
    return out


def line_mean(x: np.ndarray, t: np.ndarray, lines: list[float], lo: float, hi: float) -> np.ndarray:
    """Mean over ``[lo, hi]`` (times as `t`, in steps) of the sinusoids at `lines` fitted to `x` (n, k) with a constant."""
    if not lines or hi <= lo:
        return np.zeros(x.shape[1])
    coef = np.linalg.lstsq(_design(t, lines), x, rcond=None)[0]
    w = 2 * np.pi * np.asarray(lines)
    ds, dc = (np.sin(w * hi) - np.sin(w * lo)) / w, (np.cos(w * hi) - np.cos(w * lo)) / w
    return (ds @ coef[1::2] - dc @ coef[2::2]) / (hi - lo)


def ramp_end(y: np.ndarray, level: float) -> float | None:
    """Where the ramp in `y` (n,), rising towards its end, reaches `level` > 0: the line through its
    middle (a fifth to four fifths of the level) meeting the level, in steps from ``y[0]``; None when
    `y` holds no such ramp (a slope of at least a tenth of the level over its middle's span is needed)."""
    below = np.flatnonzero(y < 0.5 * level)
    if not len(below):
        return None
    q = int(below[-1])
    low = np.flatnonzero(y[:q + 1] < 0.2 * level)
    high = np.flatnonzero(y[q:] >= 0.8 * level)
    lo, hi = (int(low[-1]) + 1 if len(low) else 0), (q + int(high[0]) if len(high) else len(y))
    i = np.arange(lo, hi)
    if len(i) < 2:
        return None
    slope, icpt = np.polyfit(i, y[lo:hi], 1)
    if slope * (hi - lo) < 0.1 * level:
        return None
    return float(np.clip((level - icpt) / slope, q, len(y)))


def block_means(x: np.ndarray, d: int) -> np.ndarray:
    """Means of consecutive blocks of `d` rows of `x` (n,) or (n, k); the tail that fills no block is dropped."""
    if d <= 1:
        return x
    m = len(x) // d
    avg = np.full(d, 1.0 / d)
    if x.ndim == 1:
        return x[: m * d].reshape(m, d) @ avg
    # column by column, as matrix-vector products: contiguous for column-major windows
    return np.stack([c[: m * d].reshape(m, d) @ avg for c in x.T], axis=1)
