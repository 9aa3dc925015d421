"""Pose geometry: gravity directions on the sphere, how well they cover it, and pose sequences.

A pose is where the board rests; what the calibration sees of it is the direction of the
specific force (gravity, pointing up) in the sensor frame. The accelerometer's scale and bias
along an axis are determined only by poses with that axis up and down; its non-orthogonality
only by poses between the axes. Two figures say how well a set of poses does this:

* ``spread``: three times the smallest eigenvalue of the mean outer product of the unit
  directions. It is 1 for directions spread evenly over the sphere (and for the six faces of a
  cube) and 0 when they all lie on one great circle, where one axis is not seen.
* ``empty_cap_deg``: the angular radius of the largest spherical cap holding no pose, searched
  on a dense grid: 90 deg for a hemisphere left empty, about 55 deg for the six faces.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import quaternion as quat
from .._validation import finite_array

__all__ = [
    "MIN_JERK_PEAK",
    "UP",
    "Coverage",
    "coverage",
    "distinct_directions",
    "fibonacci_directions",
    "min_jerk",
    "pose_sequence",
    "relative_rotvec",
    "triangular_frame",
]

#: World "up": the specific force of a board at rest points along it.
UP = np.array([0.0, 0.0, 1.0])
#: Two gravity directions closer than this are one pose for counting [deg].
DISTINCT_DEG = 10.0


def fibonacci_directions(n: int) -> np.ndarray:
    """`n` unit vectors spread almost evenly over the sphere (golden-angle spiral), (n, 3)."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = np.pi * (1.0 + 5.0**0.5) * i
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


_GRID = fibonacci_directions(5000)  # about 3 deg apart


def _unit(v: np.ndarray) -> np.ndarray:
    v = finite_array("directions", v, shape_tail=(3,), ndim=2)
    norm = np.linalg.norm(v, axis=1, keepdims=True)
    if np.any(norm == 0):
        raise ValueError("a direction of zero length")
    return v / norm


def distinct_directions(directions, radius_deg: float = DISTINCT_DEG) -> np.ndarray:
    """Indices of one representative per group of directions within `radius_deg` of each other (greedy)."""
    u = _unit(directions)
    cos_r = np.cos(np.radians(radius_deg))
    keep: list[int] = []
    for i in range(len(u)):
        if not keep or np.max(u[keep] @ u[i]) < cos_r:
            keep.append(i)
    return np.array(keep, dtype=int)


@dataclass(frozen=True)
class Coverage:
    """How a set of gravity directions covers the sphere.

    Attributes
    ----------
    poses : int
        Distinct directions (more than 10 deg apart).
    spread : float
        Three times the smallest eigenvalue of the mean outer product of the distinct unit
        directions; 1 = even, 0 = all on one great circle.
    weakest_axis : ndarray, shape (3,)
        Eigenvector of that eigenvalue: the direction the poses see least.
    empty_cap_deg : float
        Angular radius of the largest cap without a pose [deg].
    empty_cap_centre : ndarray, shape (3,)
        Centre of that cap: where a new pose would help most.
    """

    poses: int
    spread: float
    weakest_axis: np.ndarray
    empty_cap_deg: float
    empty_cap_centre: np.ndarray

    def to_dict(self) -> dict:
        return {"poses": self.poses, "spread": self.spread, "weakest_axis": self.weakest_axis.tolist(),
                "empty_cap_deg": self.empty_cap_deg, "empty_cap_centre": self.empty_cap_centre.tolist()}


def coverage(directions) -> Coverage:
    """Coverage of the sphere by gravity directions (n, 3) in the sensor frame."""
    u = _unit(directions)
    d = u[distinct_directions(u)]
    vals, vecs = np.linalg.eigh(d.T @ d / len(d))
    nearest = (_GRID @ d.T).max(axis=1)
    far = int(np.argmin(nearest))
    return Coverage(poses=len(d), spread=float(3.0 * max(vals[0], 0.0)), weakest_axis=vecs[:, 0],
                    empty_cap_deg=float(np.degrees(np.arccos(np.clip(nearest[far], -1, 1)))),
                    empty_cap_centre=_GRID[far].copy())


