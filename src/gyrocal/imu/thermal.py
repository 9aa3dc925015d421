"""The whole IMU across temperature: a multi-position session at each plateau of a chamber.

The log is cut into temperature plateaus (:func:`~gyrocal.imu.plateaus.find_plateaus`: a break
or a temperature change ends one), and each plateau is calibrated on its own by
:func:`~gyrocal.imu.session.calibrate_imu` (stillness and poses judged inside it, the gyro's bias
its own), so a bias that jumps between plateaus, or a soak that was not recorded, harms nothing.
Plateaus at one temperature are one point: their parameters are joined by their inverse
covariances. With ``model="auto"`` every point then takes the smallest model any point chose, so
the same parameters exist at every temperature. The points' parameters become a
:class:`~gyrocal.imu.thermal_model.TemperatureModel` per sensor: the 3-node Lagrange table of the
full-temperature-range method and the smooth polynomial chosen by leave-one-temperature-out error.

Frame. Still poses fix the accelerometer only up to a rotation of its output frame. Each point
writes in the frame of the 9-parameter model (:func:`~gyrocal.imu.poses.triangular_frame`, Tedaldi
et al.): corrected x along the sensor's x axis at that temperature, corrected y in the plane of the
sensor's x and y axes (``scale-bias``: the sensor's own axes). That frame is defined by the sensor
itself at every temperature, so the points agree on it without any reference; a rotation of the
sensor's axes relative to the case with temperature is invisible to still poses and is not in the
model. The gyro's correction maps onto the corrected accelerometer frame at the same temperature.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import DegenerateDesignError, InputError, SegmentationError
from ..units import STANDARD_GRAVITY
from ._gyro_solve import MASKS
from .accel import model_matrices
from .plateaus import Plateau, find_plateaus, temperature_points
from .session import ImuCalibrationResult, calibrate_imu
from .thermal_limits import Limits, assess, branches, lag_corrected, too_few_poses
from .thermal_model import TemperatureModel, temperature_model

__all__ = ["FRAME", "ImuPoint", "ImuThermalResult", "calibrate_imu_thermal", "correct_with_section", "sensor_matrices"]

FRAME = ("accelerometer: the 9-parameter model's frame at each temperature (corrected x along the sensor's x "
         "axis, y in the sensor's xy plane; scale-bias: the sensor's axes); gyro: onto the corrected accelerometer "
         "frame at the same temperature")
_ACCEL_ORDER = ("scale-bias", "triangular", "affine")
_GYRO_ORDER = ("scale", "affine")


@dataclass(frozen=True)
class ImuPoint:
    """Both sensors' parameters at one temperature point.

    Attributes
    ----------
    temperature, temp_std : float
        Mean and scatter of the temperature over the point's plateaus [degC].
    plateaus : tuple of Plateau
    results : tuple of ImuCalibrationResult
        One per plateau, sample indices those of the whole log.
    accel, accel_cov : ndarray
        Accelerometer parameters (:attr:`~gyrocal.imu.accel.AccelFit.param_names`) and covariance.
    gyro, gyro_cov : ndarray
        Gyro parameters (matrix entries, offset) and covariance.
    """

    temperature: float
    temp_std: float
    plateaus: tuple[Plateau, ...]
    results: tuple[ImuCalibrationResult, ...]
    accel: np.ndarray
    accel_cov: np.ndarray
    gyro: np.ndarray
    gyro_cov: np.ndarray

    @property
    def poses(self) -> int:
        return sum(len(r.statics) for r in self.results)


@dataclass(frozen=True)
class ImuThermalResult:
    """A whole-IMU calibration across temperature.

    Attributes
    ----------
    points : tuple of ImuPoint
        In increasing temperature.
    accel_model, gyro_model : str
        The models every point was fitted with.
    accel, gyro : TemperatureModel
    reference : int
        Index of the point nearest 25 degC: the single-temperature calibration.
    notes : tuple of str
        Plateaus left out and why, and the limits flagged.
    limits : Limits or None
        Hysteresis between the heating and cooling branches, and temperature drift within plateaus
        (:mod:`gyrocal.imu.thermal_limits`).
    """

    points: tuple[ImuPoint, ...]
    accel_model: str
    gyro_model: str
    accel: TemperatureModel
    gyro: TemperatureModel
    reference: int
    notes: tuple[str, ...] = ()
    limits: Limits | None = field(default=None, compare=False)

    def correct_accel(self, readings, temp, scheme: str = "smooth") -> np.ndarray:
        """Specific force (N, 3) [m/s^2] from readings (N, 3) at temperatures (N,) [degC]."""
        p, _ = self.accel.at(temp, scheme)
        a = model_matrices(self.accel_model, p)
        return np.einsum("nij,nj->ni", a, np.asarray(readings, dtype=float) - p[:, -3:])

    def correct_gyro(self, readings, temp, scheme: str = "smooth") -> np.ndarray:
        """Rates (N, 3) [rad/s] from readings (N, 3) at temperatures (N,) [degC] (no g-sensitivity)."""
        p, _ = self.gyro.at(temp, scheme)
        mask = MASKS[self.gyro_model]
        k = int(mask.sum())
        a = np.zeros((len(p), 3, 3))
        a[:, mask] = p[:, :k]
        return np.einsum("nij,nj->ni", a, np.asarray(readings, dtype=float) - p[:, k:k + 3])

    def to_dict(self) -> dict:
        """The ``accelerometer.thermal`` section of the calibration file."""
        return {
            "method": "full-temperature-range: parameters at each point, 3-node Lagrange and smooth polynomial",
            "frame": FRAME,
            "reference_point": self.reference,
            "points": [{"temperature": p.temperature, "temp_std": p.temp_std, "poses": p.poses,
                        "plateaus": [[q.start, q.stop] for q in p.plateaus]} for p in self.points],
            "accelerometer": {"model": self.accel_model, **self.accel.to_dict()},
            "gyro": {"model": self.gyro_model, **self.gyro.to_dict()},
            "notes": list(self.notes),
            **({} if self.limits is None else {"limits": self.limits.to_dict()}),
        }


def _shifted(result: ImuCalibrationResult, start: int) -> ImuCalibrationResult:
    statics = tuple(replace(s, start=s.start + start, stop=s.stop + start) for s in result.statics)
    return replace(result, statics=statics)


def _fit_plateau(t, gyro, accel, plateau: Plateau, gaps, kw) -> ImuCalibrationResult:
    a, b = plateau.start, plateau.stop
    inner = [g - a for g in gaps if a < g < b]
    return _shifted(calibrate_imu(t[a:b], gyro[a:b], accel[a:b], gaps=inner, **kw), a)


def _smallest(models, order) -> str:
    return min(models, key=order.index)


def _harmonise(t, gyro, accel, fitted, gaps, kw, accel_model, gyro_model):
    """Refit the plateaus whose auto-chosen model is larger than the smallest any plateau chose."""
    am = accel_model if accel_model != "auto" else _smallest([r.accel.model for _, r in fitted], _ACCEL_ORDER)
    gm = gyro_model if gyro_model != "auto" else _smallest([r.gyro.model for _, r in fitted], _GYRO_ORDER)
    out = []
    for plateau, r in fitted:
        if r.accel.model != am or r.gyro.model != gm:
            r = _fit_plateau(t, gyro, accel, plateau, gaps, {**kw, "accel_model": am, "gyro_model": gm})
        out.append((plateau, r))
    return out, am, gm


def _point(group: list[tuple[Plateau, ImuCalibrationResult]], sides: list[str], limits: Limits) -> ImuPoint:
    plateaus = tuple(p for p, _ in group)
    results = tuple(r for _, r in group)
    a, a_cov = limits.join("accelerometer", [r.accel.params for r in results], [r.accel.covariance for r in results],
                           sides)
    k = int(MASKS[results[0].gyro.model].sum()) + 3
    g, g_cov = limits.join("gyro", [r.gyro.params[:k] for r in results], [r.gyro.covariance[:k, :k] for r in results],
                           sides)
    weights = np.array([p.stop - p.start for p in plateaus], dtype=float)
    temps = np.array([p.temperature for p in plateaus])
    spread = np.sqrt(np.average([p.temp_std**2 for p in plateaus], weights=weights)
                     + np.average((temps - np.average(temps, weights=weights)) ** 2, weights=weights))
    return ImuPoint(temperature=float(np.average(temps, weights=weights)), temp_std=float(spread),
                    plateaus=plateaus, results=results, accel=a, accel_cov=a_cov, gyro=g, gyro_cov=g_cov)


def calibrate_imu_thermal(t, gyro, accel, temp, *, gravity: float = STANDARD_GRAVITY, accel_model="auto",
                          gyro_model="auto", min_static: float = 1.0, gaps=(), breaks=(), threshold=None,
                          tol: float = 1.0, min_plateau: float = 30.0, max_order: int = 3,
                          sensor_lag: float | None = None, plateaus: list[Plateau] | None = None
                          ) -> ImuThermalResult:
    """Calibrate both sensors at each temperature point of a chamber log and model them in temperature.

    Parameters
    ----------
    t, gyro, accel, gravity, accel_model, gyro_model, min_static, gaps, breaks, threshold :
        As :func:`~gyrocal.imu.session.calibrate_imu` (poses detected, no windows).
    temp : array_like, shape (N,)
        Temperature of each sample [degC].
    tol, min_plateau :
        See :func:`~gyrocal.imu.plateaus.find_plateaus` [degC, s].
    max_order : int
        Highest order of the smooth polynomial tried.
    sensor_lag : float, optional
        Time constant [s] of a temperature sensor that lags the die (:func:`~gyrocal.imu.thermal_limits.lag_corrected`).
    plateaus : list of Plateau, optional
        The parts of the log to calibrate on their own (a ramp's temperature bins,
        :func:`~gyrocal.imu.ramp.ramp_bins`); default :func:`~gyrocal.imu.plateaus.find_plateaus`.

    Raises
    ------
    InputError
        Fewer than 3 temperature points whose poses determine both sensors.
    """
    t, gyro, accel = (np.asarray(x, dtype=float) for x in (t, gyro, accel))
    kw = {"gravity": gravity, "accel_model": accel_model, "gyro_model": gyro_model, "min_static": min_static,
          "threshold": threshold}
    fitted, notes = [], []
    temp = np.asarray(temp, dtype=float)
    if plateaus is None:
        plateaus = find_plateaus(t, temp, breaks=breaks, tol=tol, min_duration=min_plateau)
    for plateau in lag_corrected(t, temp, plateaus, sensor_lag):
        try:
            fitted.append((plateau, _fit_plateau(t, gyro, accel, plateau, gaps, kw)))
        except (DegenerateDesignError, SegmentationError) as exc:
            notes.append(f"plateau at {plateau.temperature:.1f} degC (samples {plateau.start}-{plateau.stop}) "
                         f"left out: {str(exc).splitlines()[0]}")
    if not fitted:
        raise InputError("no temperature plateau holds poses that determine the accelerometer and the gyro")
    fitted, few = too_few_poses(fitted, tol, {"accel": _ACCEL_ORDER, "gyro": _GYRO_ORDER},
                                {"accel": None if accel_model == "auto" else accel_model,
                                 "gyro": None if gyro_model == "auto" else gyro_model})
    notes += few
    fitted, am, gm = _harmonise(t, gyro, accel, fitted, gaps, kw, accel_model, gyro_model)
    groups = temperature_points([p for p, _ in fitted], tol)
    k = int(MASKS[gm].sum()) + 3
    limits = assess(t, temp, fitted, groups, k, tol, sensor_lag)
    sides = branches([p for p, _ in fitted], tol)
    points = tuple(_point([fitted[i] for i in g], [sides[i] for i in g], limits) for g in groups)
    if len(points) < 3:
        raise InputError(f"a model in temperature needs poses at 3 or more temperature points; this log has "
                         f"{len(points)} ({', '.join(f'{p.temperature:.1f}' for p in points)} degC)")
    nodes = [p.temperature for p in points]
    first = points[0].results[0]
    a_model = limits.widen("accelerometer", temperature_model(
        first.accel.param_names, nodes, [p.accel for p in points], [p.accel_cov for p in points], max_order))
    g_model = limits.widen("gyro", temperature_model(first.gyro.param_names[:k], nodes, [p.gyro for p in points],
                                                     [p.gyro_cov for p in points], max_order))
    ref = int(np.argmin(np.abs(np.array(nodes) - 25.0)))
    return ImuThermalResult(points=points, accel_model=am, gyro_model=gm, accel=a_model, gyro=g_model,
                            reference=ref, notes=tuple(notes) + limits.notes() + _misfits(a_model, g_model), limits=limits)


def _misfits(*models: TemperatureModel) -> tuple[str, ...]:
    """A note naming the parameters whose highest order tried misfits the points (1-sigma scaled by it)."""
    bad = [f"{n} x{np.sqrt(k):.2g}" for m in models for n, k in zip(m.names, m.misfit_scale) if k > 1]
    if not bad:
        return ()
    return (f"the smooth model misfits its points at the highest order the points allow, its 1-sigma scaled "
            f"(Birge ratio): {', '.join(bad)}; more temperature points would let it follow them",)


def _smooth_values(doc, temp: np.ndarray) -> np.ndarray:
    """Parameters (N, m) of a file's smooth model (``accelerometer.thermal.<sensor>``), the temperature clamped
    to the points' range."""
    smooth = doc["smooth"]
    nodes = np.asarray(doc["points"]["temperature"], dtype=float)
    u = (np.clip(temp, nodes.min(), nodes.max()) - float(smooth["centre"])) / float(smooth["scale"])
    coefs = np.asarray(smooth["coefs"], dtype=float)
    return np.vander(u, coefs.shape[1], increasing=True) @ coefs.T


