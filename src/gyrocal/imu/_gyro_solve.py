"""Solving the gyro's equations: start, least squares with re-weighted groups, and screening of gross outliers."""

from __future__ import annotations

import numpy as np
from scipy import stats
from scipy.optimize import least_squares

from .._arrays import median
from ..errors import DegenerateDesignError
from . import _fit
from ._gyro_cov import noise_model, whitener
from ._gyro_jac import residual_jacobian
from ._gyro_problem import GyroProblem

__all__ = ["MASKS", "initial_scale", "jacobian", "residuals", "residuals_jacobian", "screen_pairs", "solve", "unpack"]

MASKS = {"affine": np.ones((3, 3), dtype=bool), "scale": np.eye(3, dtype=bool)}
#: Re-weighting rounds of the equation groups (variance-component estimation).
_VCE_ITER = 8
#: A pose pair is left out when its misfit, in units of the pairs' robust scatter, has a p-value below this.
OUTLIER_P = 1e-4


def unpack(model, with_g, p):
    k = int(MASKS[model].sum())
    a = np.zeros((3, 3))
    a[MASKS[model]] = p[:k]
    return a, p[k:k + 3], (p[k + 3:k + 12].reshape(3, 3) if with_g else None)


def residuals(prob: GyroProblem, model, with_g, p, directions, directions_std):
    a, b, g = unpack(model, with_g, p)
    return np.concatenate([prob.static_residuals(b, g), prob.pair_residuals(a, b, g, directions, directions_std),
                           prob.turn_residuals(a, b, g)])


def residuals_jacobian(prob: GyroProblem, model, with_g, p, directions, directions_std):
    """``d residuals / d p`` of :func:`residuals`, analytic (:mod:`gyrocal.imu._gyro_jac`): one integration
    of the attitudes, where a finite difference takes two per parameter."""
    return residual_jacobian(prob, MASKS[model], with_g, *unpack(model, with_g, p), directions, directions_std)


def jacobian(fun, p: np.ndarray) -> np.ndarray:
    """Central-difference Jacobian of `fun` at `p`."""
    cols = []
    for j in range(p.size):
        h = 1e-6 * max(abs(p[j]), 1e-3 * float(np.abs(p).max()), 1e-12)
        dp = np.zeros_like(p)
        dp[j] = h
        cols.append((fun(p + dp) - fun(p - dp)) / (2 * h))
    return np.column_stack(cols)


def initial_scale(prob: GyroProblem, bias, directions, directions_std) -> float:
    """Gyro scale [rad/s per raw unit] that best joins the poses with ``A = c I``, by a grid over c.

    The grid is centred on the ratio of the tilt between poses to the integrated raw reading,
    which is below the true scale when a move also turns about the vertical.
    """
    guesses = []
    if len(prob.pairs):
        ang = np.linalg.norm(prob.pair_integrals(bias), axis=1)
        tilt = np.arccos(np.clip(np.einsum("pi,pi->p", directions[prob.pairs[:, 0]], directions[prob.pairs[:, 1]]),
                                 -1, 1))
        ok = (tilt > np.radians(20)) & (ang > 0)
        guesses += list(tilt[ok] / ang[ok])
    if prob.turns:
        norm = np.linalg.norm(prob.turn_m - prob.turn_time[:, None] * bias, axis=1)
        guesses += [t.angle / n for t, n in zip(prob.turns, norm) if n > 0]
    if not guesses:
        raise DegenerateDesignError("no turn between still poses changes the gravity direction by 20 deg or more, "
                                    "so the gyro scale cannot be found; tilt the board between poses")
    c0 = float(median(guesses))
    grid = c0 * np.exp(np.linspace(np.log(0.5), np.log(4.0), 43))  # 5 % apart
    cost = [np.sum(residuals(prob, "scale", False, np.concatenate([[c, c, c], bias]), directions,
                              directions_std) ** 2) for c in grid]
    return float(grid[int(np.argmin(cost))])


def solve(prob, model, with_g, p0, accel, means):
    """Generalised least squares, re-weighting the equation groups (poses, pairs, turns) by their own scatter.

    Sets ``prob.factors`` to the groups' noise factors (1 where the noise model holds) and returns
    ``(params, whitened residuals, whitened Jacobian, S)``; ``S`` is the equations' covariance
    under the noise model (:func:`gyrocal.imu._gyro_cov.noise_model`), the parameter covariance
    ``(J^T J)^-1`` of the whitened Jacobian.
    """
    # two groups: still poses, and every integrated turn (pose pairs and known-angle turns share the gyro's
    # integration and its unmodelled errors; three known-angle turns alone would have no spare equation)
    groups = np.repeat([0, 1], [prob.means.size, 2 * len(prob.pairs) + 3 * len(prob.turns)])
    prob.factors = np.ones(3)
    d, d_std = accel.directions, accel.direction_std

    def raw(q):
        return residuals(prob, model, with_g, q, d, d_std)

    def raw_jac(q):
        return residuals_jacobian(prob, model, with_g, q, d, d_std)

    def fit(q):
        s = noise_model(prob, unpack(model, with_g, q), accel, means)
        w = whitener(s)
        q = least_squares(lambda x: w @ raw(x), q, jac=lambda x: w @ raw_jac(x), method="lm", x_scale="jac",
                          xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=2000).x
        return q, w @ raw(q), w @ raw_jac(q), s

    p, r, jac, s = fit(p0)
    for _ in range(_VCE_ITER):
        new = _fit.group_factors(r, groups, prob.factors[:2], _fit.redundancy(jac, groups, 2))
        if np.allclose(new, prob.factors[:2], rtol=0.01):
            break
        prob.factors = new[[0, 1, 1]]
        p, r, jac, s = fit(p)
    return p, r, jac, s


def screen_pairs(prob: GyroProblem, p0, directions, directions_std) -> np.ndarray:
    """Which pose pairs to keep (P,) bool: all but gross outliers, judged from a robust fit.

    A board that moved during a pose, or a gyro that saturated, leaves one pair far off. Least
    squares bends every parameter toward it and then blames other pairs; a Cauchy-loss fit does
    not. A pair is left out when its misfit, in units of the pairs' own robust scatter (the
    median misfit, never below the noise model), has a p-value below :data:`OUTLIER_P`.
    """
    n_pairs = len(prob.pairs)
    keep = np.ones(n_pairs, dtype=bool)
    if n_pairs < 6:
        return keep
    prob.factors = np.ones(3)
    n_static = prob.means.size

    def fun(q):
        return residuals(prob, "affine", False, q, directions, directions_std)

    def jac(q):
        return residuals_jacobian(prob, "affine", False, q, directions, directions_std)

    def pair_chi2(q):
        r = fun(q)[n_static:n_static + 2 * n_pairs].reshape(-1, 2)
        return np.einsum("ij,ij->i", r, r)

    def robust_scale2(chi2):
        return max(1.0, float(median(chi2)) / stats.chi2.ppf(0.5, 2))

    p = least_squares(fun, p0, jac=jac, method="trf", x_scale="jac").x
    p = least_squares(fun, p, jac=jac, method="trf", x_scale="jac", loss="cauchy",
                      f_scale=3.0 * np.sqrt(robust_scale2(pair_chi2(p)))).x
    chi2 = pair_chi2(p)
    keep = chi2 / robust_scale2(chi2) < stats.chi2.isf(OUTLIER_P, 2)
    return keep
