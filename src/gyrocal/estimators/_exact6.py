"""Closed-form first-moment fit for exactly six rotation windows (the paper's design).

With six norm equations and six unknowns the least-squares solution makes every
residual zero, so the weights drop out. Squaring ``|diag(k)(m_mean + b)| = rate`` gives
the servo method's linear form (eq. 3-4) with window means in place of means of squares:

    X beta + beta0(beta) 1 = Y,   X_i = [m_mean_i^2, m_mean_i],   Y_i = rate_i^2.

As in Algorithm 1, ``beta = u - beta0 v`` with ``u = X^-1 Y`` and ``v = X^-1 1``, so
the system reduces to one scalar equation ``beta0 = gamma(u - beta0 v)``, solved here
by Newton's method from ``beta0 = 0``.

Everything is vectorised over the batch with the batch axis last, in cache-sized
chunks spread over threads (numpy releases the GIL inside its loops). The 6x6
inverse is an in-place Gauss-Jordan elimination with one pivot order for the whole
batch, taken from the first gyro: every gyro of a batch shares the design, so the
same rows dominate. Items whose result does not satisfy the norm equations (or is
not finite) are flagged so the caller can re-solve them with the general path.

The covariance is the exactly-determined sandwich ``J^-1 Sigma J^-T`` of the
general path, computed in beta-space: ``M = X + 1 grad(gamma)^T`` is a rank-one
update of ``X`` (Sherman-Morrison), then mapped to ``(k, b)``.
"""

from __future__ import annotations

import os

import numpy as np

from ._noise import pooled_noise_var

_CHUNK = 8192  # gyros per chunk: measured best of 1k..32k on the 2-core machine
_NEWTON_MAX = 30
_RESIDUAL_RTOL = 1e-8  # |norm - rate| / rate accepted as "solved exactly"


def pivot_order(X0: np.ndarray) -> np.ndarray:
    """Row order (6,) that puts partial-pivoting pivots of `X0` (6, 6) on the diagonal."""
    A = np.array(X0, dtype=float)
    order = np.arange(len(A))
    for c in range(len(A)):
        p = c + int(np.argmax(np.abs(A[c:, c])))
        A[[c, p]], order[[c, p]] = A[[p, c]], order[[p, c]]
        if A[c, c] != 0:
            A[c + 1:] -= np.outer(A[c + 1:, c] / A[c, c], A[c])
    return order


def _inv_inplace(A: np.ndarray) -> None:
    """Gauss-Jordan inverse of (n, n, b) matrices in place, pivots on the diagonal."""
    tmp = np.empty_like(A)
    for c in range(A.shape[0]):
        piv = 1.0 / A[c, c]
        A[c, c] = 1.0
        A[c] *= piv
        f = A[:, c].copy()
        f[c] = 0.0
        A[:, c] = 0.0
        A[c, c] = piv
        np.multiply(f[:, None], A[c][None], out=tmp)
        A -= tmp  # every other row at once; row c has f = 0


def _gamma_newton(u: np.ndarray, v: np.ndarray, tol: np.ndarray):
    """Solve ``g = gamma(u - g v)`` for each item (u, v: (6, b)); return g, steps, ok, betas."""
    g = np.zeros(u.shape[1])
    steps = np.zeros(u.shape[1], dtype=int)
    active = np.ones(u.shape[1], dtype=bool)
    betas = [u.copy()]
    for _ in range(_NEWTON_MAX):
        a, d = u[3:] - g * v[3:], u[:3] - g * v[:3]
        f = g - np.sum(a * a / (4 * d), axis=0)
        fp = 1.0 + np.sum(a * v[3:] / (2 * d) - a * a * v[:3] / (4 * d * d), axis=0)
        step = np.where(active, f / fp, 0.0)
        g -= step
        steps += active
        betas.append(u - g * v)  # finished items take zero steps, so their rows repeat
        active &= ~(np.abs(step) <= tol)  # NaN stays active, and fails below
        if not active.any():
            break
    return g, steps, ~active, betas


def _kb(beta: np.ndarray) -> np.ndarray:
    """(k, b) rows (6, b) from beta rows (6, b); sqrt of |beta| keeps failed items finite."""
    return np.concatenate([np.sqrt(np.abs(beta[:3])), beta[3:] / (2 * beta[:3])])