def sensor_matrices(section, sensor: str, params) -> tuple[np.ndarray, np.ndarray]:
    """Matrices (N, 3, 3) and offsets (N, 3) of `sensor` (``accelerometer`` or ``gyro``) of a file's
    ``accelerometer.thermal`` section from parameter rows (N, m) in its names' order; linear in the rows."""
    p = np.atleast_2d(np.asarray(params, dtype=float))
    doc = section[sensor]
    if sensor == "gyro":
        mask = MASKS[doc["model"]]
        k = int(mask.sum())
        a = np.zeros((len(p), 3, 3))
        a[:, mask] = p[:, :k]
        return a, p[:, k:k + 3]
    return model_matrices(doc["model"], p), p[:, -3:]


def correct_with_section(doc, gyro, accel, temp) -> tuple[np.ndarray, np.ndarray]:
    """Both sensors corrected by a file's ``accelerometer.thermal`` section at each sample's temperature.

    `gyro` and `accel` are in the section's ``internal`` units; returns rates [rad/s] and specific
    force [m/s^2]. The smooth model is used, its temperature clamped to the points' range (a
    polynomial is not extrapolated).
    """
    temp = np.asarray(temp, dtype=float)
    out = []
    for sensor, raw in (("gyro", gyro), ("accelerometer", accel)):
        a, offset = sensor_matrices(doc, sensor, _smooth_values(doc[sensor], temp))
        out.append(np.einsum("nij,nj->ni", a, np.asarray(raw, dtype=float) - offset))
    return out[0], out[1]
