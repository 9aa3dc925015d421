"""A hand multi-position session of a whole IMU: still poses joined by hand turns, with the truth.

The board rests in a sequence of orientations (chosen, random, or a tilt sequence that fills
the sphere) and is turned by hand between them. Each move goes through an intermediate
orientation (a wobble off the direct path, as a hand does) in two minimum-jerk rotations,
each about a fixed body axis, so attitude, body rate and angular acceleration are exact in
closed form at any time. The accelerometer sits at a lever arm from the centre of the
turns, so it feels centripetal and tangential acceleration while the board moves.

Sensors: ``gyro = K w + B + G f + noise`` (a :class:`~gyrocal.simulation.VirtualGyro` plus a
g-sensitivity ``G``) and ``accel = A^-1 f + o + noise``, with ``f`` the specific force [m/s^2].
Times may have uneven steps (samples taken late, early or dropped), and the readings are
taken at those true times.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import quaternion as quat
from .._validation import finite_array, positive
from ..errors import InputError
from ..imu import poses as _poses
from ..imu.gyro import EARTH_RATE
from ..units import STANDARD_GRAVITY
from .gyro import VirtualGyro

__all__ = ["ImuSession", "MultiPositionProtocol", "VirtualImu", "hand_session", "mounted_gyro", "random_accelerometer",
           "session_facts", "session_motion", "session_recording", "simulate_multi_position"]


@dataclass(frozen=True)
class VirtualImu:
    """A simulated IMU: gyro, accelerometer and the coupling between them.

    Parameters
    ----------
    gyro : VirtualGyro
        Rates ``K w + B + noise`` [rad/s].
    accel_matrix : array_like, shape (3, 3)
        Canonical accelerometer correction ``A`` (``f = A (u - o)``) [m/s^2 per reading unit].
    accel_offset : array_like, shape (3,)
        Canonical offset ``o`` [reading units].
    accel_noise_std : float or array_like, shape (3,)
        Per-sample white noise of the readings [reading units].
    accel_quantum : float, optional
        Resolution of the readings [reading units].
    g_sensitivity : array_like, shape (3, 3)
        Gyro reading per specific force ``G`` [rad/s per m/s^2]; zero by default.
    """

    gyro: VirtualGyro
    accel_matrix: np.ndarray = field(default_factory=lambda: np.eye(3))
    accel_offset: np.ndarray = field(default_factory=lambda: np.zeros(3))
    accel_noise_std: float | tuple[float, float, float] = 0.01
    accel_quantum: float | None = None
    g_sensitivity: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))

    def __post_init__(self):
        for name, shape in (("accel_matrix", (3, 3)), ("accel_offset", (3,)), ("g_sensitivity", (3, 3))):
            object.__setattr__(self, name, finite_array(name, getattr(self, name), shape_tail=shape, ndim=len(shape)))
        if np.linalg.cond(self.accel_matrix) > 1e8:
            raise InputError("accel_matrix is singular")
        sd = np.asarray(self.accel_noise_std, dtype=float)
        if not (np.all(np.isfinite(sd)) and np.all(sd >= 0)):
            raise InputError(f"{{param}} must be >= 0, got {self.accel_noise_std!r}", param="accel_noise_std")

    def accel(self, f: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Readings (N, 3) for specific forces (N, 3) [m/s^2]."""
        u = f @ np.linalg.inv(self.accel_matrix).T + self.accel_offset
        u = u + rng.standard_normal(u.shape) * np.asarray(self.accel_noise_std, dtype=float)
        if self.accel_quantum is not None:
            u = np.round(u / self.accel_quantum) * self.accel_quantum
        return u


