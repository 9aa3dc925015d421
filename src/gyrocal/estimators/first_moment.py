"""The first-moment estimator (docs/core.md, Estimators): unbiased, with a data-driven covariance.

Rotation windows give norm equations on the window mean,

    |diag(k) (m_mean + b)| = rate,                  rate = angle / T, or the known speed,

and static windows give vector equations ``diag(k) (m_mean + b) = 0``. Squaring the
window mean instead of averaging squares (the servo method of Wang et al., eq. 8) keeps the noise power out
of the equations, so the estimate is unbiased.

Rows are weighted by the square root of the window's sample count (equal per-sample
noise on every axis); the covariance is a sandwich that uses the per-axis noise
actually measured, so it stays right when the axes differ.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DegenerateDesignError, InputError
from ..observations import ObservationSet
from ._checks import require_converged, require_count, require_every_axis, require_full_rank, require_positive_k2
from ._exact6 import exact_six
from ._lm import batched_lm
from ._noise import estimate_noise_var
from ._result import BatchFit, FitResult

__all__ = ["FirstMoment", "estimate_noise_var", "first_moment_batch", "residuals_and_jacobian", "row_noise_var",
           "row_variance", "sandwich_covariance"]

PARAM_NAMES = ("kx", "ky", "kz", "bx", "by", "bz")


def residuals_and_jacobian(p: np.ndarray, obs: ObservationSet,
                           row_scale: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weighted residuals (B, m), Jacobian (B, m, 6) and each row's noise sensitivity.

    Rows are the rotation windows, then three rows per static window, each weighted
    by ``sqrt(count)`` (times `row_scale` (B, m) when given). The third output (B, m, 3)
    is the derivative of a weighted row with respect to one sample's reading: a window
    mean of ``n`` samples has variance ``sigma^2 / n`` and the row weight is ``sqrt(n)``,
    so the two cancel. It feeds :func:`sandwich_covariance`.
    """
    k, b = p[:, None, :3], p[:, None, 3:]
    rot, sta = ~obs.static, obs.static
    w_rot = np.sqrt(obs.count[rot])[None, :, None]
    v = k * (obs.mean[:, rot] + b)  # (B, n_rot, 3)
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    u = v / norm
    r_rot = (norm[..., 0] - obs.rate[:, rot]) * w_rot[..., 0]
    J_rot = np.concatenate([u * (obs.mean[:, rot] + b), u * k], axis=-1) * w_rot
    S_rot = u * k

    ms = obs.mean[:, sta] + b  # (B, n_sta, 3)
    w_sta = np.sqrt(obs.count[sta])[None, :, None]
    r_sta = (k * ms * w_sta).reshape(len(p), -1)
    eye = np.eye(3)
    k_sta = np.broadcast_to(k, ms.shape)
    J_sta = np.concatenate([eye * ms[..., None], eye * k_sta[..., None]], axis=-1) * w_sta[..., None]
    S_sta = eye * k_sta[..., None]
    B = len(p)
    r = np.concatenate([r_rot, r_sta], axis=1)
    J = np.concatenate([J_rot, J_sta.reshape(B, -1, 6)], axis=1)
    S = np.concatenate([S_rot, S_sta.reshape(B, -1, 3)], axis=1)
    if row_scale is not None:
        r, J, S = r * row_scale, J * row_scale[..., None], S * row_scale[..., None]
    return r, J, S


def row_noise_var(obs: ObservationSet, noise_var: np.ndarray) -> np.ndarray:
    """Per-sample-equivalent noise variance (B, m, 3) behind each row, ``count x var(window mean)``.

    Windows with a measured mean variance (``obs.mean_var``) use it; the others white noise
    `noise_var` (B, 3). Row order as in :func:`residuals_and_jacobian`.
    """
    obs = obs.as_batch()
    nu = np.broadcast_to(noise_var[:, None, :], obs.mean.shape)
    if obs.mean_var is not None:
        nu = np.where(np.isnan(obs.mean_var), nu, obs.mean_var * obs.count[None, :, None])
    return np.concatenate([nu[:, ~obs.static], np.repeat(nu[:, obs.static], 3, axis=1)], axis=1)


def row_variance(obs: ObservationSet, S: np.ndarray, nu: np.ndarray, row_scale: np.ndarray | None = None):
    """Variance (B, m) of each weighted row: window-mean noise ``sum_j S^2 nu``, plus the reference's.

    A rotation row ``sqrt(count) (|k (m + b)| - rate)`` (times `row_scale`) carries the reference
    rate's own variance ``count rate_var`` too (a turn whose angle a time-stamp gap leaves uncertain).
    """
    var = np.einsum("bmj,bmj->bm" if nu.ndim == 3 else "bmj,bj->bm", S * S, nu)
    if obs.rate_var is not None:
        extra = np.zeros(var.shape[-1])
        n_rot = int((~obs.static).sum())
        extra[:n_rot] = (obs.count * obs.rate_var)[~obs.static]
        var = var + extra * (1.0 if row_scale is None else row_scale**2)
    return var


