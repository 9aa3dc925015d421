"""Levenberg–Marquardt on the servo method's regression model: the paper's comparison."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..observations import ObservationSet
from ._checks import require_converged
from ._lm import batched_lm
from ._result import BatchFit, FitResult
from .paper_model import beta_to_kb, gamma, gamma_gradient, kb_covariance, kb_history, regressors

__all__ = ["PaperLM", "paper_lm_batch"]


def paper_lm_batch(obs: ObservationSet, *, max_iter: int = 100) -> BatchFit:
    """Minimise ``sum (x_i . beta + beta0(beta) - y_i)^2`` over ``beta`` for every gyro.

    Starts from Algorithm 1's initial estimate (``beta0 = 0``).
    """
    X, Y = regressors(obs)
    beta0 = np.linalg.solve(np.einsum("bni,bnj->bij", X, X), np.einsum("bni,bn->bi", X, Y)[..., None])[..., 0]

    def fun(beta):
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.einsum("bni,bi->bn", X, beta) + gamma(beta)[:, None] - Y
            return r, X + gamma_gradient(beta)[:, None, :]

    beta, iterations, converged, residuals, history = batched_lm(fun, beta0, max_iter=max_iter)
    require_converged(converged, iterations, "Levenberg-Marquardt")
    k, b = beta_to_kb(beta, "Levenberg-Marquardt")
    cov, nv = kb_covariance(beta, obs, X)
    return BatchFit(
        method="lm", k=k, b=b, iterations=iterations, converged=converged, residuals=residuals,
        covariance=cov, noise_std=np.sqrt(nv), history=kb_history(history),
    )


@dataclass(frozen=True)
class PaperLM:
    """Levenberg–Marquardt on the model of the servo method of Wang et al. (eq. 4 with ``beta0`` tied to ``beta``)."""

    max_iter: int = 100

    def fit(self, obs: ObservationSet) -> FitResult:
        """Estimate one gyro's scale factors and biases."""
        return self.fit_batch(obs.as_batch()).item(0)

    def fit_batch(self, obs: ObservationSet) -> BatchFit:
        """Estimate every gyro of a batch."""
        return paper_lm_batch(obs, max_iter=self.max_iter)