@dataclass(frozen=True)
class MultiPositionProtocol:
    """How the session is done.

    Parameters
    ----------
    orientations : array_like, shape (n, 4), optional
        Poses as unit quaternions (body to world, ``w, x, y, z``). Without them, `poses` poses
        are drawn: a tilt sequence of `turn_deg` (see :func:`gyrocal.imu.poses.pose_sequence`)
        or, with ``turn_deg=None``, uniformly random orientations.
    poses : int
        Number of poses when `orientations` is not given.
    turn_deg : float or None
        Tilt between successive poses [deg].
    static_duration : (float, float)
        Range of the still time in each pose [s] (drawn uniformly).
    first_static : float
        Still time of the first pose [s] (an initial rest, as Tedaldi et al. ask for).
    peak_rate_deg : (float, float)
        Range of the peak rate of each hand move [deg/s].
    wobble_deg : float
        Size of the detour through an intermediate orientation [deg].
    lever_arm : array_like, shape (3,)
        Position of the accelerometer from the centre of the turns, body frame [m].
    sample_rate : float
        Nominal rate [Hz].
    uneven_steps : float
        Fraction of time steps that are 0.5, 1.5 or 2 (a dropped sample) times the nominal step.
    gravity : float
        Local gravity [m/s^2].
    latitude_deg : float or None
        Latitude [deg]: the gyro also senses the Earth's rotation, 7.29e-5 rad/s about the polar
        axis (world y is north). None for none.
    """

    orientations: np.ndarray | None = None
    poses: int = 24
    turn_deg: float | None = 90.0
    static_duration: tuple[float, float] = (2.0, 4.0)
    first_static: float = 5.0
    peak_rate_deg: tuple[float, float] = (90.0, 200.0)
    wobble_deg: float = 20.0
    lever_arm: tuple[float, float, float] = (0.03, -0.02, 0.01)
    sample_rate: float = 100.0
    uneven_steps: float = 0.0
    gravity: float = STANDARD_GRAVITY
    latitude_deg: float | None = 45.0

    def __post_init__(self):
        if self.orientations is not None:
            q = finite_array("orientations", self.orientations, shape_tail=(4,), ndim=2)
            if len(q) < 2:
                raise InputError("orientations needs at least 2 poses")
            object.__setattr__(self, "orientations", q / np.linalg.norm(q, axis=1, keepdims=True))
        elif int(self.poses) != self.poses or self.poses < 2:
            raise InputError(f"{{param}} must be a whole number >= 2, got {self.poses!r}", param="poses")
        lo, hi = self.static_duration
        if not 0 < lo <= hi:
            raise InputError(f"{{param}} must be (low, high) with 0 < low <= high [s], got {self.static_duration!r}",
                             param="static_duration")
        lo, hi = self.peak_rate_deg
        if not 0 < lo <= hi:
            raise InputError(f"{{param}} must be (low, high) with 0 < low <= high [deg/s], got {self.peak_rate_deg!r}",
                             param="peak_rate_deg")
        if self.turn_deg is not None and not 0 < self.turn_deg <= 180:
            raise InputError(f"{{param}} must be in (0, 180] deg, got {self.turn_deg!r}", param="turn_deg")
        positive("sample_rate", self.sample_rate)
        positive("gravity", self.gravity)
        if not 0 <= self.uneven_steps < 0.5:
            raise InputError(f"uneven_steps must be in [0, 0.5), got {self.uneven_steps!r}")

    def pose_orientations(self, rng: np.random.Generator) -> np.ndarray:
        """The poses (n, 4) of one session."""
        if self.orientations is not None:
            return np.array(self.orientations)
        if self.turn_deg is None:
            q = rng.standard_normal((int(self.poses), 4))
            return q / np.linalg.norm(q, axis=1, keepdims=True)
        return _poses.pose_sequence(int(self.poses), self.turn_deg, rng=rng)


@dataclass(frozen=True)
class ImuSession:
    """A simulated session: readings and the truth.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Sample times [s].
    gyro : ndarray, shape (N, 3)
        Gyro readings [rad/s].
    accel : ndarray, shape (N, 3)
        Accelerometer readings [reading units of the virtual IMU, m/s^2 by default].
    still : ndarray, shape (n, 2)
        True still spans ``start, stop`` (sample indices) of each pose.
    orientations : ndarray, shape (n, 4)
        The poses.
    truth : dict
        ``accel_matrix, accel_offset, gyro_matrix, gyro_offset, g_sensitivity, gravity``:
        canonical corrections (``w = gyro_matrix (m - gyro_offset - G f)``), internal units.
    """

    t: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray
    still: np.ndarray
    orientations: np.ndarray
    truth: dict


def _times(duration: float, fs: float, uneven: float, rng: np.random.Generator) -> np.ndarray:
    """Sample times from 0 to `duration` [s]: nominal steps, a fraction `uneven` of them 0.5, 1.5 or 2 times longer."""
    n = int(np.ceil(duration * fs)) + 1
    steps = np.full(n - 1, 1.0 / fs)
    if uneven > 0:
        odd = rng.random(n - 1) < uneven
        steps[odd] *= rng.choice([0.5, 1.5, 2.0], size=int(odd.sum()))
    t = np.concatenate([[0.0], np.cumsum(steps)])
    return t[t <= duration + 1e-9]


