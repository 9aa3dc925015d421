"""Unit quaternions and the attitude change a gyro measures between two instants.

Quaternions are arrays ``[..., 4]`` = ``(w, x, y, z)`` with Hamilton's product; ``q`` maps
body vectors to the world, ``v_world = q v_body q*``. The body rate ``omega`` [rad/s] drives
``dq/dt = q (0, omega) / 2``.

:func:`attitude_change` integrates on the real sample times: each step's rotation vector is
the trapezoid of the two end rates plus the second-order coning term of a rate that varies
linearly over the step, ``phi = h (w0 + w1) / 2 + h^2 / 12 (w0 x w1)``. The steps are then
multiplied in a balanced tree (one vectorised product per level), so integrating many
intervals of a few hundred samples each costs a handful of numpy calls.
"""

from __future__ import annotations

import numpy as np

__all__ = ["attitude_change", "from_rotvec", "multiply", "rotate", "step_rotvecs", "to_matrix"]


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


def _tree_product(q: np.ndarray) -> np.ndarray:
    """Ordered product ``q[..., 0, :] q[..., 1, :] ...`` along axis -2, by pairwise levels."""
    while q.shape[-2] > 1:
        if q.shape[-2] % 2:
            pad = np.zeros(q.shape[:-2] + (1, 4))
            pad[..., 0] = 1.0
            q = np.concatenate([q, pad], axis=-2)
        q = multiply(q[..., 0::2, :], q[..., 1::2, :])
        q /= np.linalg.norm(q, axis=-1, keepdims=True)
    return q[..., 0, :]


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
    bounds = np.asarray(bounds, dtype=int).reshape(-1, 2)
    phi = step_rotvecs(t, omega)
    steps = bounds[:, 1] - bounds[:, 0]
    out = np.zeros((len(bounds), 4))
    out[:, 0] = 1.0
    # intervals grouped by the power of two above their length: padding at most doubles the work
    group = np.ceil(np.log2(np.maximum(steps, 1))).astype(int)
    for g in np.unique(group[steps > 0]):
        members = np.flatnonzero((group == g) & (steps > 0))
        longest = int(steps[members].max())
        # steps of interval k are phi[first_k : last_k]; shorter ones are padded with identities
        idx = bounds[members, :1] + np.arange(longest)[None, :]
        valid = np.arange(longest)[None, :] < steps[members, None]
        padded = np.where(valid[..., None], phi[np.clip(idx, 0, len(phi) - 1)], 0.0)
        out[members] = _tree_product(from_rotvec(padded))
    return out
