"""The noise model of the gyro's equations, with the still poses' noise carried through both fits.

The gyro's pose-pair equations use gravity directions computed from the pose means with the
fitted accelerometer, and the accelerometer was fitted from the same pose means. A pose mean's
noise therefore reaches the gyro twice: directly (the direction of that pose) and through the
accelerometer's parameters (every direction, a common error of the frame). The equations are
then correlated:

    S = diag(own) + D Su D^T,

with ``own`` the variance of each normalised equation that does not come from the pose means
(gyro noise, Earth rate), ``Su`` the pose means' covariance and ``D`` the total derivative of the
equations with respect to the pose means. The gyro is fitted by generalised least squares, on
equations whitened by ``S`` (:func:`whitener`), so a common error of the frame is not taken for
a dozen independent ones, and its covariance is the usual ``(J^T S^-1 J)^-1``.
"""

from __future__ import annotations

import numpy as np

from ._gyro_problem import GyroProblem, tangent_basis
from .accel import AccelFit, directions_of

__all__ = ["noise_model", "whitener"]


def _direction_jacobian(prob: GyroProblem, a, b, g, directions, directions_std) -> np.ndarray:
    """d (normalised pair equations) / d (pose directions): (2P, n, 3)."""
    n_pairs, n = len(prob.pairs), len(directions)
    out = np.zeros((2 * n_pairs, n, 3))
    if not n_pairs:
        return out
    from .. import quaternion as quat

    rot = quat.attitude_matrices(prob.t_cat, prob.omega_params(a, b, g), prob.bounds)
    e1, e2 = tangent_basis(directions[prob.pairs[:, 1]])
    sig = prob.pair_sigma(a, directions_std)
    for k, (i, j) in enumerate(prob.pairs):
        e = np.stack([e1[k], e2[k]]) / sig[k]
        out[2 * k:2 * k + 2, i] += e @ rot[k].T   # the first direction, carried by the attitude change
        out[2 * k:2 * k + 2, j] -= e              # the second: the residual is its miss across it
    return out


def _pose_derivative(accel: AccelFit, means: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """d (direction of pose p) / d (mean of pose q): directly, and through the accelerometer's parameters.

    Returns the two (n, 3, n, 3) arrays; their sum is the total derivative.
    """
    n = len(means)
    f = accel.correct(means)
    norm = np.linalg.norm(f, axis=1)
    v = f / norm[:, None]
    out = np.zeros((n, 3, n, 3))
    direct = (np.eye(3) - v[:, :, None] * v[:, None, :]) @ accel.matrix / norm[:, None, None]
    out[np.arange(n), :, np.arange(n), :] = direct
    p = accel.params
    dv_da = np.empty((n, 3, p.size))
    for k in range(p.size):
        h = 1e-6 * max(abs(p[k]), 1e-3 * np.abs(p).max())
        dp = np.zeros_like(p)
        dp[k] = h
        dv_da[:, :, k] = (directions_of(accel, p + dp, means) - directions_of(accel, p - dp, means)) / (2 * h)
    return out, np.einsum("pik,kqj->piqj", dv_da, accel.gain)


def noise_model(prob: GyroProblem, unpacked, accel: AccelFit, means: np.ndarray) -> np.ndarray:
    """Covariance ``S`` of the normalised equations under the noise model (m, m).

    The groups' noise factors scale both a residual and its normalisation, so ``S`` is the
    factor-free model: each equation's own noise (gyro, Earth rate) on the diagonal plus the
    pose means' noise carried through the directions and the accelerometer (``D Su D^T``).
    """
    a, b, g = unpacked
    factors = prob.factors
    prob.factors = np.ones(3)
    try:
        d_std = accel.direction_std
        n_static, n_pairs = prob.means.size, len(prob.pairs)
        m = n_static + 2 * n_pairs + 3 * len(prob.turns)
        own = np.ones(m)
        d, d_via = np.zeros((m, means.size)), np.zeros((m, means.size))
        if n_pairs:
            dir_var = d_std[prob.pairs[:, 0]] ** 2 + d_std[prob.pairs[:, 1]] ** 2
            own[n_static:n_static + 2 * n_pairs] = np.repeat(1.0 - dir_var / prob.pair_sigma(a, d_std) ** 2, 2)
            dv = _direction_jacobian(prob, a, b, g, accel.directions, d_std).reshape(2 * n_pairs, -1)
            direct, via = (x.reshape(means.size, means.size) for x in _pose_derivative(accel, means))
            d[n_static:n_static + 2 * n_pairs] = dv @ (direct + via)
            d_via[n_static:n_static + 2 * n_pairs] = dv @ via
    finally:
        prob.factors = factors
    su = accel.pose_se.ravel() ** 2
    # an accelerometer fit that scatters beyond its noise (hand-placed faces, for one) has its parameters'
    # covariance scaled up; that extra reaches the directions through the parameters only
    extra = accel.fit.birge_ratio**2 - 1.0 if accel.fit.covariance_scaled else 0.0
    return np.diag(own) + (d * su) @ d.T + extra * (d_via * su) @ d_via.T


def whitener(s: np.ndarray) -> np.ndarray:
    """``L^-1`` with ``S = L L^T``: whitened equations ``L^-1 r`` are independent with unit variance."""
    from scipy.linalg import solve_triangular

    scale = float(np.max(np.diag(s)))
    lower = np.linalg.cholesky(s + 1e-12 * scale * np.eye(len(s)))
    return solve_triangular(lower, np.eye(len(s)), lower=True)