def _segments(q: np.ndarray, p: MultiPositionProtocol, rng: np.random.Generator) -> list[tuple]:
    """``(t0, duration, q_start, body_axis, angle)`` of every still and moving piece."""
    segs, t0 = [], 0.0
    for k in range(len(q)):
        still = p.first_static if k == 0 else rng.uniform(*p.static_duration)
        segs.append((t0, still, q[k], np.array([0.0, 0.0, 1.0]), 0.0))
        t0 += still
        if k == len(q) - 1:
            break
        mid = quat.multiply(q[k], quat.from_rotvec(0.5 * _poses.relative_rotvec(q[k], q[k + 1])))
        mid = quat.multiply(mid, quat.from_rotvec(rng.standard_normal(3) * np.radians(p.wobble_deg) / np.sqrt(3)))
        for a, b in ((q[k], mid), (mid, q[k + 1])):
            phi = _poses.relative_rotvec(a, b)
            angle = float(np.linalg.norm(phi))
            if angle < 1e-9:
                continue
            peak = np.radians(rng.uniform(*p.peak_rate_deg))
            duration = _poses.MIN_JERK_PEAK * angle / peak
            segs.append((t0, duration, a, phi / angle, angle))
            t0 += duration
    return segs


def _kinematics(t: np.ndarray, segs: list[tuple]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Orientation (N, 4), body rate (N, 3) and body angular acceleration (N, 3) at times `t`."""
    starts = np.array([s[0] for s in segs])
    idx = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(segs) - 1)
    dur = np.array([s[1] for s in segs])[idx]
    q0 = np.array([s[2] for s in segs])[idx]
    axis = np.array([s[3] for s in segs])[idx]
    angle = np.array([s[4] for s in segs])[idx]
    s, sd, sdd = _poses.min_jerk(angle, dur, (t - starts[idx]) / dur)
    q = quat.multiply(q0, quat.from_rotvec(axis * s[:, None]))
    return q, axis * sd[:, None], axis * sdd[:, None]


def session_motion(q_poses: np.ndarray, p: MultiPositionProtocol, rng: np.random.Generator):
    """The true motion of a session through poses `q_poses` (n, 4): sample times (N,) [s], body rates (N, 3)
    [rad/s] (the Earth's rotation included), specific force (N, 3) [m/s^2] at the lever arm, and the still
    spans (n, 2) of the poses (sample indices)."""
    segs = _segments(q_poses, p, rng)
    end = segs[-1][0] + segs[-1][1]
    t = _times(end, p.sample_rate, p.uneven_steps, rng)
    q, w, alpha = _kinematics(t, segs)
    r = np.asarray(p.lever_arm, dtype=float)
    f = quat.rotate(q * [1, -1, -1, -1], p.gravity * _poses.UP)
    f = f + np.cross(alpha, r) + np.cross(w, np.cross(w, r))
    if p.latitude_deg is not None:
        lat = np.radians(p.latitude_deg)
        w = w + quat.rotate(q * [1, -1, -1, -1], EARTH_RATE * np.array([0.0, np.cos(lat), np.sin(lat)]))
    still = np.array([[np.searchsorted(t, s[0], side="left"), np.searchsorted(t, s[0] + s[1], side="right")]
                      for s in segs if s[4] == 0.0])
    return t, w, f, still


def simulate_multi_position(imu: VirtualImu, protocol: MultiPositionProtocol | None = None, *,
                            rng: np.random.Generator) -> ImuSession:
    """Simulate a hand multi-position session.

    Parameters
    ----------
    imu : VirtualImu
    protocol : MultiPositionProtocol, optional
        Defaults to 24 poses joined by 90 deg tilts at 100 Hz.
    rng : numpy.random.Generator

    Returns
    -------
    ImuSession
    """
    p = protocol or MultiPositionProtocol()
    q_poses = p.pose_orientations(rng)
    t, w, f, still = session_motion(q_poses, p, rng)
    gyro = imu.gyro.measure(w, p.sample_rate, rng) + f @ imu.g_sensitivity.T
    accel = imu.accel(f, rng)
    aff = imu.gyro.model.to_affine()
    truth = {"accel_matrix": imu.accel_matrix.copy(), "accel_offset": imu.accel_offset.copy(),
             "gyro_matrix": np.linalg.inv(aff.K), "gyro_offset": np.array(aff.B),
             "g_sensitivity": imu.g_sensitivity.copy(), "gravity": p.gravity}
    return ImuSession(t=t, gyro=gyro, accel=accel, still=still, orientations=q_poses, truth=truth)


def random_accelerometer(rng: np.random.Generator, *, scale_error: float = 0.02, cross_deg: float = 0.5,
                         offset: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """A plausible MEMS accelerometer truth in the 9-parameter model's frame: ``(A, o)``.

    Scale factors within ``1 +- scale_error``, non-orthogonality of about `cross_deg` [deg],
    offsets of about `offset` [m/s^2] (lower-triangular ``A``: x along the sensor's x axis).
    """
    a = np.eye(3) * (1 + rng.uniform(-scale_error, scale_error, 3))
    a[np.tril_indices(3, -1)] = rng.normal(0.0, np.radians(cross_deg), 3)
    return a, rng.normal(0.0, offset, 3)


def mounted_gyro(model, misalignment_deg: float, rng: np.random.Generator):
    """`model` (scale and bias) with its axes turned by `misalignment_deg` [deg] about a random axis
    from the accelerometer's frame, as an :class:`~gyrocal.models.Affine` (readings ``K w + B``)."""
    from ..models import Affine

    aff = model.to_affine()
    axis = rng.normal(size=3)
    turn = quat.to_matrix(quat.from_rotvec(np.radians(misalignment_deg) * axis / np.linalg.norm(axis)))
    return Affine(K=aff.K @ turn.T, B=aff.B)


def session_recording(session: ImuSession, units: str = "rad/s"):
    """The simulated session as a :class:`~gyrocal.recording.Recording` (gyro rad/s, accelerometer m/s^2)."""
    from ..recording import Recording

    return Recording(t=session.t, gyro=session.gyro, accel=session.accel, accel_units="m/s^2",
                     accel_source_units="m/s^2", source_units=units)


def session_facts(session: ImuSession) -> dict:
    """The truth of a session beyond the gyro model, as JSON for the truth file."""
    tr = session.truth
    return {"accelerometer": {"matrix": tr["accel_matrix"].tolist(), "offset": tr["accel_offset"].tolist(),
                              "units": "m/s^2", "equation": "a_true = matrix @ (raw - offset)"},
            "gyro_correction": {"matrix": tr["gyro_matrix"].tolist(), "offset": tr["gyro_offset"].tolist(),
                                "units": "rad/s", "equation": "w_true = matrix @ (raw - offset - G a_true)"},
            "g_sensitivity": tr["g_sensitivity"].tolist(), "gravity": tr["gravity"],
            "poses": session.orientations.tolist(), "still": session.still.tolist()}


def hand_session(gyro_model, *, gyro_kw: dict, poses: int = 24, tilt_deg: float = 90.0, still: float = 3.0,
                 accel_noise_std: float = 0.02, misalignment_deg: float = 5.0, sample_rate: float = 100.0,
                 rng: np.random.Generator):
    """The whole-IMU session of ``gyrocal simulate --protocol multi-position``.

    The gyro (`gyro_model` and :class:`VirtualGyro` options `gyro_kw`) is mounted `misalignment_deg`
    off a drawn accelerometer (:func:`random_accelerometer`); `poses` poses a tilt of `tilt_deg`
    apart, each still for ``still`` s +- 25 %.

    Returns
    -------
    (Recording, Affine, dict, dict)
        The recording, the gyro's true model, the truth facts, the settings.
    """
    from .gyro import VirtualGyro

    positive("static_duration", still)  # before any draw: a bad value is refused as the user typed it
    gyro = mounted_gyro(gyro_model, misalignment_deg, rng)
    a, o = random_accelerometer(rng)
    imu = VirtualImu(VirtualGyro(gyro, **gyro_kw), accel_matrix=a, accel_offset=o, accel_noise_std=accel_noise_std)
    proto = MultiPositionProtocol(poses=poses, turn_deg=tilt_deg, static_duration=(0.75 * still, 1.25 * still),
                                  sample_rate=sample_rate)
    session = simulate_multi_position(imu, proto, rng=rng)
    settings = {"poses": poses, "tilt_deg": tilt_deg, "still_s": still, "accel_noise_std": accel_noise_std,
                "misalignment_deg": misalignment_deg}
    return session_recording(session), gyro, session_facts(session), settings
