"""The servo method of Wang et al., Algorithm 1: the iterative linear least-squares method, as published."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..observations import ObservationSet
from ._checks import require_converged, require_positive_k2
from ._result import BatchFit, FitResult
from .paper_model import beta_to_kb, gamma, kb_covariance, kb_history, regressors

__all__ = ["Algorithm1", "algorithm1_batch"]


def algorithm1_batch(obs: ObservationSet, *, tol: float = 1e-6, max_iter: int = 100) -> BatchFit:
    """Run Algorithm 1 on every gyro of a batch.

    Because ``beta = (X^T X)^-1 X^T (Y - beta0)`` is linear in the scalar ``beta0``,
    one solve gives ``u = P Y`` and ``v = P 1`` and each iteration is
    ``beta = u - gamma(beta) v``: the published iteration, at the cost of a scalar update.

    Parameters
    ----------
    obs : ObservationSet
        Six or more windows, optionally batched.
    tol : float
        Stop when ``sum |beta(n+1) - beta(n)| < tol`` (the paper uses 1e-6).
    max_iter : int
        Most ``beta0`` updates before :class:`~gyrocal.errors.ConvergenceError`.
    """
    X, Y = regressors(obs)
    rhs = np.stack([Y, np.ones_like(Y)], axis=-1)
    if X.shape[1] == X.shape[2]:
        uv = np.linalg.solve(X, rhs)  # six windows: (X^T X)^-1 X^T = X^-1, one solve fewer
    else:
        Xt = X.transpose(0, 2, 1)
        uv = np.linalg.solve(Xt @ X, Xt @ rhs)
    u, v = uv[..., 0], uv[..., 1]
    beta = u.copy()  # beta0 = 0: the initial estimate
    history = [beta.copy()]
    B = len(beta)
    iterations = np.zeros(B, dtype=int)
    active = np.ones(B, dtype=bool)
    for _ in range(max_iter):
        require_positive_k2(beta[active, :3], "Algorithm 1")
        new = u - gamma(beta)[:, None] * v
        delta = np.abs(new - beta).sum(axis=1)
        beta = np.where(active[:, None], new, beta)
        iterations += active
        active &= delta >= tol
        history.append(beta.copy())
        if not active.any():
            break
    require_converged(~active, iterations, "Algorithm 1")
    k, b = beta_to_kb(beta, "Algorithm 1")
    residuals = (X @ beta[..., None])[..., 0] + gamma(beta)[:, None] - Y
    cov, nv = kb_covariance(beta, obs, X)
    return BatchFit(
        method="algorithm1", k=k, b=b, iterations=iterations, converged=~active, residuals=residuals,
        covariance=cov, noise_std=np.sqrt(nv), history=kb_history(np.stack(history)).transpose(1, 0, 2),
    )


@dataclass(frozen=True)
class Algorithm1:
    """The servo method of Wang et al., Algorithm 1 on the mean-of-squares regression (eq. 4–8).

    Parameters
    ----------
    tol : float
        Convergence threshold on ``sum |delta beta|`` (paper: 1e-6).
    max_iter : int
        Most iterations.

    Notes
    -----
    With exactly six observations the fixed point solves the six equations exactly,
    so it equals the Levenberg–Marquardt solution. With more, it ignores
    ``d beta0 / d beta`` and stops short of the least-squares optimum. The
    regressors average ``m^2``, which adds the noise power to every observation and
    biases the scale factors low (see :class:`~gyrocal.estimators.FirstMoment`).
    """

    tol: float = 1e-6
    max_iter: int = 100

    def fit(self, obs: ObservationSet) -> FitResult:
        """Estimate one gyro's scale factors and biases."""
        return self.fit_batch(obs.as_batch() if not obs.batched else obs).item(0)

    def fit_batch(self, obs: ObservationSet) -> BatchFit:
        """Estimate every gyro of a batch."""
        return algorithm1_batch(obs, tol=self.tol, max_iter=self.max_iter)
