"""The servo method's linear regression form, shared by Algorithm 1 and its LM comparison.

Eq. 4: ``y = beta0 + sum_j beta_j x_j`` with regressors ``x = (mean m^2, mean m)``
per window (eq. 8), response ``y = omega^2``, and ``beta0 = sum beta_{j+3}^2 / (4 beta_j)``.
"""

from __future__ import annotations

import numpy as np

from ..observations import ObservationSet
from ._checks import require_count, require_every_axis, require_full_rank, require_positive_k2
from ._noise import estimate_noise_var

BETA_NAMES = ("beta1", "beta2", "beta3", "beta4", "beta5", "beta6")


def regressors(obs: ObservationSet) -> tuple[np.ndarray, np.ndarray]:
    """Eq. 7 and 8: X (B, n, 6) ``[m_x^2, m_y^2, m_z^2, m_x, m_y, m_z]`` (window means) and Y (B, n)."""
    obs = obs.as_batch()
    require_count(len(obs), f"{len(obs)} observation(s)")
    require_every_axis(obs.mean[0], obs.static)
    X = np.concatenate([obs.mean_sq, obs.mean], axis=-1)
    require_full_rank(X[0], BETA_NAMES, "the observations")
    return X, obs.rate**2


def gamma(beta: np.ndarray) -> np.ndarray:
    """``beta0`` implied by ``beta`` (B, 6): ``sum beta_{j+3}^2 / (4 beta_j)``."""
    return np.sum(beta[:, 3:] ** 2 / (4.0 * beta[:, :3]), axis=1)


def beta_to_kb(beta: np.ndarray, method: str) -> tuple[np.ndarray, np.ndarray]:
    """Algorithm 1's return step: ``k = sqrt(beta_1..3)``, ``b = beta_4..6 / (2 beta_1..3)``."""
    require_positive_k2(beta[..., :3], method)
    return np.sqrt(beta[..., :3]), beta[..., 3:] / (2.0 * beta[..., :3])


def kb_history(beta_history: np.ndarray) -> np.ndarray:
    """(k, b) rows from beta rows, leaving non-physical rows as NaN."""
    b1 = beta_history[..., :3]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.concatenate([np.sqrt(b1), beta_history[..., 3:] / (2.0 * b1)], axis=-1)


def gamma_gradient(beta: np.ndarray) -> np.ndarray:
    """``d beta0 / d beta`` (B, 6)."""
    return np.concatenate([-beta[:, 3:] ** 2 / (4 * beta[:, :3] ** 2), beta[:, 3:] / (2 * beta[:, :3])], axis=1)


def paper_row_var(beta: np.ndarray, obs: ObservationSet, nv: np.ndarray) -> np.ndarray:
    """Variance (B, n) of each row ``beta0 + x . beta - y`` under white noise of variance `nv` (B, 3).

    See :func:`kb_covariance` for the derivation.
    """
    obs = obs.as_batch()
    b1, b2 = beta[:, None, :3], beta[:, None, 3:]
    s2 = nv[:, None, :]
    return np.sum(s2 * ((2 * b1 * obs.mean + b2) ** 2 + 2 * b1**2 * s2), axis=-1) / obs.count


def kb_covariance(beta: np.ndarray, obs: ObservationSet, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Covariance (B, 6, 6) of ``(k, b)`` from the regression, and the noise variance (B, 3) used.

    White noise of variance ``s_j^2`` per sample moves a window's ``mean m_j`` by
    ``s_j^2 / n`` and its ``mean m_j^2`` by ``(4 mu_j^2 s_j^2 + 2 s_j^4) / n``, the two
    correlated by ``2 mu_j s_j^2 / n``. A row ``beta0 + x . beta - y`` therefore has variance
    ``sum_j s_j^2 ((2 beta_j mu_j + beta_{j+3})^2 + 2 beta_j^2 s_j^2) / n``. The least-squares
    sandwich gives the covariance of ``beta``, and the delta method that of ``(k, b)``. It is
    the spread over noise draws; the bias of the mean-of-squares form (docs/core.md, Accuracy) comes on top.
    """
    obs = obs.as_batch()
    nv = estimate_noise_var(obs)
    row_var = paper_row_var(beta, obs, nv)
    J = X + gamma_gradient(beta)[:, None, :]  # X: the regressors (B, n, 6) of :func:`regressors`
    # d beta = A e with e the rows' unit-variance errors: A = J^-1 sqrt(row_var) (square J), else H^-1 J^T sqrt(..)
    if J.shape[1] == J.shape[2]:
        A = np.linalg.inv(J)
    else:
        Jt = J.transpose(0, 2, 1)
        A = np.linalg.solve(np.einsum("bmi,bmj->bij", J, J), Jt)
    A *= np.sqrt(row_var)[:, None, :]
    # to (k, b): k = sqrt(beta_1..3), b = beta_4..6 / (2 beta_1..3); rows of A are d beta per error
    L = np.empty_like(A)
    L[:, :3] = A[:, :3] / (2 * np.sqrt(beta[:, :3]))[..., None]
    L[:, 3:] = (A[:, 3:] - (beta[:, 3:] / beta[:, :3])[..., None] * A[:, :3]) / (2 * beta[:, :3])[..., None]
    return np.einsum("bik,bjk->bij", L, L), nv
