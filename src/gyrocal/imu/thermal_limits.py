"""Honest limits of a chamber calibration: hysteresis between branches and a temperature sensor still moving.

Hysteresis. A point reached while cooling (colder than the plateau before it in time) is on the
cooling branch, the others on the heating branch. At a temperature point visited on both branches
the two branches' parameters (each joined by inverse covariance) are compared: their difference
``d`` against its covariance ``C_h + C_c`` gives ``chi2 = d^T (C_h + C_c)^-1 d``, summed over such
points (``m`` dof each). Above :data:`HYSTERESIS_P` the branches differ beyond their noise. The
point's joined value then sits between the branches, so a correction evaluated on either branch is
off by about half the difference: that half-width, estimated per parameter as
``h_j^2 / 4`` with ``h_j^2`` the weighted mean of ``d_j^2 - var(d_j)`` over the points (not below 0),
is added to the variance of the smooth model's constant coefficient (a variance at every temperature
alike, since the branches' difference is measured at the shared points only). The points are then
joined on the mid-branch (:meth:`Limits.join`): an inverse-covariance mean of two branches that
disagree in the offsets would move the parameters correlated with them (the matrix) as well.

A lagging temperature sensor. While the die follows the chamber, a sensor that lags it still moves
during a plateau's poses. Each plateau's temperature drift is the slope of a straight line through
its readings (white reading noise: the slope's standard error from the residuals) times its length;
a drift beyond :data:`DRIFT_LIMIT` and beyond :data:`DRIFT_Z` times its 1-sigma is flagged. The
reading then trails the die by ``tau`` times the slope (``y - T_die = -tau y'`` for a first-order lag), and
``tau`` is not measurable from a plateau much shorter than it (the curvature ``y'' = -y' / tau`` is below the
reading noise): the flag says so, and with ``tau`` known (a datasheet, a step test) :func:`lag_corrected`
moves each plateau's temperature to the die's, ``mean + tau * slope``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .._chi2 import chi2_sf
from .plateaus import Plateau

__all__ = ["DRIFT_LIMIT", "DRIFT_Z", "HYSTERESIS_P", "Drift", "Hysteresis", "Limits", "assess", "branches", "die_temperature",
           "hysteresis", "lag_corrected", "plateau_drift", "too_few_poses"]

#: Branches whose difference has a chi-square p-value below this are flagged as hysteresis.
HYSTERESIS_P = 1e-3
#: A plateau whose temperature moves more than this over its poses is flagged [degC] (a lag ``tau`` much
#: longer than the plateau puts the reading ``tau / duration`` times this behind the die) ...
DRIFT_LIMIT = 0.05
#: ... when the move is also this many times its own 1-sigma.
DRIFT_Z = 5.0


@dataclass(frozen=True)
class Hysteresis:
    """Difference of the cooling branch from the heating branch of one sensor's parameters.

    Attributes
    ----------
    temperatures : tuple of float
        Points visited on both branches [degC].
    names : tuple of str
    difference, std : ndarray, shape (m,)
        Inverse-variance mean of cooling minus heating over those points, and its 1-sigma.
    chi2 : float
        Of all the points' differences against their covariances, ``dof`` degrees of freedom.
    dof : int
    p_value : float
    extra_variance : ndarray, shape (m,)
        ``h^2 / 4`` per parameter, added to the model's variance when flagged (zero otherwise).
    """

    temperatures: tuple[float, ...]
    names: tuple[str, ...]
    difference: np.ndarray
    std: np.ndarray
    chi2: float
    dof: int
    p_value: float
    extra_variance: np.ndarray

    @property
    def flagged(self) -> bool:
        return self.p_value < HYSTERESIS_P

    def to_dict(self) -> dict:
        return {"flag": "hysteresis" if self.flagged else "none", "temperatures": list(self.temperatures),
                "names": list(self.names), "cooling_minus_heating": self.difference.tolist(),
                "std": self.std.tolist(), "chi2": self.chi2, "dof": self.dof, "p_value": self.p_value,
                "half_width_std_added": np.sqrt(self.extra_variance).tolist(),
                "equation": "cooling-branch parameters minus heating-branch parameters at the same point; when "
                            "flagged, half_width_std_added^2 is in the smooth model's constant coefficient's variance"}

    def describe(self, sensor: str) -> str:
        """One line: the size of the difference and what was done."""
        big = int(np.argmax(np.abs(self.difference) / self.std))
        size = (f"largest {self.names[big]} {self.difference[big]:+.3g} ±{self.std[big]:.2g}; chi2 {self.chi2:.1f} "
                f"for {self.dof} dof (p = {self.p_value:.2g}) at {', '.join(f'{t:.1f}' for t in self.temperatures)}"
                " degC")
        if not self.flagged:
            return f"{sensor}: heating and cooling branches agree within their noise ({size})"
        return (f"{sensor}: hysteresis, the cooling branch differs from the heating branch ({size}); the model is "
                "the mid-branch one and the half-width is added to its 1-sigma")


def branches(plateaus: list[Plateau], tol: float = 1.0) -> list[str]:
    """``heating`` or ``cooling`` for each plateau in time order: cooling when colder than the one before by
    more than `tol` [degC], else the branch of the one before (the first: heating)."""
    out: list[str] = []
    for k, p in enumerate(plateaus):
        step = 0.0 if k == 0 else p.temperature - plateaus[k - 1].temperature
        out.append("cooling" if step < -tol else "heating" if step > tol or k == 0 else out[-1])
    return out


def _join(params, covs):
    if len(params) == 1:
        return params[0], covs[0]
    info = [np.linalg.inv(c) for c in covs]
    cov = np.linalg.inv(sum(info))
    return cov @ sum(i @ p for i, p in zip(info, params)), cov


def hysteresis(groups: list[list[int]], plateaus: list[Plateau], params, covs, names, tol: float = 1.0):
    """The :class:`Hysteresis` of one sensor, or None when no point was visited on both branches.

    `groups` are the plateau indices of each point; `params` and `covs` each plateau's parameters (m,)
    and covariance (m, m), in the plateaus' time order.
    """
    side = branches(plateaus, tol)
    temps, diffs, dcovs = [], [], []
    for g in groups:
        h = [k for k in g if side[k] == "heating"]
        c = [k for k in g if side[k] == "cooling"]
        if h and c:
            (ph, ch), (pc, cc) = (_join([params[k] for k in s], [covs[k] for k in s]) for s in (h, c))
            temps.append(float(np.mean([plateaus[k].temperature for k in g])))
            diffs.append(pc - ph)
            dcovs.append(ch + cc)
    if not diffs:
        return None
    d, c = np.array(diffs), np.array(dcovs)
    chi2 = float(sum(x @ np.linalg.solve(v, x) for x, v in zip(d, c)))
    dof = int(d.size)
    var = np.einsum("kjj->kj", c)
    w = 1.0 / var
    mean = (w * d).sum(axis=0) / w.sum(axis=0)
    std = 1.0 / np.sqrt(w.sum(axis=0))
    p = chi2_sf(dof, chi2)
    h2 = np.maximum((w * (d**2 - var)).sum(axis=0) / w.sum(axis=0), 0.0)
    extra = h2 / 4 if p < HYSTERESIS_P else np.zeros_like(h2)
    return Hysteresis(tuple(temps), tuple(names), mean, std, chi2, dof, p, extra)


@dataclass(frozen=True)
class Drift:
    """How much a plateau's temperature reading moved over its poses.

    Attributes
    ----------
    temperature : float
        The plateau's mean reading [degC].
    rate, rate_std : float
        Slope of the readings and its 1-sigma [degC/s].
    duration : float
        [s].
    """

    temperature: float
    rate: float
    rate_std: float
    duration: float

    @property
    def drift(self) -> float:
        return self.rate * self.duration

    @property
    def flagged(self) -> bool:
        return abs(self.drift) > DRIFT_LIMIT and abs(self.rate) > DRIFT_Z * self.rate_std

    def to_dict(self) -> dict:
        return {"temperature": self.temperature, "rate_degC_per_s": self.rate, "rate_std": self.rate_std,
                "drift_degC": self.drift, "duration_s": self.duration}


def plateau_drift(t, temp, plateau: Plateau) -> Drift:
    """The straight-line slope of a plateau's temperature readings, with its standard error."""
    tt = np.asarray(t[plateau.start:plateau.stop], dtype=float)
    y = np.asarray(temp[plateau.start:plateau.stop], dtype=float)
    x = tt - tt.mean()
    sxx = float(x @ x)
    rate = float(x @ (y - y.mean())) / sxx
    resid = y - y.mean() - rate * x
    sd = float(np.sqrt(resid @ resid / max(len(y) - 2, 1) / sxx))
    return Drift(plateau.temperature, rate, sd, float(tt[-1] - tt[0]))


