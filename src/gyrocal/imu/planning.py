"""Planning a hand session: how many poses, and which turns between them, reach a target accuracy.

The prediction is the Cramér–Rao bound of the fits in this package: the same equations
(:mod:`gyrocal.imu.accel`, :mod:`gyrocal.imu._gyro_problem`) evaluated on an ideal session,
noise-free, with each equation weighted by the noise the session would have. A plan is a
sequence of poses, each a tilt of ``turn_deg`` from the last
(:func:`~gyrocal.imu.poses.pose_sequence`), held ``static_duration`` seconds and joined by
minimum-jerk moves peaking at ``peak_rate_deg``. Real sessions scatter more than their noise
(hand placement, timing): the bound is what a careful session approaches, not a promise.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product

import numpy as np

from .. import quaternion as quat
from .._validation import positive
from ..errors import DegenerateDesignError, InputError
from ..units import STANDARD_GRAVITY
from . import _fit
from ._gyro_cov import noise_model, whitener
from ._gyro_problem import build_problem
from ._gyro_solve import jacobian, residuals
from .accel import fit_accelerometer
from .accel import param_names as accel_names
from .poses import MIN_JERK_PEAK, UP, Coverage, coverage, min_jerk, pose_sequence, relative_rotvec
from .statics import Static

__all__ = ["FIGURES", "PosePlan", "predict_poses", "suggest_poses"]

#: Moving-window length of the still-pose detector [s] (:func:`gyrocal.imu.statics.detect_statics`).
DETECTOR_WINDOW = 0.5
#: Summary figures of a plan: the largest 1-sigma of each kind of parameter.
FIGURES = ("accel_scale", "accel_cross", "accel_offset", "gyro_scale", "gyro_cross", "gyro_bias")


@dataclass(frozen=True)
class PosePlan:
    """Predicted accuracy of a hand session.

    Attributes
    ----------
    poses, turn_deg, static_duration, peak_rate_deg, sample_rate :
        The plan [-, deg, s, deg/s, Hz].
    accel_noise, gyro_noise : float
        Per-sample noise [m/s^2, rad/s].
    accel_std : ndarray
        Cramér–Rao 1-sigma of the accelerometer's parameters (9-parameter model) [-, m/s^2].
    gyro_std : ndarray, shape (12,)
        Of the gyro's ``A`` (row-major) and bias [-, rad/s].
    total_time : float
        Still time plus moves [s].
    coverage : Coverage
    """

    poses: int
    turn_deg: float
    static_duration: float
    peak_rate_deg: float
    sample_rate: float
    accel_noise: float
    gyro_noise: float
    accel_std: np.ndarray
    gyro_std: np.ndarray
    total_time: float
    coverage: Coverage

    def figures(self) -> dict[str, float]:
        """The largest 1-sigma of each kind: scale and cross terms [-], offset [m/s^2], gyro bias [rad/s]."""
        a = self.accel_std
        g = self.gyro_std[:9].reshape(3, 3)
        diag = np.eye(3, dtype=bool)
        names = accel_names("triangular")
        cross = [s for n, s in zip(names, a) if n.startswith("A_") and n[2] != n[3]]
        return {"accel_scale": float(max(s for n, s in zip(names, a) if n in ("A_xx", "A_yy", "A_zz"))),
                "accel_cross": float(max(cross)), "accel_offset": float(a[-3:].max()),
                "gyro_scale": float(g[diag].max()), "gyro_cross": float(g[~diag].max()),
                "gyro_bias": float(self.gyro_std[9:].max())}


def _ideal_session(q: np.ndarray, still: float, peak: float, fs: float, gravity: float):
    """Times, body rates, specific force and still spans of a noise-free session through orientations `q`."""
    pieces_t, pieces_w, pieces_f, spans, t0, n0 = [], [], [], [], 0.0, 0
    for k in range(len(q)):
        n = max(2, round(still * fs))
        tt = t0 + np.arange(n) / fs
        f = np.tile(quat.rotate(q[k] * [1, -1, -1, -1], gravity * UP), (n, 1))
        pieces_t.append(tt)
        pieces_w.append(np.zeros((n, 3)))
        pieces_f.append(f)
        spans.append((n0, n0 + n))
        t0, n0 = tt[-1] + 1 / fs, n0 + n
        if k == len(q) - 1:
            break
        phi = relative_rotvec(q[k], q[k + 1])
        angle = float(np.linalg.norm(phi))
        duration = MIN_JERK_PEAK * angle / peak
        m = max(2, round(duration * fs))
        tau = np.arange(m) / m
        s, sd, _ = min_jerk(angle, duration, tau)
        axis = phi / angle
        qq = quat.multiply(q[k], quat.from_rotvec(axis * s[:, None]))
        pieces_t.append(t0 + tau * duration)
        pieces_w.append(axis * sd[:, None])
        pieces_f.append(quat.rotate(qq * [1, -1, -1, -1], gravity * UP))
        t0, n0 = t0 + duration, n0 + m
    return np.concatenate(pieces_t), np.concatenate(pieces_w), np.concatenate(pieces_f), spans


def _crb(t, w, f, spans, gyro_se, accel_se, gravity) -> tuple[np.ndarray, np.ndarray]:
    """Cramér–Rao 1-sigma of the 9-parameter accelerometer and the affine gyro, at ``A = I``, zero offsets.

    The same fits as a real session, on noise-free readings with the noise's weights: the
    accelerometer fit of the ideal pose means, then the gyro's Jacobian and covariance
    (the poses' noise carried through both, :mod:`gyrocal.imu._gyro_cov`).
    """
    n = np.array([b - a for a, b in spans])
    means = np.array([f[a] for a, _ in spans])
    se = accel_se / np.sqrt(n)[:, None] * np.ones(3)
    try:
        afit = fit_accelerometer(means, se, gravity=gravity, model="triangular")
    except DegenerateDesignError:
        return np.full(9, np.inf), np.full(12, np.inf)
    statics = [Static(a, b, float(t[a]), float(t[b - 1]), f[a], np.zeros(3), se[k],
                      np.full(3, gyro_se / np.sqrt(b - a)), np.full(3, accel_se), np.full(3, gyro_se))
               for k, (a, b) in enumerate(spans)]
    prob = build_problem(t, w, f, statics, np.array([(i, i + 1) for i in range(len(spans) - 1)]), (), 1.0)
    p0 = np.concatenate([np.eye(3).ravel(), np.zeros(3)])
    jac = jacobian(lambda p: residuals(prob, "affine", False, p, afit.directions, afit.direction_std), p0)
    rank, _ = _fit.relative_rank(jac)
    if rank < jac.shape[1]:
        return afit.std, np.full(12, np.inf)
    w = whitener(noise_model(prob, (np.eye(3), np.zeros(3), None), afit, means))
    jw = w @ jac
    cov = np.linalg.inv(jw.T @ jw)
    return afit.std, np.sqrt(np.diag(cov))


def predict_poses(poses: int = 24, turn_deg: float = 90.0, *, static_duration: float = 2.0,
                  peak_rate_deg: float = 150.0, sample_rate: float = 100.0, accel_noise_density: float = 2e-3,
                  gyro_noise_density: float = 1e-4, gravity: float = STANDARD_GRAVITY) -> PosePlan:
    """Cramér–Rao accuracy of a plan.

    Parameters
    ----------
    poses : int
        Still poses (6 or more).
    turn_deg : float
        Tilt between successive poses [deg], in (0, 180].
    static_duration : float
        Still time per pose [s]; the detector uses all but :data:`DETECTOR_WINDOW` of it.
    peak_rate_deg : float
        Peak rate of each hand move [deg/s].
    sample_rate : float
        [Hz].
    accel_noise_density : float
        [m/s^2/sqrt(Hz)] (MPU-6050: about 4e-3; a good MEMS IMU: 1e-3).
    gyro_noise_density : float
        [rad/s/sqrt(Hz)] (MPU-6050: about 9e-5).
    gravity : float
        [m/s^2].
    """
    if int(poses) != poses or poses < 6:
        raise InputError(f"{{param}} must be a whole number >= 6, got {poses!r}", param="poses")
    if not 0 < turn_deg <= 180:
        raise InputError(f"{{param}} must be in (0, 180] deg, got {turn_deg!r}", param="turn_deg")
    fs = positive("sample_rate", sample_rate)
    still, peak = positive("static_duration", static_duration), np.radians(positive("peak_rate_deg", peak_rate_deg))
    accel_se = positive("accel_noise_density", accel_noise_density) * np.sqrt(fs)
    gyro_se = positive("gyro_noise_density", gyro_noise_density) * np.sqrt(fs)
    if still <= DETECTOR_WINDOW:
        raise InputError(f"{{param}} must exceed {DETECTOR_WINDOW} s: the detector trims that much off each pose",
                         param="static_duration")
    q = pose_sequence(int(poses), turn_deg)
    t, w, f, spans = _ideal_session(q, still, peak, fs, gravity)
    # the detector keeps a pose only where its whole moving window is still: half a window less at each end
    trim = int(round(DETECTOR_WINDOW * fs / 2))
    spans = [(a + trim, b - trim) if k else (a, b - trim) for k, (a, b) in enumerate(spans)]
    accel_std, gyro_std = _crb(t, w, f, spans, gyro_se, accel_se, gravity)
    return PosePlan(poses=int(poses), turn_deg=float(turn_deg), static_duration=still, peak_rate_deg=peak_rate_deg,
                    sample_rate=fs, accel_noise=accel_se, gyro_noise=gyro_se, accel_std=accel_std, gyro_std=gyro_std,
                    total_time=float(t[-1] - t[0]), coverage=coverage(np.array([f[a] for a, _ in spans])))


def suggest_poses(targets: dict[str, float], *, pose_counts=(12, 16, 20, 24, 30, 36, 48),
                  turns=(45.0, 90.0, 135.0), **options) -> PosePlan:
    """The shortest plan on a grid of pose counts and turn sizes that reaches every target.

    Parameters
    ----------
    targets : dict
        Largest acceptable 1-sigma per figure of :data:`FIGURES` (for example
        ``{"gyro_scale": 1e-3, "accel_offset": 0.01}``).
    pose_counts, turns : sequence
        The grid searched. It starts at 12 poses: fewer leave the 9-parameter accelerometer too few
        spare equations to check its fit, and ``gyrocal imu`` then fits scale and bias only.
    **options
        Passed to :func:`predict_poses`.

    Raises
    ------
    DegenerateDesignError
        No plan of the grid reaches the targets; the message gives the best one found.
    """
    unknown = set(targets) - set(FIGURES)
    if unknown or not targets:
        raise InputError(f"targets must name some of {', '.join(FIGURES)}, got {sorted(targets)}")
    bad = {k: v for k, v in targets.items() if not (np.isfinite(v) and v > 0)}
    if bad:
        raise InputError(f"every target must be a 1-sigma > 0, got {bad}", param="targets", value=bad)
    plans = [predict_poses(n, turn, **options) for n, turn in product(pose_counts, turns)]
    ok = [p for p in plans if all(p.figures()[k] <= v for k, v in targets.items())]
    if ok:
        return min(ok, key=lambda p: p.total_time)
    best = min(plans, key=lambda p: max(p.figures()[k] / v for k, v in targets.items()))
    worst = max(targets, key=lambda k: best.figures()[k] / targets[k])
    raise DegenerateDesignError(
        f"no plan of up to {max(pose_counts)} poses reaches the targets; the closest, {best.poses} poses with "
        f"{best.turn_deg:g} deg turns, reaches {worst} = {best.figures()[worst]:.2g} (target {targets[worst]:.2g}); "
        "hold each pose longer or use a quieter sensor")