def _next_up(up: np.ndarray, seen: np.ndarray, angle: float) -> np.ndarray:
    """Of the directions `angle` [rad] away from `up`, the one farthest from every direction `seen`."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(up[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(up, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(up, e1)
    phi = np.linspace(0, 2 * np.pi, 144, endpoint=False)[:, None]
    cand = up * np.cos(angle) + (e1 * np.cos(phi) + e2 * np.sin(phi)) * np.sin(angle)
    return cand[int(np.argmin((cand @ seen.T).max(axis=1)))]


def pose_sequence(n: int, turn_deg: float, *, rng: np.random.Generator | None = None) -> np.ndarray:
    """Orientations (n, 4) of a hand session: each pose a tilt of `turn_deg` from the last.

    The first pose has the sensor's z axis up. Of the orientations one tilt of `turn_deg` away,
    each next pose takes the one whose 'up' (in the sensor frame) is farthest from every pose
    so far, so the poses fill the sphere. With `rng`, a random turn about the vertical
    (invisible to the accelerometer, as in a real session) is added.
    """
    q = np.zeros((n, 4))
    q[0] = [1.0, 0.0, 0.0, 0.0]
    ups = [UP.copy()]
    angle = np.radians(turn_deg)
    for k in range(1, n):
        up = ups[-1]
        new = _next_up(up, np.array(ups), angle)
        axis = np.cross(up, new)
        norm = np.linalg.norm(axis)
        axis = axis / norm if norm > 1e-9 else np.cross(up, [1.0, 0.0, 0.0] if abs(up[0]) < 0.9 else [0.0, 1.0, 0.0])
        # turning the body by -angle about `axis` moves its view of 'up' from `up` to `new`
        qk = quat.multiply(q[k - 1], quat.from_rotvec(-angle * axis / np.linalg.norm(axis)))
        if rng is not None:
            qk = quat.multiply(quat.from_rotvec(UP * rng.uniform(-np.pi, np.pi)), qk)
        q[k] = qk / np.linalg.norm(qk)
        ups.append(quat.rotate(q[k] * [1, -1, -1, -1], UP))
    return q


#: Peak rate of a minimum-jerk move over its mean rate.
MIN_JERK_PEAK = 1.875


def min_jerk(angle, duration, tau) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Angle [rad], rate [rad/s] and acceleration [rad/s^2] of a minimum-jerk move at fractions `tau` of it.

    A smooth hand move: from rest to rest in `duration` [s] through `angle` [rad], peak rate
    ``MIN_JERK_PEAK * angle / duration`` at mid-move.
    """
    tau = np.clip(tau, 0.0, 1.0)
    s = angle * (10 * tau**3 - 15 * tau**4 + 6 * tau**5)
    sd = angle / duration * (30 * tau**2 - 60 * tau**3 + 30 * tau**4)
    sdd = angle / duration**2 * (60 * tau - 180 * tau**2 + 120 * tau**3)
    return s, sd, sdd


def relative_rotvec(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Body rotation vector [rad] taking orientation `a` to `b` (unit quaternions), the short way."""
    d = quat.multiply(a * [1, -1, -1, -1], b)
    d = d * np.sign(d[0]) if d[0] != 0 else d
    half = np.arccos(np.clip(d[0], -1.0, 1.0))
    s = np.sin(half)
    return np.zeros(3) if s < 1e-12 else d[1:] * (2.0 * half / s)


def triangular_frame(matrix) -> tuple[np.ndarray, np.ndarray]:
    """Express an accelerometer correction in the frame of the 9-parameter model.

    |a| = g fixes a correction ``A`` only up to a rotation of the output frame. The
    convention of Tedaldi et al. fixes it: the corrected x axis is the sensor's x axis and
    the corrected y axis lies in the plane of the sensor's x and y axes, which makes ``A``
    lower triangular with a positive diagonal.

    Returns
    -------
    L : ndarray, shape (3, 3)
        Lower-triangular ``L = R A`` with ``L^T L = A^T A``.
    R : ndarray, shape (3, 3)
        The rotation from `matrix`'s output frame to the triangular one (``R = L A^-1``).
    """
    a = finite_array("matrix", matrix, shape_tail=(3, 3), ndim=2)
    flip = np.eye(3)[::-1]
    c = np.linalg.cholesky(flip @ (a.T @ a) @ flip)
    lower = flip @ c.T @ flip
    return lower, lower @ np.linalg.inv(a)