@dataclass(frozen=True)
class Limits:
    """What a chamber log says about the limits of its temperature model.

    Attributes
    ----------
    accelerometer, gyro : Hysteresis or None
        None: no point was visited on both branches.
    drifts : tuple of Drift
        One per plateau fitted, in time order.
    sensor_lag : float or None
        Time constant [s] the plateaus' temperatures were corrected for (:func:`lag_corrected`).
    """

    accelerometer: Hysteresis | None
    gyro: Hysteresis | None
    drifts: tuple[Drift, ...]
    sensor_lag: float | None = None

    def widen(self, sensor: str, model):
        """`model` (a :class:`~gyrocal.imu.thermal_model.TemperatureModel`) with the sensor's hysteresis
        half-width in its 1-sigma when flagged."""
        h = getattr(self, sensor)
        return model.with_constant_variance(h.extra_variance) if h is not None and h.flagged else model

    def join(self, sensor: str, params, covs, sides) -> tuple[np.ndarray, np.ndarray]:
        """One point's parameters from its plateaus' `params` and `covs` on branches `sides`: the inverse-covariance
        mean, or, when the sensor's hysteresis is flagged, the mid-branch value (the mean of the two branches'
        joined values; a point seen on one branch only moved by half the measured difference towards the other,
        that half's variance added), so the branches' offset difference does not leak into correlated parameters."""
        h = getattr(self, sensor)
        if h is None or not h.flagged:
            return _join(params, covs)
        joined = {b: _join([p for p, s in zip(params, sides) if s == b], [c for c, s in zip(covs, sides) if s == b])
                  for b in ("heating", "cooling") if b in sides}
        if len(joined) == 2:
            (ph, ch), (pc, cc) = joined["heating"], joined["cooling"]
            return (ph + pc) / 2, (ch + cc) / 4
        (b, (p, c)), = joined.items()
        sign = 1.0 if b == "heating" else -1.0
        return p + sign * h.difference / 2, c + np.diag(h.std**2 / 4)

    def notes(self) -> tuple[str, ...]:
        """One line per flag (hysteresis, a sensor still moving); branches that agree are not worth a line."""
        out = [h.describe(s) for s, h in (("accelerometer", self.accelerometer), ("gyro", self.gyro))
               if h is not None and h.flagged]
        moving = [d for d in self.drifts if d.flagged]
        if moving:
            worst = max(moving, key=lambda d: abs(d.drift))
            what = (f"each plateau's temperature moved to the die's for a sensor lag of {self.sensor_lag:g} s "
                    "(mean + lag x rate)" if self.sensor_lag else
                    "a sensor that lags the die reads behind it by its time constant times the rate, which is not "
                    "in the model's 1-sigma; soak longer, read the die's own sensor, or give the sensor's lag")
            out.append(f"temperature still moving during the poses of {len(moving)} of {len(self.drifts)} plateaus "
                       f"(largest {worst.drift:+.2f} degC over {worst.duration:.0f} s at {worst.temperature:.1f} "
                       f"degC): {what}")
        return tuple(out)

    def to_dict(self) -> dict:
        """The file's ``limits`` entry: the flags, each with its measured size and 1-sigma."""
        flags = [f"hysteresis: {s}" for s, h in (("accelerometer", self.accelerometer), ("gyro", self.gyro))
                 if h is not None and h.flagged]
        if any(d.flagged for d in self.drifts):
            flags.append("temperature moving during plateaus")
        return {"flags": flags,
                "hysteresis": {s: None if h is None else h.to_dict()
                               for s, h in (("accelerometer", self.accelerometer), ("gyro", self.gyro))},
                "temperature_drift": {"limit_degC": DRIFT_LIMIT, "z": DRIFT_Z, "sensor_lag_s": self.sensor_lag,
                                      "plateaus": [{**d.to_dict(), "flagged": d.flagged} for d in self.drifts]}}


