"""How well an IMU thermal calibration corrects a test chamber log, against the single-temperature baseline.

The test log is a pose session at any temperatures in the calibrated range (still poses, turns
between them). Its still poses are found as ``gyrocal imu`` finds them
(:func:`~gyrocal.imu.statics.detect_statics`); each pose's mean readings and mean temperature are
corrected by every scheme of the file's ``accelerometer.thermal`` section:

* ``single``: the point nearest 25 degC (the reference point) at every temperature, the baseline;
* ``lagrange``: the full-temperature-range method's 3-node Lagrange interpolation of the points;
* ``smooth``: the smooth polynomial per parameter (temperature clamped to the points' range).

Still, the corrected accelerometer's magnitude is gravity and the corrected gyro reads no rate (the
Earth's 7.3e-5 rad/s aside), whatever the orientation, so no reference is needed: the errors are
``|f| - g`` [m/s^2] and the still rate's three components [rad/s]. The smooth model's own 1-sigma of
``|f|`` (its parameters' covariance at that temperature through ``|A (u - o)|``, plus the pose
mean's noise) gives a z per pose: RMS z near 1 says the reported 1-sigma holds between the points.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..thermal.lagrange import lagrange_weights
from .statics import detect_statics
from .thermal import _smooth_values, sensor_matrices

__all__ = ["SCHEMES", "PoseErrors", "evaluate_imu_thermal"]

SCHEMES = ("single", "lagrange", "smooth")


@dataclass(frozen=True)
class PoseErrors:
    """Each still pose's errors under each scheme.

    Attributes
    ----------
    temperature : ndarray, shape (n,)
        Mean temperature of each pose [degC].
    accel : dict of str to ndarray, shape (n,)
        ``|f| - g`` per scheme [m/s^2].
    gyro : dict of str to ndarray, shape (n, 3)
        Still rate per scheme [rad/s].
    accel_z : ndarray, shape (n,)
        The smooth scheme's ``|f| - g`` over its 1-sigma.
    raw_accel : ndarray, shape (n, 3)
        Each pose's mean accelerometer reading [internal units].
    """

    temperature: np.ndarray
    accel: dict
    gyro: dict
    accel_z: np.ndarray
    raw_accel: np.ndarray

    def summary(self) -> list[dict]:
        """One row per scheme: RMS of ``|f| - g`` and of the still rate, and the improvement on the baseline."""
        base_a, base_g = _rms(self.accel["single"]), _rms(self.gyro["single"])
        return [{"scheme": s, "poses": len(self.temperature), "accel_rms_m_s2": _rms(self.accel[s]),
                 "accel_factor": base_a / _rms(self.accel[s]), "gyro_rms_rad_s": _rms(self.gyro[s]),
                 "gyro_factor": base_g / _rms(self.gyro[s])} for s in SCHEMES]

    def by_temperature(self, tol: float = 1.0) -> list[dict]:
        """RMS per scheme at each test temperature (poses within `tol` degC of one another)."""
        order = np.argsort(self.temperature)
        groups, rows = [], []
        for k in order:
            if groups and self.temperature[k] - self.temperature[groups[-1][-1]] <= tol:
                groups[-1].append(k)
            else:
                groups.append([k])
        for g in groups:
            row = {"temperature": float(np.mean(self.temperature[g])), "poses": len(g)}
            row.update({f"{s}_accel_rms": _rms(self.accel[s][g]) for s in SCHEMES})
            row.update({f"{s}_gyro_rms": _rms(self.gyro[s][g]) for s in SCHEMES})
            row["smooth_accel_rms_z"] = _rms(self.accel_z[g])
            rows.append(row)
        return rows


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def _params(doc, temp: np.ndarray, scheme: str, reference: int) -> np.ndarray:
    """Parameters (N, m) of one sensor's part of the section at temperatures (N,) by `scheme`."""
    values = np.asarray(doc["points"]["values"], dtype=float)
    if scheme == "single":
        return np.tile(values[reference], (len(temp), 1))
    if scheme == "smooth":
        return _smooth_values(doc, temp)
    idx, w = lagrange_weights(np.asarray(doc["points"]["temperature"], dtype=float), temp, "clamp")
    return np.einsum("nk,nkj->nj", w, values[idx])