def sandwich_covariance(J: np.ndarray, S: np.ndarray, noise_var: np.ndarray,
                        row_var: np.ndarray | None = None) -> np.ndarray:
    """Covariance (B, 6, 6) of the weighted fit with per-axis noise `noise_var` (B, 3), or (B, m, 3) per row.

    ``H^-1 J^T Sigma J H^-1`` with ``H = J^T J`` and ``Sigma`` the row covariance implied
    by independent per-axis noise of each window mean (or `row_var` (B, m), when given).
    """
    H = np.einsum("bmi,bmj->bij", J, J)
    # Rows of one static window share no noise across axes, and windows are independent,
    # so Sigma is diagonal: sum_j S_rj^2 sigma_j^2.
    sigma_rows = row_var if row_var is not None else np.einsum(
        "bmj,bmj->bm" if noise_var.ndim == 3 else "bmj,bj->bm", S * S, noise_var)
    meat = np.einsum("bmi,bm,bmj->bij", J, sigma_rows, J)
    Hinv = np.linalg.inv(H)
    return Hinv @ meat @ Hinv


def initial_guess(obs: ObservationSet) -> np.ndarray:
    """Per-axis linear start (B, 6), ignoring misalignment.

    For windows turning mainly about axis j, ``m_j = s omega / k_j - b_j``; static windows
    give ``m_j = -b_j``. Each axis is then a two-unknown linear fit in ``(1/k_j, b_j)``.
    """
    B = obs.mean.shape[0]
    p0 = np.empty((B, 6))
    require_every_axis(obs.mean[0], obs.static)
    dominant = np.abs(obs.mean).argmax(axis=-1)
    for j in range(3):
        on_axis = (dominant == j) & ~obs.static  # (B, n)
        use = on_axis | obs.static
        x = np.where(on_axis, np.sign(obs.mean[..., j]) * obs.rate, 0.0)  # signed reference
        w = use * obs.count
        A = np.stack([x, -np.ones_like(x)], axis=-1) * np.sqrt(w)[..., None]
        y = obs.mean[..., j] * np.sqrt(w)
        AtA = np.einsum("bni,bnj->bij", A, A)
        if np.linalg.matrix_rank(AtA[0]) < 2:
            raise DegenerateDesignError(
                f"the {'xyz'[j]} axis has one rotation and no static window, so its bias and scale "
                "cannot be separated; turn both ways or add a static window"
            )
        c, neg_b = np.linalg.solve(AtA, np.einsum("bni,bn->bi", A, y)[..., None])[..., 0].T
        p0[:, j], p0[:, 3 + j] = 1.0 / c, neg_b
    return p0


def first_moment_batch(
    obs: ObservationSet,
    *,
    noise_var=None,
    max_iter: int = 100,
    closed_form: bool = True,
) -> BatchFit:
    """Fit ``(k, b)`` from first-moment equations for every gyro of a batch.

    Parameters
    ----------
    obs : ObservationSet
        Rotation windows (speed or angle reference) and static windows.
    noise_var : array_like, shape (3,) or (B, 3), optional
        Known per-sample noise variance [reading units^2]; estimated from the data when
        omitted (:func:`estimate_noise_var`).
    max_iter : int
        Most Levenberg–Marquardt iterations.
    closed_form : bool
        With exactly six rotation windows and no static window, solve the six equations
        directly (one 6x6 inverse and a scalar Newton iteration per gyro; see
        :mod:`gyrocal.estimators._exact6`), which gives the least-squares solution at a
        fraction of the cost. Gyros it cannot solve fall back to Levenberg–Marquardt.
        ``False`` always uses Levenberg–Marquardt. ``iterations`` counts Newton steps on
        ``beta0`` for the closed form and LM steps otherwise.
    """
    obs = obs.as_batch()
    n_rot, n_sta = int((~obs.static).sum()), int(obs.static.sum())
    require_count(n_rot + 3 * n_sta, f"{n_rot} rotation and {n_sta} static window(s)")
    if not (closed_form and n_rot == 6 and n_sta == 0 and obs.mean_var is None and obs.rate_var is None):
        return _lm_fit(obs, _noise_var(obs, noise_var), max_iter)
    initial_guess(obs.take([0]))  # the design checks, with their specific messages
    # Without a known noise level, the closed form estimates it chunk by chunk, in cache.
    known = None if noise_var is None else _noise_var(obs, noise_var)
    k, b, cov, steps, ok, resid, history, nv = exact_six(obs.mean, obs.rate, obs.count, known, obs.noise_var)
    ok &= steps <= max_iter
    if not ok.all():
        rest = _lm_fit(obs.take(~ok), nv[~ok], max_iter)
        k[~ok], b[~ok], cov[~ok], steps[~ok] = rest.k, rest.b, rest.covariance, rest.iterations
        resid[~ok] = rest.residuals
        depth = max(history.shape[1], rest.history.shape[1])
        history = _pad_history(history, depth)
        history[~ok] = _pad_history(rest.history, depth)
    _, J, _ = residuals_and_jacobian(np.concatenate([k[:1], b[:1]], axis=1), obs.take([0]))
    require_full_rank(J[0], PARAM_NAMES, "the windows")
    return BatchFit(
        method="first-moment", k=k, b=b, iterations=steps, converged=np.ones(len(k), dtype=bool), residuals=resid,
        covariance=cov, noise_std=np.sqrt(nv), history=history,
    )


