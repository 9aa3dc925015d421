"""Unit quaternions and the attitude change a gyro measures between two instants.

Quaternions are arrays ``[..., 4]`` = ``(w, x, y, z)`` with Hamilton's product; ``q`` maps
body vectors to the world, ``v_world = q v_body q*``. The body rate ``omega`` [rad/s] drives
``dq/dt = q (0, omega) / 2``.

:func:`attitude_change` integrates on the real sample times: each step's rotation vector is
the trapezoid of the two end rates plus the second-order coning term of a rate that varies
linearly over the step, ``phi = h (w0 + w1) / 2 + h^2 / 12 (w0 x w1)``. The step rotations are
then multiplied as matrices in a balanced tree (one batched matrix product per level), so
integrating many intervals of a few hundred samples each costs a handful of numpy calls.
"""

from __future__ import annotations

import numpy as np

from ._arrays import distinct

__all__ = ["align_vectors", "attitude_change", "attitude_matrices", "from_matrix", "from_rotvec", "matrix_rotvec",
           "multiply", "rotate", "rotvec_matrix", "step_rotvecs", "to_matrix", "to_rotvec"]


def multiply(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product ``p q`` of quaternion arrays ``(..., 4)``."""
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack([
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    ], axis=-1)


def from_rotvec(phi: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(..., 4)`` of rotation vectors ``(..., 3)`` [rad]."""
    phi = np.asarray(phi, dtype=float)
    angle = np.linalg.norm(phi, axis=-1, keepdims=True)
    half = 0.5 * angle
    # sin(x)/x by its series below 1e-4 rad: exact to double precision and free of 0/0
    small = angle < 1e-4
    sinc = np.where(small, 0.5 - angle**2 / 48.0, np.sin(half) / np.where(small, 1.0, angle))
    return np.concatenate([np.cos(half), phi * sinc], axis=-1)


def to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` of unit quaternions ``(..., 4)`` (body to world)."""
    q = np.asarray(q, dtype=float)
    w, x, y, z = np.moveaxis(q / np.linalg.norm(q, axis=-1, keepdims=True), -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=-2)


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``q v q*``: vectors ``(..., 3)`` rotated by unit quaternions ``(..., 4)``."""
    return np.einsum("...ij,...j->...i", to_matrix(q), v)


def step_rotvecs(t: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Rotation vector of each step between samples (n - 1, 3) [rad], for rates (n, 3) [rad/s] at times t [s]."""
    h = np.diff(t)[:, None]
    w0, w1 = omega[:-1], omega[1:]
    return h * 0.5 * (w0 + w1) + (h * h / 12.0) * np.cross(w0, w1)


def rotvec_matrix(phi: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of rotation vectors (..., 3) [rad] (Rodrigues' formula)."""
    phi = np.asarray(phi, dtype=float)
    a2 = np.einsum("...i,...i->...", phi, phi)
    small = a2 < 1e-8
    a = np.sqrt(a2)
    # sin(a)/a and (1 - cos a)/a^2 by their series for small angles: exact to double precision
    s1 = np.where(small, 1 - a2 / 6, np.sin(a) / np.where(small, 1.0, a))
    s2 = np.where(small, 0.5 - a2 / 24, (1 - np.cos(a)) / np.where(small, 1.0, a2))
    c = 1 - s2 * a2
    # R = cos(a) I + sin(a)/a [phi]x + (1 - cos a)/a^2 phi phi^T
    r = s2[..., None, None] * phi[..., :, None] * phi[..., None, :]
    x, y, z = (s1 * phi[..., i] for i in range(3))
    r[..., 0, 0] += c
    r[..., 1, 1] += c
    r[..., 2, 2] += c
    r[..., 0, 1] -= z
    r[..., 1, 0] += z
    r[..., 0, 2] += y
    r[..., 2, 0] -= y
    r[..., 1, 2] -= x
    r[..., 2, 1] += x
    return r


def from_matrix(r: np.ndarray) -> np.ndarray:
    """Unit quaternions (..., 4), w >= 0, of rotation matrices (..., 3, 3) (Shepperd's method)."""
    r = np.asarray(r, dtype=float)
    tr = np.trace(r, axis1=-2, axis2=-1)
    cand = np.stack([tr, r[..., 0, 0], r[..., 1, 1], r[..., 2, 2]], axis=-1)
    k = np.argmax(cand, axis=-1)
    q = np.empty(r.shape[:-2] + (4,))
    w = np.stack([1 + tr, r[..., 2, 1] - r[..., 1, 2], r[..., 0, 2] - r[..., 2, 0], r[..., 1, 0] - r[..., 0, 1]], -1)
    x = np.stack([r[..., 2, 1] - r[..., 1, 2], 1 + 2 * r[..., 0, 0] - tr, r[..., 0, 1] + r[..., 1, 0],
                  r[..., 0, 2] + r[..., 2, 0]], -1)
    y = np.stack([r[..., 0, 2] - r[..., 2, 0], r[..., 0, 1] + r[..., 1, 0], 1 + 2 * r[..., 1, 1] - tr,
                  r[..., 1, 2] + r[..., 2, 1]], -1)
    z = np.stack([r[..., 1, 0] - r[..., 0, 1], r[..., 0, 2] + r[..., 2, 0], r[..., 1, 2] + r[..., 2, 1],
                  1 + 2 * r[..., 2, 2] - tr], -1)
    q = np.choose(k[..., None], [w, x, y, z])
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    return q * np.where(q[..., :1] < 0, -1.0, 1.0)


def to_rotvec(q: np.ndarray) -> np.ndarray:
    """Rotation vectors (..., 3) [rad], angle in [0, pi], of unit quaternions (..., 4)."""
    q = np.asarray(q, dtype=float)
    q = q * np.where(q[..., :1] < 0, -1.0, 1.0)
    xyz = q[..., 1:]
    angle = 2.0 * np.arctan2(np.linalg.norm(xyz, axis=-1), q[..., 0])
    # angle / sin(angle / 2) by its series below 1e-3 rad, as scipy's Rotation.as_rotvec
    small = angle <= 1e-3
    a2 = angle * angle
    scale = np.where(small, 2.0 + a2 / 12.0 + 7.0 * a2 * a2 / 2880.0,
                     angle / np.sin(0.5 * np.where(small, 1.0, angle)))
    return scale[..., None] * xyz


def matrix_rotvec(r: np.ndarray) -> np.ndarray:
    """Rotation vectors (..., 3) [rad] of rotation matrices (..., 3, 3); the inverse of :func:`rotvec_matrix`."""
    return to_rotvec(from_matrix(r))


def align_vectors(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation matrix ``R`` (3, 3) that minimises ``sum_i |a_i - R b_i|^2`` over vectors (n, 3) (Wahba's problem).

    Kabsch's solution: ``R = U V^T`` from the SVD of ``sum_i a_i b_i^T``, the last singular direction
    flipped where that product would be a reflection.
    """
    u, _, vh = np.linalg.svd(np.asarray(a, dtype=float).T @ np.asarray(b, dtype=float))
    if np.linalg.det(u @ vh) < 0:
        u[:, -1] = -u[:, -1]
    return u @ vh


def _tree_product(m: np.ndarray) -> np.ndarray:
    """Ordered product ``m[..., 0, :, :] @ m[..., 1, :, :] ...`` along axis -3, by pairwise levels."""
    while m.shape[-3] > 1:
        if m.shape[-3] % 2:
            m = np.concatenate([m, np.broadcast_to(np.eye(3), m.shape[:-3] + (1, 3, 3))], axis=-3)
        m = m[..., 0::2, :, :] @ m[..., 1::2, :, :]
    return m[..., 0, :, :]


def attitude_matrices(t: np.ndarray, omega: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """Attitude change of each interval as rotation matrices (m, 3, 3); see :func:`attitude_change`."""
    bounds = np.asarray(bounds, dtype=int).reshape(-1, 2)
    phi = step_rotvecs(t, omega)
    steps = bounds[:, 1] - bounds[:, 0]
    out = np.broadcast_to(np.eye(3), (len(bounds), 3, 3)).copy()
    # one padded block when that wastes little; otherwise groups by the power of two above the length
    # (padding then at most doubles the work)
    one_block = len(steps) * steps.max(initial=0) <= 2 * steps.sum() + 4096
    group = np.zeros(len(steps), int) if one_block else np.ceil(np.log2(np.maximum(steps, 1))).astype(int)
    for g in distinct(group[steps > 0]):
        members = np.flatnonzero((group == g) & (steps > 0))
        longest = int(steps[members].max())
        # steps of interval k are phi[first_k : last_k]; shorter ones are padded with identities
        idx = bounds[members, :1] + np.arange(longest)[None, :]
        valid = np.arange(longest)[None, :] < steps[members, None]
        padded = np.where(valid[..., None], phi[np.clip(idx, 0, len(phi) - 1)], 0.0)
        out[members] = _tree_product(rotvec_matrix(padded))
    return out


def attitude_change(t: np.ndarray, omega: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """Attitude at the end of each interval relative to its start, as unit quaternions (m, 4).

    Parameters
    ----------
    t : ndarray, shape (N,)
        Sample times [s], increasing.
    omega : ndarray, shape (N, 3)
        Body rates [rad/s].
    bounds : ndarray of int, shape (m, 2)
        ``first, last`` sample of each interval (inclusive); the rotation from sample ``first``
        to sample ``last``.

    Returns
    -------
    ndarray, shape (m, 4)
        ``q_rel`` with ``v_body(first) = q_rel v_body(last) q_rel*`` for a world-fixed vector.
    """
    return from_matrix(attitude_matrices(t, omega, bounds))