def _solve_chunk(mean, rate, count, noise_var, out_p, out_cov, out_resid):
    """Solve one chunk, writing (6, b), (6, 6, b) and (6, b) outputs; returns steps, ok, history.

    Inputs: window means (6, 3, b), rates (6, b), counts (6,), noise variances (3, b).
    """
    m = mean
    Y = rate**2
    Xi = np.concatenate([m * m, m], axis=1)  # (6 windows, 6 params, b)
    _inv_inplace(Xi)  # now X^-1: (6 params, 6 windows, b)
    u = np.einsum("pwb,wb->pb", Xi, Y)
    v = Xi.sum(axis=1)
    _, steps, ok, betas = _gamma_newton(u, v, 1e-15 * Y.max(axis=0))
    beta = betas[-1]
    k, b = np.sqrt(beta[:3]), beta[3:] / (2 * beta[:3])
    out_p[:3], out_p[3:] = k, b
    vk = k[None] * (m + b[None])  # (6, 3, b): diag(k)(m_mean + b) per window
    norm = np.sqrt(np.sum(vk * vk, axis=1))
    out_resid[...] = (norm - rate) * np.sqrt(count)[:, None]
    ok &= np.all(np.abs(norm - rate) <= _RESIDUAL_RTOL * rate, axis=0) & np.all(beta[:3] > 0, axis=0)

    # Covariance: dF = M dbeta + dF/dm dm with F_i = |v_i|^2 - rate_i^2 (the squared norm equation),
    # M = X + 1 grad^T; cov(k, b) = T diag(q) T^T with T = d(k, b)/d(beta) M^-1.
    grad = np.concatenate([-(beta[3:] ** 2) / (4 * beta[:3] ** 2), beta[3:] / (2 * beta[:3])])
    w = np.einsum("pb,pwb->wb", grad, Xi) / (1.0 + np.sum(grad * v, axis=0))  # Sherman-Morrison
    T = Xi  # X^-1 is not needed any more: build T in its place
    T[3:] -= 2 * b[:, None] * T[:3]
    T -= np.concatenate([v[:3], v[3:] - 2 * b * v[:3]])[:, None] * w[None]
    q = 4 * np.einsum("wjb,jb->wb", vk * vk * k[None] ** 2, noise_var) / count[:, None]  # var(F_i)
    T *= np.concatenate([1 / (2 * k), 1 / (2 * beta[:3])])[:, None] * np.sqrt(q)[None]
    for p in range(6):  # symmetric: the upper triangle, then its mirror
        np.einsum("wb,qwb->qb", T[p], T[p:], out=out_cov[p, p:])
        out_cov[p + 1:, p] = out_cov[p, p + 1:]
    ok &= np.all(np.isfinite(out_cov), axis=(0, 1))
    return steps, ok, [_kb(bt) for bt in betas]


def exact_six(mean: np.ndarray, rate: np.ndarray, count: np.ndarray, noise_var: np.ndarray | None,
              window_noise_var: np.ndarray, workers: int | None = None):
    """Exactly-determined first-moment fit of a batch of six rotation windows.

    Parameters
    ----------
    mean : ndarray, shape (B, 6, 3)
        Window means [reading units].
    rate : ndarray, shape (B, 6)
        Reference rates [rad/s].
    count : ndarray, shape (6,)
        Samples per window.
    noise_var : ndarray of shape (B, 3), or None
        Known per-sample noise variance per axis [reading units^2]; None to pool it
        from `window_noise_var` (:func:`~gyrocal.estimators._noise.pooled_noise_var`).
    window_noise_var : ndarray, shape (B, 6, 3)
        Each window's first-difference noise variance [reading units^2].
    workers : int, optional
        Threads; default ``os.cpu_count()``.

    Returns
    -------
    k, b : (B, 3); covariance (B, 6, 6); iterations (B,) Newton steps; ok (B,) bool;
    residuals (B, 6) weighted as in the general path; history (B, n + 1, 6) of ``(k, b)``;
    noise variance (B, 3).
    Arrays with the batch axis first are transposed views of batch-last storage.
    """
    B = len(mean)
    with np.errstate(all="ignore"):
        order = pivot_order(np.concatenate([mean[0] ** 2, mean[0]], axis=1))
    count = np.asarray(count, dtype=float)[order]
    params, cov, resid = np.empty((6, B)), np.empty((6, 6, B)), np.empty((6, B))
    steps, ok = np.empty(B, dtype=int), np.empty(B, dtype=bool)

    def run(s: int):
        sl = slice(s, min(B, s + _CHUNK))
        m = np.ascontiguousarray(mean[sl][:, order].transpose(1, 2, 0))
        r = np.ascontiguousarray(rate[sl][:, order].T)
        if noise_var is None:
            wnv = np.ascontiguousarray(window_noise_var[sl][:, order].transpose(1, 2, 0))
            nv = pooled_noise_var(m, wnv, count, np.zeros(6, dtype=bool))
        else:
            nv = np.ascontiguousarray(noise_var[sl].T)
        with np.errstate(all="ignore"):
            steps[sl], ok[sl], h = _solve_chunk(m, r, count, nv, params[:, sl], cov[..., sl], resid[:, sl])
        return sl, h, nv

    starts = range(0, B, _CHUNK)
    n_workers = min(workers or os.cpu_count() or 1, len(starts))
    if n_workers > 1:
        from concurrent.futures import ThreadPoolExecutor  # only a batch big enough for threads pays its import

        with ThreadPoolExecutor(n_workers) as pool:
            chunks = list(pool.map(run, starts))
    else:
        chunks = [run(s) for s in starts]
    depth = max(len(h) for _, h, _ in chunks)
    history, nv_out = np.empty((depth, 6, B)), np.empty((3, B))
    for sl, h, nv in chunks:
        nv_out[:, sl] = nv
        for i in range(depth):  # finished chunks repeat their final row
            history[i, :, sl] = h[min(i, len(h) - 1)]
    undo = np.argsort(order)
    return (params[:3].T, params[3:].T, cov.transpose(2, 0, 1), steps, ok, resid[undo].T,
            history.transpose(2, 0, 1), nv_out.T)