def _pad_history(history: np.ndarray, depth: int) -> np.ndarray:
    """(B, depth, P) history, repeating the final row."""
    extra = depth - history.shape[1]
    return np.concatenate([history, np.repeat(history[:, -1:], extra, axis=1)], axis=1) if extra else history


def _noise_var(obs: ObservationSet, noise_var) -> np.ndarray:
    if noise_var is None:
        return estimate_noise_var(obs)
    nv = np.broadcast_to(np.asarray(noise_var, dtype=float), (obs.batch_size, 3))
    if not np.all(np.isfinite(nv)) or np.any(nv < 0):
        raise InputError(f"noise_var must be finite and >= 0 with shape (3,) or (B, 3), got {noise_var!r}")
    return nv


def _lm_fit(obs: ObservationSet, nv: np.ndarray, max_iter: int) -> BatchFit:
    """The general path: Levenberg–Marquardt from the per-axis linear start.

    With measured window-mean variances (``obs.mean_var``) the rows are weighted by their own
    noise (at the start point), so the weighted residuals are in noise units; otherwise by
    ``sqrt(count)``.
    """
    p0 = initial_guess(obs)
    nu, scale = nv, None
    if obs.mean_var is not None or obs.rate_var is not None:
        nu = row_noise_var(obs, nv)
        _, _, S0 = residuals_and_jacobian(p0, obs)
        scale = 1.0 / np.sqrt(row_variance(obs, S0, nu))

    def fun(p):
        return residuals_and_jacobian(p, obs, scale)[:2]
    p, iterations, converged, residuals, history = batched_lm(fun, p0, max_iter=max_iter)
    require_converged(converged, iterations, "first-moment least squares")
    # The norm equations cannot see the sign of k; a positive scale is the physical one.
    p[:, :3] = np.abs(p[:, :3])
    history[..., :3] = np.abs(history[..., :3])
    require_positive_k2(p[:, :3] ** 2, "first-moment least squares")
    _, J, S = residuals_and_jacobian(p, obs, scale)
    require_full_rank(J[0], PARAM_NAMES, "the windows")
    return BatchFit(
        method="first-moment", k=p[:, :3], b=p[:, 3:], iterations=iterations, converged=converged,
        residuals=residuals, covariance=sandwich_covariance(J, S, nu, row_variance(obs, S, nu, scale)),
        noise_std=np.sqrt(nv), history=history,
    )


@dataclass(frozen=True)
class FirstMoment:
    """The first-moment estimator: unbiased scale and bias with a covariance.

    Parameters
    ----------
    noise_std : float or array_like of shape (3,), optional
        Known per-sample white-noise standard deviation [reading units], for example
        from ``gyrocal noise``. Estimated from the windows when omitted.
    max_iter : int
        Most Levenberg–Marquardt iterations (and Newton steps of the closed form).
    closed_form : bool
        Solve exactly-determined problems (six rotation windows) in closed form; see
        :func:`first_moment_batch`.
    """

    noise_std: float | tuple[float, float, float] | None = None
    max_iter: int = 100
    closed_form: bool = True

    def _noise_var(self):
        return None if self.noise_std is None else np.broadcast_to(np.square(np.asarray(self.noise_std, float)), (3,))

    def fit(self, obs: ObservationSet) -> FitResult:
        """Estimate one gyro's scale factors and biases, with their covariance."""
        return self.fit_batch(obs.as_batch()).item(0)

    def fit_batch(self, obs: ObservationSet) -> BatchFit:
        """Estimate every gyro of a batch."""
        return first_moment_batch(obs, noise_var=self._noise_var(), max_iter=self.max_iter,
                                  closed_form=self.closed_form)
