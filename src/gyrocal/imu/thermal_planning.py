"""Planning a chamber session: how many temperature points, and poses at each, reach a target 1-sigma.

One point's accuracy is the Cramér–Rao bound of a hand session (:func:`~gyrocal.imu.planning.predict_poses`).
Between the points the correction is the smooth polynomial of ``gyrocal imu``
(:mod:`gyrocal.imu.thermal_model`): its coefficients are the points' values weighted by their 1-sigma
(:func:`gyrocal.thermal.smooth.weighted_coefficients`), so the points' covariances carry through that
least squares to a 1-sigma at every temperature. The points are spread evenly over the range, every
point with the same plan, and each parameter's polynomial is taken at the highest order the fit tries
(``min(3, points - 2)``: a cubic drift with enough signal is fitted so); a lower order, chosen when the
drift is small, has a smaller 1-sigma but can miss the drift. Soak time is not counted.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product

import numpy as np

from ..errors import DegenerateDesignError, InputError
from ..thermal.smooth import SmoothModel, weighted_coefficients
from .accel import param_names
from .planning import PosePlan, predict_poses
from .thermal_model import TemperatureModel

__all__ = ["THERMAL_FIGURES", "ThermalPlan", "predict_thermal", "smooth_sigma", "suggest_thermal"]

#: The figures a chamber plan reports, and a target may name.
THERMAL_FIGURES = ("accel_scale", "accel_offset", "gyro_scale", "gyro_bias")
_NAMES = param_names("triangular")
#: Which sensor's parameters, and which of them, make each figure (the gyro's: its affine ``M`` row-major, bias).
_KIND = {"accel_scale": ("accel", [_NAMES.index(n) for n in ("A_xx", "A_yy", "A_zz")]),
         "accel_offset": ("accel", [_NAMES.index(n) for n in ("o_x", "o_y", "o_z")]),
         "gyro_scale": ("gyro", [0, 4, 8]), "gyro_bias": ("gyro", [9, 10, 11])}
#: Temperatures across the range at which the smooth model's 1-sigma is evaluated.
_GRID = 201


def smooth_sigma(nodes, std, temps, max_order: int = 3) -> np.ndarray:
    """1-sigma (N, m) of the smooth polynomials at `temps` (N,) [degC] from points at `nodes` (n,) [degC]
    whose parameters have 1-sigma `std` (n, m) (independent points), at the highest order tried."""
    nodes = np.asarray(nodes, dtype=float)
    std = np.atleast_2d(np.asarray(std, dtype=float))
    n, m = std.shape
    top = min(int(max_order), n - 2)
    if top < 0:
        raise InputError(f"a model in temperature needs at least 3 temperature points, got {n}")
    centre, scale = float(nodes.mean()), float(max(np.ptp(nodes) / 2, 1e-12))
    model = SmoothModel(centre=centre, scale=scale, orders=np.full(m, top), coefs=np.zeros((m, top + 1)),
                        loto_rms=np.zeros((top + 1, m)))
    covs = np.stack([np.diag(s**2) for s in std])
    _, cov, _ = weighted_coefficients(model, nodes, np.zeros((n, m)), covs)
    tm = TemperatureModel(names=tuple(f"p{j}" for j in range(m)), nodes=nodes, values=np.zeros((n, m)),
                          covariances=covs, smooth=model, smooth_covariance=cov, chi2=np.zeros(m))
    return tm.smooth_at(temps)[1]


@dataclass(frozen=True)
class ThermalPlan:
    """Predicted accuracy of a chamber session.

    Attributes
    ----------
    points, poses : int
        Temperature points, and poses at each.
    nodes : ndarray, shape (points,)
        The points [degC], evenly over the range.
    order : int
        Of each parameter's polynomial.
    point : PosePlan
        One point's hand session.
    per_point, between, between_rms : dict of str to float
        Largest 1-sigma of each of :data:`THERMAL_FIGURES` at one point; the smooth polynomial's largest
        anywhere across the range (at its ends, where the polynomial rests on fewest points), and its
        RMS across the range [-, m/s^2, rad/s]. The gyro's bias is its noise alone: a bias that jumps
        between turn-ons adds its own repeatability.
    total_time : float
        Pose sequences at every point, soaks not counted [s].
    """

    points: int
    poses: int
    nodes: np.ndarray
    order: int
    point: PosePlan
    per_point: dict
    between: dict
    between_rms: dict
    total_time: float

    def meets(self, targets: dict[str, float]) -> bool:
        """Whether the smooth polynomial's largest 1-sigma across the range reaches every target."""
        return all(self.between[k] <= v for k, v in targets.items())


