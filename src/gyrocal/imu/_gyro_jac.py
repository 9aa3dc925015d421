"""The analytic Jacobian of the gyro's equations (:mod:`gyrocal.imu._gyro_problem`) from one integration.

A finite-difference Jacobian integrates every attitude change once or twice per parameter; here the
attitude of each pose pair is integrated once, with its sensitivity to the rates of every sample.

Each step ``k`` of an interval rotates by ``R_k = exp([phi_k]x)`` (the trapezoid-plus-coning
rotation vector of :func:`gyrocal.quaternion.step_rotvecs`), and the interval by
``R = R_0 R_1 ... R_{n-1}``. A change ``d phi_k`` turns ``R_k`` into ``R_k exp([J_r(phi_k) d phi_k]x)``
(``J_r`` the right Jacobian of the rotation group), and so ``R`` into ``R exp([d theta]x)`` with

    d theta = R^T sum_k P_k J_r(phi_k) d phi_k,        P_k = R_0 ... R_k,

to first order (the R^T is applied once, to the sums). ``d phi_k`` is linear in the rates of samples ``k`` and ``k + 1``, and the rates
``A (m - b - G f)`` are linear in each of ``A``, ``b`` and ``G``; the prefix products ``P_k`` are
one blocked scan. The predicted direction ``R^T d`` then moves by ``(R^T d) x d theta``.
"""

from __future__ import annotations

import numpy as np

from .. import quaternion as quat
from .._arrays import distinct
from ._gyro_problem import EARTH_RATE, GyroProblem, tangent_basis

__all__ = ["residual_jacobian"]

#: Columns of the parameters in the full layout (A row-major, b, G row-major).
_A, _B, _G = slice(0, 9), slice(9, 12), slice(12, 21)
_DIAG = np.array([0, 4, 8])