def _smooth_param_cov(doc, temp: np.ndarray) -> np.ndarray:
    """Covariance (N, m, m) of the smooth parameters at temperatures (N,) (clamped to the points' range)."""
    sm = doc["smooth"]
    nodes = np.asarray(doc["points"]["temperature"], dtype=float)
    coefs = np.asarray(sm["coefs"], dtype=float)
    m, width = coefs.shape
    u = (np.clip(temp, nodes.min(), nodes.max()) - float(sm["centre"])) / float(sm["scale"])
    powers = np.vander(u, width, increasing=True)
    cov = np.asarray(sm["covariance"], dtype=float).reshape(m, width, m, width)
    return np.einsum("np,ipjq,nq->nij", powers, cov, powers)


def _magnitude(section, params, raw) -> np.ndarray:
    a, o = sensor_matrices(section, "accelerometer", params)
    return np.linalg.norm(np.einsum("nij,nj->ni", a, raw - o), axis=1)


def _magnitude_sigma(section, params, cov, raw, raw_se) -> np.ndarray:
    """1-sigma (N,) of ``|A (u - o)|`` from the parameters' covariance (N, m, m) and the pose means' noise
    (central differences: ``|f|`` is smooth and nearly linear over a parameter's 1-sigma)."""
    def grad(x, fn):
        out = np.empty_like(x)
        for j in range(x.shape[1]):
            step = np.zeros(x.shape[1])
            step[j] = 1e-6 * max(1.0, float(np.abs(x[:, j]).max()))
            out[:, j] = (fn(x + step) - fn(x - step)) / (2 * step[j])
        return out

    jac = grad(params, lambda p: _magnitude(section, p, raw))
    d_u = grad(raw, lambda u: _magnitude(section, params, u))
    var = np.einsum("ni,nij,nj->n", jac, cov, jac) + np.sum((d_u * raw_se) ** 2, axis=1)
    return np.sqrt(var)


def evaluate_imu_thermal(section, t, gyro, accel, temp, *, gravity: float, breaks=(),
                         min_static: float = 1.0) -> PoseErrors:
    """Errors of each still pose of a test log under each scheme of `section` (``accelerometer.thermal``).

    `gyro` and `accel` are in the section's ``internal`` units, `temp` in degC, `gravity` in m/s^2.
    """
    t, gyro, accel, temp = (np.asarray(x, dtype=float) for x in (t, gyro, accel, temp))
    statics = detect_statics(t, gyro, accel, min_duration=min_static, breaks=breaks).statics
    raw_a = np.array([s.accel_mean for s in statics])
    raw_g = np.array([s.gyro_mean for s in statics])
    se = np.array([s.accel_se for s in statics])
    temps = np.array([temp[s.start:s.stop].mean() for s in statics])
    ref = int(section["reference_point"])
    out_a, out_g = {}, {}
    for scheme in SCHEMES:
        for sensor, raw, out in (("accelerometer", raw_a, out_a), ("gyro", raw_g, out_g)):
            a, o = sensor_matrices(section, sensor, _params(section[sensor], temps, scheme, ref))
            out[scheme] = np.einsum("nij,nj->ni", a, raw - o)
        out_a[scheme] = np.linalg.norm(out_a[scheme], axis=1) - gravity
    p = _params(section["accelerometer"], temps, "smooth", ref)
    sigma = _magnitude_sigma(section, p, _smooth_param_cov(section["accelerometer"], temps), raw_a, se)
    return PoseErrors(temperature=temps, accel=out_a, gyro=out_g, accel_z=out_a["smooth"] / sigma, raw_accel=raw_a)