def predict_thermal(points: int, poses: int = 24, turn_deg: float = 90.0, *, temp_range=(-25.0, 50.0),
                    point: PosePlan | None = None, **options) -> ThermalPlan:
    """Accuracy of `points` temperature points over `temp_range` [degC], `poses` poses each.

    `options` go to :func:`~gyrocal.imu.planning.predict_poses`; `point`, when given, is that
    prediction already made (the same for every point count).
    """
    if int(points) != points or points < 3:
        raise InputError(f"{{param}} must be a whole number >= 3, got {points!r}", param="points")
    lo, hi = (float(v) for v in temp_range)
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise InputError(f"{{param}} must be low:high with low < high [degC], got {temp_range!r}", param="temp_range")
    point = point or predict_poses(poses, turn_deg, **options)
    nodes = np.linspace(lo, hi, int(points))
    stds = {"accel": point.accel_std, "gyro": point.gyro_std}
    grid = np.linspace(lo, hi, _GRID)
    sigma = {s: smooth_sigma(nodes, np.tile(v, (int(points), 1)), grid) for s, v in stds.items()}
    per_point = {k: float(stds[s][idx].max()) for k, (s, idx) in _KIND.items()}
    between = {k: float(sigma[s][:, idx].max()) for k, (s, idx) in _KIND.items()}
    rms = {k: float(np.sqrt(np.mean(sigma[s][:, idx] ** 2, axis=0)).max()) for k, (s, idx) in _KIND.items()}
    return ThermalPlan(points=int(points), poses=point.poses, nodes=nodes, order=min(3, int(points) - 2),
                       point=point, per_point=per_point, between=between,
                       between_rms=rms, total_time=points * point.total_time)


def suggest_thermal(targets: dict[str, float], *, point_counts=range(5, 13),
                    pose_counts=(12, 16, 20, 24, 30, 36, 48), turn_deg: float = 90.0, temp_range=(-25.0, 50.0),
                    **options) -> ThermalPlan:
    """The plan of fewest poses in all (then fewest points) whose smooth polynomial reaches every target.

    The grid starts at 5 points: the fit tries orders up to ``points - 2``, and a cubic drift needs 3.

    Raises
    ------
    DegenerateDesignError
        No plan of the grid reaches the targets; the message gives the closest.
    """
    unknown = set(targets) - set(THERMAL_FIGURES)
    if unknown or not targets:
        raise InputError(f"targets must name some of {', '.join(THERMAL_FIGURES)}, got {sorted(targets)}")
    singles = {p: predict_poses(p, turn_deg, **options) for p in pose_counts}
    plans = [predict_thermal(n, p, turn_deg, temp_range=temp_range, point=singles[p])
             for n, p in product(point_counts, pose_counts)]
    ok = [p for p in plans if p.meets(targets)]
    if ok:
        return min(ok, key=lambda p: (p.points * p.poses, p.points))
    best = min(plans, key=lambda p: max(p.between[k] / v for k, v in targets.items()))
    worst = max(targets, key=lambda k: best.between[k] / targets[k])
    raise DegenerateDesignError(
        f"no plan of up to {max(point_counts)} points and {max(pose_counts)} poses reaches the targets; the closest, "
        f"{best.points} points of {best.poses} poses, reaches {worst} = {best.between[worst]:.2g} (target "
        f"{targets[worst]:.2g}); hold each pose longer or use a quieter sensor")