def _skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrices ``[v]x`` (..., 3, 3) of vectors (..., 3)."""
    x, y, z = np.moveaxis(v, -1, 0)
    o = np.zeros_like(x)
    return np.stack([np.stack([o, -z, y], -1), np.stack([z, o, -x], -1), np.stack([-y, x, o], -1)], -2)


def right_jacobian(phi: np.ndarray) -> np.ndarray:
    """``J_r(phi) = I - (1 - cos a)/a^2 [phi]x + (a - sin a)/a^3 [phi]x^2`` (..., 3, 3), ``a = |phi|``,
    with ``[phi]x^2 = phi phi^T - a^2 I``."""
    a2 = np.einsum("...i,...i->...", phi, phi)
    small = a2 < 1e-4
    a = np.sqrt(np.where(small, 1.0, a2))
    # both coefficients by their series for small angles: exact to double precision and free of 0/0
    c1 = np.where(small, 0.5 - a2 / 24 + a2**2 / 720, (1 - np.cos(a)) / a**2)
    c2 = np.where(small, 1 / 6 - a2 / 120 + a2**2 / 5040, (a - np.sin(a)) / a**3)
    out = (c2[..., None, None] * phi[..., :, None]) * phi[..., None, :] - c1[..., None, None] * _skew(phi)
    out += (1 - c2 * a2)[..., None, None] * np.eye(3)
    return out


def prefix_products(m: np.ndarray) -> np.ndarray:
    """Inclusive ordered products ``m[:, 0] @ ... @ m[:, k]`` along axis 1 of (P, L, 3, 3).

    A blocked scan: about ``sqrt(L)`` batched products inside blocks, then as many carrying each
    block's product into the next, instead of ``L`` sequential ones.
    """
    n_int, length = m.shape[:2]
    size = max(1, int(np.ceil(np.sqrt(length))))
    blocks = -(-length // size)
    pad = np.broadcast_to(np.eye(3), (n_int, blocks * size - length, 3, 3))
    x = np.concatenate([m, pad], axis=1).reshape(n_int, blocks, size, 3, 3)
    for i in range(1, size):
        x[:, :, i] = x[:, :, i - 1] @ x[:, :, i]
    for j in range(1, blocks):
        x[:, j] = x[:, j - 1, -1][:, None] @ x[:, j]
    return x.reshape(n_int, blocks * size, 3, 3)[:, :length]


def _padded(bounds: np.ndarray, prob: GyroProblem, omega: np.ndarray):
    """The motion samples of the pairs of `bounds` as rows of (P, L + 1): times (held at the last one
    after the end, so padded steps last no time), rates (zero after the end), the index into the
    concatenation, and the mask (P, L + 1, 1) of real samples."""
    steps = bounds[:, 1] - bounds[:, 0]
    cols = np.arange(int(steps.max(initial=0)) + 1)
    valid = cols[None, :] <= steps[:, None]
    idx = np.minimum(bounds[:, :1] + cols[None, :], bounds[:, 1:])
    t = prob.t_cat[idx]
    keep = valid[..., None]
    return t, np.where(keep, omega[idx], 0.0), idx, keep


def _pair_theta(prob: GyroProblem, a, b, g, with_g: bool):
    """Attitude change of each pair (P, 3, 3) and ``d theta / d params`` (P, 3, 12 or 21).

    Pairs are taken in groups of similar length (by the power of two above it), so that padding
    at most doubles the work and the memory, as in :func:`gyrocal.quaternion.attitude_matrices`.
    """
    omega = prob.omega_params(a, b, g)
    steps = prob.bounds[:, 1] - prob.bounds[:, 0]
    group = np.ceil(np.log2(np.maximum(steps, 1))).astype(int)
    rot = np.broadcast_to(np.eye(3), (len(steps), 3, 3)).copy()
    dtheta = np.zeros((len(steps), 3, 21 if with_g else 12))
    for k in distinct(group):
        members = np.flatnonzero(group == k)
        rot[members], dtheta[members] = _group_theta(prob.bounds[members], prob, omega, a, b, g, with_g)
    return rot, dtheta


def _group_theta(bounds, prob: GyroProblem, omega, a, b, g, with_g: bool):
    """:func:`_pair_theta` of the pairs of `bounds`."""
    t, w, idx, keep = _padded(bounds, prob, omega)
    h = np.diff(t, axis=1)[..., None]
    w0, w1 = w[:, :-1], w[:, 1:]
    phi = h * 0.5 * (w0 + w1) + (h * h / 12.0) * np.cross(w0, w1)
    n_int, n_samp = t.shape
    pre = prefix_products(quat.rotvec_matrix(phi))
    rot = pre[:, -1] if pre.shape[1] else np.broadcast_to(np.eye(3), (n_int, 3, 3))
    v = pre @ right_jacobian(phi)
    # d phi_k = (h/2 - h^2/12 [w1]x) d w0 + (h/2 + h^2/12 [w0]x) d w1, and the rows of V [w]x are V_a x w
    half, cone = (h * 0.5)[..., None], (h * h / 12.0)[..., None]
    m = np.zeros((n_int, n_samp, 3, 3))
    m[:, :-1] += half * v - cone * np.cross(v, w1[:, :, None, :])
    m[:, 1:] += half * v + cone * np.cross(v, w0[:, :, None, :])
    m_t = np.swapaxes(m.reshape(n_int, n_samp, 9), 1, 2)  # (P, 9, L + 1): sums over samples as products
    u = np.where(keep, prob.m_cat[idx] - b, 0.0)
    f = np.where(keep, prob.f_cat[idx], 0.0)
    if g is not None:
        u = u - f @ g.T
    rot_t = np.swapaxes(rot, -1, -2)
    parts = [rot_t @ (m_t @ u).reshape(n_int, 3, 9), -rot_t @ m.sum(axis=1) @ a]
    if with_g:
        nf = (m_t @ f).reshape(n_int, 3, 3, 3)
        parts.append(-rot_t @ np.einsum("pabl,bi->pail", nf, a).reshape(n_int, 3, 9))
    return rot, np.concatenate(parts, axis=2)


def _sigma_term(r, sd, w2, a, prob: GyroProblem) -> np.ndarray:
    """``d r / d A_ii`` (rows, 3) through the noise ``sd`` of equations ``r``, which grows with the mean
    squared diagonal of ``A`` (the gyro noise in rad)."""
    return -(r * (prob.lrv * w2 / (3 * sd**2)))[:, None] * np.diag(a)[None, :]


def _pair_rows(prob: GyroProblem, a, b, g, with_g, directions, directions_std, n_cols) -> np.ndarray:
    n_pairs = len(prob.pairs)
    if not n_pairs:
        return np.zeros((0, n_cols))
    rot, dtheta = _pair_theta(prob, a, b, g, with_g)
    pred = np.einsum("pji,pj->pi", rot, directions[prob.pairs[:, 0]])
    sig = prob.pair_sigma(a, directions_std)
    rows = []
    for e in tangent_basis(directions[prob.pairs[:, 1]]):
        r = np.einsum("pi,pi->p", pred, e) / sig
        jr = np.einsum("pa,pak->pk", np.cross(e, pred) / sig[:, None], dtheta)
        jr[:, _DIAG] += _sigma_term(r, sig, prob.factors[1] ** 2 * prob.pair_lrv_w2, a, prob)
        rows.append(jr)
    return np.stack(rows, axis=1).reshape(2 * n_pairs, -1)


def _turn_rows(prob: GyroProblem, a, b, g, with_g, n_cols) -> np.ndarray:
    n_turns = len(prob.turns)
    if not n_turns:
        return np.zeros((0, n_cols))
    c = prob.turn_m - prob.turn_time[:, None] * b - (0 if g is None else prob.turn_f @ g.T)
    eye = np.eye(3)
    parts = [np.einsum("ij,tl->tijl", eye, c).reshape(n_turns, 3, 9), -prob.turn_time[:, None, None] * a]
    if with_g:
        parts.append(np.einsum("ij,tl->tijl", -a, prob.turn_f).reshape(n_turns, 3, 9))
    scale2 = float(np.mean(np.diag(a) ** 2))
    axis = np.array([(t.angle * t.axis_std) ** 2 for t in prob.turns])
    sd = prob.factors[2] * np.sqrt(prob.lrv * scale2 * prob.turn_w2 + axis
                                   + (EARTH_RATE * prob.turn_time) ** 2 / 3)
    out = np.concatenate(parts, axis=2) / sd[:, None, None]
    r = prob.turn_residuals(a, b, g).reshape(-1, 3)
    for i in range(3):
        out[:, i, _DIAG] += _sigma_term(r[:, i], sd, prob.factors[2] ** 2 * prob.turn_w2, a, prob)
    return out.reshape(3 * n_turns, -1)


def _static_rows(prob: GyroProblem, with_g, n_cols) -> np.ndarray:
    n = len(prob.means)
    sd = prob.static_sd * prob.factors[0]
    out = np.zeros((n, 3, n_cols))
    for i in range(3):
        out[:, i, 9 + i] = -1.0 / sd[:, i]
        if with_g:
            out[:, i, 12 + 3 * i:15 + 3 * i] = -prob.f_static / sd[:, i:i + 1]
    return out.reshape(3 * n, n_cols)


def residual_jacobian(prob: GyroProblem, mask: np.ndarray, with_g: bool, a, b, g, directions,
                      directions_std) -> np.ndarray:
    """``d residuals / d params`` of :func:`gyrocal.imu._gyro_solve.residuals` (equations, parameters).

    `mask` (3, 3) bool selects the fitted entries of ``A`` (row-major), followed by ``b`` and, with
    `with_g`, ``G`` (row-major), the order of the parameter vector.
    """
    n_cols = 21 if with_g else 12
    full = np.concatenate([_static_rows(prob, with_g, n_cols),
                           _pair_rows(prob, a, b, g, with_g, directions, directions_std, n_cols),
                           _turn_rows(prob, a, b, g, with_g, n_cols)])
    cols = np.concatenate([np.flatnonzero(np.asarray(mask).ravel()), np.arange(9, n_cols)])
    return full[:, cols]
