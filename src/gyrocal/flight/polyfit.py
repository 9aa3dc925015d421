"""Polynomial fits of block means with an order chosen by leave-one-segment-out error.

Neighbouring samples of a warm-up log are strongly correlated (bias instability, the slow
lag between die and sensor temperature), so leaving out single samples or blocks would
let their neighbours vouch for them and favour too high an order. Instead the temperature
range is cut into segments of equal width, and each is predicted from a fit to the others
(for a board that warms steadily a segment is also a stretch of time). The standard errors
of the coefficients come from a noise model fitted to the residuals, white noise plus a
Gauss-Markov wander of the bias (:func:`ar1_covariance`), so correlated residuals widen them.
"""

from __future__ import annotations

import math

import numpy as np

from .._arrays import distinct

__all__ = ["ar1_covariance", "choose_orders", "segment_cv", "vander"]


def vander(u: np.ndarray, order: int) -> np.ndarray:
    """Columns ``u**0 .. u**order``."""
    return np.vander(u, order + 1, increasing=True)


def segment_cv(u: np.ndarray, y: np.ndarray, segments: np.ndarray, max_order: int) -> np.ndarray:
    """RMS prediction error (max_order + 1, m) of each order, each segment predicted from the others.

    Parameters
    ----------
    u : ndarray, shape (n,)
        Regressor (scaled temperature).
    y : ndarray, shape (n, m)
        Values to fit, one column each.
    segments : ndarray of int, shape (n,)
        Segment label of each point.
    max_order : int
        Highest order tried.
    """
    labels = distinct(segments)
    out = np.empty((max_order + 1, y.shape[1]))
    for p in range(max_order + 1):
        err = np.empty_like(y)
        for k in labels:
            test = segments == k
            coef, *_ = np.linalg.lstsq(vander(u[~test], p), y[~test], rcond=None)
            err[test] = vander(u[test], p) @ coef - y[test]
        out[p] = np.sqrt(np.mean(err**2, axis=0))
    return out


def choose_orders(cv_rms: np.ndarray, n_segments: int) -> np.ndarray:
    """Lowest order within the CV error's own uncertainty (about 1/sqrt(2 K)) of the best, per column.

    The "one standard error" rule of cross-validation: noise alone cannot buy extra orders.
    """
    best = cv_rms.min(axis=0)
    return np.argmax(cv_rms <= best * (1 + 1 / math.sqrt(2 * n_segments)) + 1e-300, axis=0)


def _ar1_apply(x: np.ndarray, phi: float) -> np.ndarray:
    """``R x`` for ``R_ij = phi^|i - j|`` (columns of x), by a forward and a backward recursion."""
    from scipy.signal import lfilter

    fwd = lfilter([1.0], [1.0, -phi], x, axis=0)
    bwd = lfilter([1.0], [1.0, -phi], x[::-1], axis=0)[::-1]
    return fwd + bwd - x


def _lag_sums(A: np.ndarray, B: np.ndarray, K: int) -> np.ndarray:
    """``sum_i (A B')_{i, i+k}`` for k = 0..K."""
    n = len(A)
    return sum(np.correlate(B[:, j], A[:, j], "full")[n - 1 : n + K] for j in range(A.shape[1]))


def ar1_covariance(X: np.ndarray, resid: np.ndarray, white_var: float, max_lag: int = 100) -> tuple[np.ndarray, dict]:
    """Covariance of least-squares coefficients under white noise plus a first-order autoregressive part.

    The noise of the block means is modelled as ``S = w I + s2 R(phi)``, ``R_ij = phi^|i - j|``
    (white noise of known variance `white_var` plus a Gauss-Markov wander of the bias). A
    fitted polynomial absorbs the slowest part of the wander, so the residuals' autocovariance
    is matched to its expectation under the model, ``M S M`` with ``M = I - X (X'X)^-1 X'``
    (lags 0..K, a method-of-moments fit of ``s2`` for each ``phi`` on a grid). The coefficient
    covariance is then ``B X' S X B``, ``B = (X'X)^-1``. A Bartlett-kernel (HAC) estimate misses
    such a wander when white noise dominates the lag-1 autocorrelation.

    Parameters
    ----------
    X : ndarray, shape (n, k)
        Design matrix, rows in time order.
    resid : ndarray, shape (n,)
        Residuals of the fit.
    white_var : float
        Variance of the white part of one residual (per-sample noise^2 / samples per block).
    max_lag : int
        Largest lag matched.

    Returns
    -------
    cov : ndarray, shape (k, k)
    model : dict
        ``{"white_var", "ar_var", "ar_phi"}``.
    """
    n = len(resid)
    K = max(2, min(max_lag, n // 4))
    target = _lag_sums(resid[:, None], resid[:, None], K)  # n x autocovariance
    B = np.linalg.inv(X.T @ X)
    XB = X @ B
    white = np.array([n - k for k in range(K + 1)], float) * (np.arange(K + 1) == 0) - _lag_sums(XB, X, K)
    best = (np.inf, 0.0, 0.0, None)
    for phi in np.linspace(0.0, 0.995, 100)[1:]:
        Q = _ar1_apply(X, phi)
        C = B @ (X.T @ Q) @ B
        expect = (np.array([(n - k) * phi**k for k in range(K + 1)]) - _lag_sums(XB, Q, K) - _lag_sums(Q @ B, X, K)
                  + _lag_sums(X @ C, X, K))
        rest = target - white_var * white
        s2 = max(float(expect @ rest) / float(expect @ expect), 0.0)
        sse = float(np.sum((rest - s2 * expect) ** 2))
        if sse < best[0]:
            best = (sse, float(phi), s2, C)
    _, phi, s2, C = best
    cov = white_var * B + s2 * C
    return cov, {"white_var": float(white_var), "ar_var": s2, "ar_phi": phi}