def assess(t, temp, fitted, groups, gyro_params: int, tol: float = 1.0, sensor_lag: float | None = None) -> Limits:
    """The :class:`Limits` of plateau fits `fitted` ((Plateau, ImuCalibrationResult) in time order) joined into
    points `groups`; the gyro's first `gyro_params` parameters are its model's."""
    plateaus = [p for p, _ in fitted]
    results = [r for _, r in fitted]
    k = gyro_params
    acc = hysteresis(groups, plateaus, [r.accel.params for r in results], [r.accel.covariance for r in results],
                     results[0].accel.param_names, tol)
    gyr = hysteresis(groups, plateaus, [r.gyro.params[:k] for r in results],
                     [r.gyro.covariance[:k, :k] for r in results], results[0].gyro.param_names[:k], tol)
    return Limits(acc, gyr, tuple(plateau_drift(t, temp, p) for p in plateaus), sensor_lag or None)


def _rank(model: str, order) -> int:
    return order.index(model)


def too_few_poses(fitted, tol: float, orders: dict, fixed: dict) -> tuple[list, list[str]]:
    """Leave out the plateaus whose poses determine a smaller model than the others', with a note each.

    `orders` maps ``accel``/``gyro`` to their models, smallest first; `fixed` to the model given (None: auto).
    Under auto every point takes the smallest model any plateau chose, so one plateau with too few poses
    would take the parameters it cannot determine from every point. A plateau below the largest model that
    plateaus at 3 or more (and at least half the) temperature points chose is left out instead, when that
    leaves such points; otherwise all are kept and the smaller model is said in a note.
    """
    from .plateaus import temperature_points

    def model_of(r, sensor):
        return r.accel.model if sensor == "accel" else r.gyro.model

    def n_points(items):
        return len(temperature_points([p for p, _ in items], tol)) if items else 0

    total = n_points(fitted)
    best = {}
    for sensor, order in orders.items():
        if fixed[sensor] is not None:
            continue
        for m in reversed(order):
            full = [f for f in fitted if _rank(model_of(f[1], sensor), order) >= _rank(m, order)]
            if n_points(full) >= max(3, (total + 1) // 2):
                best[sensor] = m
                break
    full = [all(_rank(model_of(r, s), orders[s]) >= _rank(m, orders[s]) for s, m in best.items())
            for _, r in fitted]
    keep = [f for f, ok in zip(fitted, full) if ok]
    dropped = [f for f, ok in zip(fitted, full) if not ok]
    if not dropped:
        return fitted, []
    if n_points(keep) < 3:
        return fitted, [f"plateau at {p.temperature:.1f} degC ({len(r.statics)} poses) determines only the "
                        f"{r.accel.model} accelerometer and {r.gyro.model} gyro models; every point takes them"
                        for p, r in dropped]
    return keep, [f"plateau at {p.temperature:.1f} degC (samples {p.start}-{p.stop}) left out: its "
                  f"{len(r.statics)} poses determine only the {r.accel.model} accelerometer and {r.gyro.model} "
                  f"gyro models, the others' {best.get('accel', r.accel.model)} and {best.get('gyro', r.gyro.model)}"
                  for p, r in dropped]


def lag_corrected(t, temp, plateaus: list[Plateau], tau: float | None) -> list[Plateau]:
    """`plateaus` with each temperature moved to the die's for a sensor lagging it by `tau` [s]: the mean reading
    plus `tau` times the readings' slope (None or 0: unchanged)."""
    if not tau:
        return plateaus
    return [replace(p, temperature=p.temperature + tau * plateau_drift(t, temp, p).rate) for p in plateaus]


def die_temperature(t, temp, tau: float, window: float = 60.0) -> np.ndarray:
    """Readings (N,) moved to the die's temperature for a sensor lagging it by `tau` [s]: each plus `tau` times
    the readings' local slope, a least-squares line over `window` seconds centred on it (a first-order lag
    ``dT_s/dt = (T_die - T_s) / tau``)."""
    t, temp = np.asarray(t, dtype=float), np.asarray(temp, dtype=float)
    x = t - t.mean()
    lo = np.searchsorted(t, t - window / 2)
    hi = np.searchsorted(t, t + window / 2, side="right")
    sums = [np.concatenate(([0.0], np.cumsum(v))) for v in (np.ones_like(x), x, temp, x * temp, x * x)]
    n, sx, sy, sxy, sxx = (c[hi] - c[lo] for c in sums)
    den = n * sxx - sx * sx
    slope = np.divide(n * sxy - sx * sy, den, out=np.zeros_like(den), where=den > 0)
    return temp + tau * slope
