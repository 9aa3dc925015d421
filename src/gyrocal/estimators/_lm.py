"""A Levenberg–Marquardt solver vectorised over a batch of small problems.

Every batch item is an independent least-squares problem with the same number of
residuals and parameters; one call solves them all with batched linear algebra.
A single problem is a batch of one, so there is one code path.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

ResidualJacobian = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]


def batched_lm(
    fun: ResidualJacobian,
    p0: np.ndarray,
    *,
    max_iter: int = 100,
    xtol: float = 1e-12,
    gtol: float = 1e-12,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Minimise ``sum(r(p)**2)`` for every batch item.

    Parameters
    ----------
    fun : callable
        ``fun(p) -> (r, J)`` with ``p`` (B, P), ``r`` (B, m) and ``J`` (B, m, P).
    p0 : ndarray, shape (B, P)
        Starting point.
    max_iter : int
        Most iterations per item.
    xtol, gtol : float
        Converged when an accepted step's norm is below ``xtol`` relative to ``||p||``, or when
        the gradient is orthogonal to the residual within ``gtol`` (MINPACK's test).

    Returns
    -------
    p, iterations, converged, residuals, history
        ``history`` is (B, n_iter + 1, P), initial point first.
    """
    p = np.array(p0, dtype=float)
    B, P = p.shape
    r, J = fun(p)
    cost = np.einsum("bm,bm->b", r, r)
    lam = np.full(B, 1e-3)
    iterations = np.zeros(B, dtype=int)
    converged = np.zeros(B, dtype=bool)
    done = np.zeros(B, dtype=bool)
    history = [p.copy()]
    eye = np.eye(P)
    for _ in range(max_iter):
        g = np.einsum("bmi,bm->bi", J, r)
        col = np.sqrt(np.einsum("bmi,bmi->bi", J, J))
        rnorm = np.sqrt(cost)
        flat = np.all(np.abs(g) <= gtol * col * rnorm[:, None] + 1e-300, axis=1)
        newly = ~done & flat
        converged |= newly
        done |= newly
        if done.all():
            break
        JtJ = np.einsum("bmi,bmj->bij", J, J)
        d = np.diagonal(JtJ, axis1=1, axis2=2)
        damp = lam[:, None] * (d + 1e-15 * d.max(axis=1, keepdims=True))
        dp = -np.linalg.solve(JtJ + damp[:, :, None] * eye, g[:, :, None])[:, :, 0]
        dp[done] = 0.0
        p_try = p + dp
        r_try, J_try = fun(p_try)
        cost_try = np.einsum("bm,bm->b", r_try, r_try)
        better = ~done & np.isfinite(cost_try) & (cost_try <= cost)
        p = np.where(better[:, None], p_try, p)
        r = np.where(better[:, None], r_try, r)
        J = np.where(better[:, None, None], J_try, J)
        cost = np.where(better, cost_try, cost)
        lam = np.where(better, np.maximum(lam * 0.1, 1e-12), lam * 10.0)
        iterations += ~done
        # MINPACK's test on the step norm: per-element tests never pass for a parameter near 0.
        small = np.linalg.norm(dp, axis=1) <= xtol * (np.linalg.norm(p, axis=1) + xtol)
        newly = better & small
        converged |= newly
        done |= newly | (lam > 1e16)
        history.append(p.copy())
        if done.all():
            break
    return p, iterations, converged, r, np.stack(history, axis=1)
