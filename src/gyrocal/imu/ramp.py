"""The whole IMU on a temperature ramp: every still pose at its own temperature, the model fitted across them.

Many chambers cannot hold plateaus, so the board is turned through its poses while the temperature
drifts. :func:`is_ramp` tells such a log from one of plateaus (most of its time in windows of
:data:`RAMP_WINDOW` s whose temperature trend moves more than ``tol``). :func:`calibrate_ramp` then

* cuts the log into temperature bins (:func:`ramp_bins`, contiguous runs within one bin of the
  temperature range) and calibrates each bin as a plateau (:func:`~gyrocal.imu.thermal.calibrate_imu_thermal`):
  each bin's poses and hand turns give both sensors there, and the gyro's parameters (its bias from
  the bin's still poses, its matrix from the turns between them) at the bins' mean temperatures become
  its model in temperature exactly as on plateaus. A bias that drifts linearly across a bin averages
  to its value at the bin's mean temperature;
* fits the accelerometer directly across every still pose of every bin, each at the mean of its own
  temperature readings: its parameters (``A`` in Tedaldi's frame, ``o``) are polynomials in
  ``u = (T - centre) / scale``, and the coefficients minimise ``sum ((|A(T_p) (u_p - o(T_p))| - g) / s_p)^2``
  (``s_p`` from the pose's own noise). One order serves all parameters: it starts at the highest tried
  and drops while the Wald test of the top power's coefficients, all parameters together, finds them
  zero (p-value above :data:`DROP_P`); dropping terms one parameter at a time by their own z-scores
  left too many several-sigma errors in simulations. The coefficients' covariance is the fit's
  (Birge-scaled when the residuals exceed the noise) plus ``d d^T``, ``d`` the coefficients' difference
  from the highest-order fit: the error the lower orders may carry, as on plateaus
  (:mod:`gyrocal.imu.thermal_model`);
* writes both models with their points sampled at :data:`NODES` temperatures spanning the poses (so the
  file's clamp to its points is the ramp's range, and ``apply`` and ``export`` read it as any other).

A pose's parameters vary with temperature along the pose; for parameters linear over that change its
mean reading is the reading at its mean temperature. A pose whose temperature moves more than
:data:`POSE_DRIFT` is said in the notes, and so is the ramp rate: a temperature sensor that lags the
sensors by ``tau`` reads ``rate * tau`` off on a ramp, which one ramp direction cannot reveal.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy import stats
from scipy.ndimage import uniform_filter1d
from scipy.optimize import least_squares

from .._arrays import distinct, median
from ..errors import InputError
from ..thermal.smooth import SmoothModel, loto_errors
from ..units import STANDARD_GRAVITY
from . import _fit
from .accel import MIN_DOF, model_matrices, param_names
from .plateaus import Plateau
from .thermal import ImuThermalResult, calibrate_imu_thermal
from .thermal_model import TemperatureModel

__all__ = ["ImuRampResult", "calibrate_ramp", "fit_ramp_accel", "is_ramp", "ramp_bins", "sampled"]

#: Window over which a ramp's temperature trend is measured [s] (about one cycle of poses).
RAMP_WINDOW = 300.0
#: Shortest bin [s] and most bins of a ramp.
MIN_BIN_S, MAX_BINS = 120.0, 8
#: Temperatures at which the file's points sample the models.
NODES = 7
#: A pose whose temperature trend moves more than this is noted [degC].
POSE_DRIFT = 0.5
#: Temperature readings smoothed over this before they are binned [s].
_SMOOTH_S = 5.0
#: The highest power is dropped while the Wald test of its coefficients (all parameters together) has a
#: p-value above this: the data show no need for it.
DROP_P = 0.05


def _parts(n: int, breaks) -> list[tuple[int, int]]:
    edges = [0, *sorted(int(b) for b in breaks if 0 < b < n), n]
    return [(a, b) for a, b in zip(edges[:-1], edges[1:]) if b - a > 1]


def _slope(t: np.ndarray, y: np.ndarray) -> float:
    tc = t - t.mean()
    den = float(tc @ tc)
    return float(tc @ (y - y.mean()) / den) if den > 0 else 0.0


def is_ramp(t, temp, breaks=(), tol: float = 1.0, window: float = RAMP_WINDOW) -> bool:
    """Whether most samples lie in windows of `window` s whose temperature trend moves more than `tol` [degC]."""
    t, temp = np.asarray(t, dtype=float), np.asarray(temp, dtype=float)
    drifting = 0
    for a, b in _parts(len(t), breaks):
        chunk = np.floor((t[a:b] - t[a]) / window).astype(int)
        for k in distinct(chunk):
            sel = np.flatnonzero(chunk == k) + a
            if len(sel) > 2 and abs(_slope(t[sel], temp[sel])) * window > tol:
                drifting += len(sel)
    return drifting > 0.5 * len(t)


def ramp_bins(t, temp, breaks=(), n_bins: int | None = None, min_duration: float = 30.0) -> list[Plateau]:
    """Contiguous runs of a ramp within one of `n_bins` equal bins of its temperature range, in time order.

    Default `n_bins`: one per :data:`MIN_BIN_S` of log, 3 to :data:`MAX_BINS`.
    """
    t, temp = np.asarray(t, dtype=float), np.asarray(temp, dtype=float)
    parts = _parts(len(t), breaks)
    if n_bins is None:
        span = sum(t[b - 1] - t[a] for a, b in parts)
        n_bins = int(np.clip(span // MIN_BIN_S, 3, MAX_BINS))
    fs = (len(t) - 1) / max(t[-1] - t[0], 1e-9)
    smooth = np.concatenate([uniform_filter1d(temp[a:b], max(1, int(_SMOOTH_S * fs)), mode="nearest")
                             for a, b in parts])
    offset = parts[0][0]
    edges = np.linspace(smooth.min(), smooth.max(), n_bins + 1)
    idx = np.clip(np.searchsorted(edges, smooth, side="right") - 1, 0, n_bins - 1)
    cuts = sorted({offset, *(np.flatnonzero(np.diff(idx)) + 1 + offset), *(a for a, _ in parts),
                   *(b for _, b in parts)})
    out = []
    for i, j in zip(cuts[:-1], cuts[1:]):
        if j - i > 1 and t[j - 1] - t[i] >= min_duration:
            out.append(Plateau(int(i), int(j), float(temp[i:j].mean()), float(temp[i:j].std())))
    return out


def _mask(model: str) -> np.ndarray:
    k = len(param_names(model))
    return model_matrices(model, np.ones(k))[0] != 0


@dataclass(frozen=True)
class RampFit:
    """The accelerometer's joint fit across the poses of a ramp.

    Attributes
    ----------
    coefs : ndarray, shape (m, P + 1)
        Of ``u^0..u^P`` per parameter (zero above its order).
    covariance : ndarray, shape (m * (P + 1), m * (P + 1))
        Of ``coefs.ravel()``, the order choice's error included.
    orders : ndarray of int, shape (m,)
    centre, scale : float
        ``u = (T - centre) / scale`` [degC].
    quality : FitQuality
        Of the chosen orders' fit (one residual per pose).
    """

    coefs: np.ndarray
    covariance: np.ndarray
    orders: np.ndarray
    centre: float
    scale: float
    quality: _fit.FitQuality


class _Problem:
    """Residuals and Jacobian of the magnitude fit with parameters polynomial in temperature."""

    def __init__(self, u, se, x, model, gravity, top):
        self.u, self.se, self.model, self.g = u, se, model, gravity
        self.powers = x[:, None] ** np.arange(top + 1)
        self.mask = _mask(model)
        self.m = len(param_names(model))

    def params(self, coefs):
        return self.powers @ coefs.T

    def _parts(self, coefs):
        q = self.params(coefs)
        a = model_matrices(self.model, q)
        v = self.u - q[:, -3:]
        f = np.einsum("nij,nj->ni", a, v)
        return a, v, f, f / np.linalg.norm(f, axis=1, keepdims=True)

    def sigma(self, coefs):
        a, _, _, n = self._parts(coefs)
        return np.sqrt(np.einsum("pj,pj->p", np.einsum("pi,pij->pj", n, a) ** 2, self.se**2))

    def resid(self, coefs, s):
        _, _, f, _ = self._parts(coefs)
        return (np.linalg.norm(f, axis=1) - self.g) / s

    def jac(self, coefs, s, active):
        a, v, _, n = self._parts(coefs)
        d_a = (n[:, :, None] * v[:, None, :])[:, self.mask]
        d_q = np.column_stack([d_a, -np.einsum("pi,pij->pj", n, a)]) / s[:, None]
        return (d_q[:, :, None] * self.powers[:, None, :])[:, active]


def _solve(prob: _Problem, coefs0: np.ndarray, active: np.ndarray):
    """Least squares over the active coefficients, weights from the estimate (twice); coefs, Jacobian, residuals."""
    coefs = np.where(active, coefs0, 0.0)

    def full(theta):
        c = np.zeros_like(coefs)
        c[active] = theta
        return c

    for _ in range(2):
        s = prob.sigma(coefs)
        sol = least_squares(lambda th, w: prob.resid(full(th), w), coefs[active],
                            jac=lambda th, w: prob.jac(full(th), w, active), args=(s,), method="lm", xtol=1e-14,
                            ftol=1e-14, gtol=1e-14)
        coefs = full(sol.x)
    return coefs, prob.jac(coefs, s, active), prob.resid(coefs, s)


def _embed(cov_active: np.ndarray, active: np.ndarray) -> np.ndarray:
    idx = np.flatnonzero(active.ravel())
    out = np.zeros((active.size, active.size))
    out[np.ix_(idx, idx)] = cov_active
    return out


def fit_ramp_accel(means, se, temps, model: str, *, gravity: float = STANDARD_GRAVITY, max_order: int = 3,
                   start=None) -> RampFit:
    """Fit the accelerometer's parameters as polynomials in temperature to poses at temperatures `temps`.

    Parameters
    ----------
    means, se : array_like, shape (n, 3)
        Each pose's mean reading and its standard error [reading units].
    temps : array_like, shape (n,)
        Each pose's mean temperature [degC].
    model : {"scale-bias", "triangular"}
    max_order : int
        Highest order tried, lowered until the poses leave :data:`~gyrocal.imu.accel.MIN_DOF` spare equations.
    start : ndarray, shape (m, max_order + 1), optional
        Starting coefficients (in the returned centre and scale); default a unit matrix, zero offset.
    """
    u, se, temps = (np.asarray(a, dtype=float) for a in (means, se, temps))
    if model not in ("scale-bias", "triangular"):
        raise InputError(f"a ramp's accelerometer fit takes scale-bias or triangular, got {model!r}")
    m = len(param_names(model))
    if len(u) < m + MIN_DOF:
        raise InputError(f"a ramp's accelerometer fit needs {m + MIN_DOF} poses or more, got {len(u)}")
    max_order = min(int(max_order), (len(u) - MIN_DOF) // m - 1)  # every order with MIN_DOF spare equations
    centre, scale = float((temps.max() + temps.min()) / 2), float(max(np.ptp(temps) / 2, 1e-9))
    prob = _Problem(u, se, (temps - centre) / scale, model, gravity, max_order)
    if start is None:
        start = np.zeros((prob.m, max_order + 1))
        start[[i for i, n in enumerate(param_names(model)) if n in ("A_xx", "A_yy", "A_zz")], 0] = 1.0
    order = max_order
    active = np.arange(max_order + 1)[None, :] <= np.full((prob.m, 1), order)
    top, jac, r = _solve(prob, start[:, : max_order + 1], active)
    coefs = top
    while True:
        q = _fit.quality(r, int(active.sum()), "accelerometer fit across the ramp")
        cov = _embed(_fit.covariance(jac, q), active)
        block = np.arange(prob.m) * (max_order + 1) + order
        c = coefs[:, order]
        wald = float(c @ np.linalg.solve(cov[np.ix_(block, block)], c)) if order > 0 else np.inf
        if not stats.chi2.sf(wald, prob.m) > DROP_P:
            break
        order -= 1
        active = np.arange(max_order + 1)[None, :] <= np.full((prob.m, 1), order)
        coefs, jac, r = _solve(prob, coefs, active)
    orders = np.full(prob.m, order)
    d = (top - coefs).ravel()
    return RampFit(coefs=coefs, covariance=cov + np.outer(d, d), orders=orders, centre=centre, scale=scale, quality=q)


def sampled(model: TemperatureModel, nodes) -> TemperatureModel:
    """`model` with its points replaced by its smooth polynomials at `nodes` [degC] (values and full covariance)."""
    nodes = np.asarray(nodes, dtype=float)
    width, m = model.smooth.coefs.shape[1], len(model.names)
    powers = np.vander((nodes - model.smooth.centre) / model.smooth.scale, width, increasing=True)
    gain = np.einsum("ij,np->nijp", np.eye(m), powers).reshape(len(nodes), m, m * width)
    covs = gain @ model.smooth_covariance @ gain.transpose(0, 2, 1)
    return replace(model, nodes=nodes, values=model.smooth(nodes), covariances=covs)


@dataclass(frozen=True)
class ImuRampResult(ImuThermalResult):
    """A whole-IMU calibration on a temperature ramp: :class:`ImuThermalResult` whose points are the ramp's
    temperature bins, with the accelerometer fitted across all poses; `ramp` says how (the file's ``ramp``)."""

    ramp: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        out = super().to_dict()
        out["method"] = ("temperature ramp: each still pose at its own mean temperature, the accelerometer's "
                         "parameters fitted as polynomials in temperature across all poses; the gyro at each "
                         "temperature bin, modelled as on plateaus; points: the models sampled across the poses")
        out["ramp"] = self.ramp
        return out


def _bin_start(base: ImuThermalResult, centre: float, scale: float, top: int) -> np.ndarray:
    """Starting coefficients: the bins' accelerometer parameters fitted by a polynomial in the joint fit's u."""
    x = (np.array([p.temperature for p in base.points]) - centre) / scale
    order = min(top, len(x) - 1)
    coef, *_ = np.linalg.lstsq(np.vander(x, order + 1, increasing=True), np.array([p.accel for p in base.points]),
                               rcond=None)
    out = np.zeros((coef.shape[1], top + 1))
    out[:, : order + 1] = coef.T
    return out


def _pose_temps(temp: np.ndarray, t: np.ndarray, statics) -> tuple[np.ndarray, np.ndarray]:
    """Mean temperature of each pose and how far its trend moves across the pose [degC]."""
    mean = np.array([temp[s.start:s.stop].mean() for s in statics])
    drift = np.array([abs(_slope(t[s.start:s.stop], temp[s.start:s.stop])) * (t[s.stop - 1] - t[s.start])
                      for s in statics])
    return mean, drift


def _accel_model(base: ImuThermalResult, fit: RampFit, names) -> TemperatureModel:
    """The accelerometer's :class:`TemperatureModel` of the joint fit, its misfit taken at the bins' own fits."""
    nodes = np.array([p.temperature for p in base.points])
    values = np.array([p.accel for p in base.points])
    sigma = np.sqrt(np.einsum("nii->ni", np.array([p.accel_cov for p in base.points])))
    top = fit.coefs.shape[1] - 1
    smooth = SmoothModel(centre=fit.centre, scale=fit.scale, orders=fit.orders, coefs=fit.coefs,
                         loto_rms=loto_errors(nodes, values, top) if len(nodes) >= 3 else np.zeros((top + 1, 0)))
    chi2 = np.sum(((values - smooth(nodes)) / sigma) ** 2, axis=0)
    return TemperatureModel(names=tuple(names), nodes=nodes, values=values,
                            covariances=np.array([p.accel_cov for p in base.points]), smooth=smooth,
                            smooth_covariance=fit.covariance, chi2=chi2)


def calibrate_ramp(t, gyro, accel, temp, *, gravity: float = STANDARD_GRAVITY, accel_model="auto",
                   gyro_model="auto", min_static: float = 1.0, gaps=(), breaks=(), threshold=None,
                   max_order: int = 3, n_bins: int | None = None) -> ImuRampResult:
    """Calibrate both sensors of a log whose temperature drifts while the poses are taken.

    Parameters are those of :func:`~gyrocal.imu.thermal.calibrate_imu_thermal`; `n_bins`: see
    :func:`ramp_bins`. The accelerometer model is the one the bins agree on (``affine`` needs known
    pose directions, which a ramp's detected poses do not have).
    """
    t, temp = np.asarray(t, dtype=float), np.asarray(temp, dtype=float)
    bins = ramp_bins(t, temp, breaks, n_bins)
    base = calibrate_imu_thermal(t, gyro, accel, temp, gravity=gravity, accel_model=accel_model,
                                 gyro_model=gyro_model, min_static=min_static, gaps=gaps, breaks=breaks,
                                 threshold=threshold, max_order=max_order, plateaus=bins)
    statics = [s for p in base.points for r in p.results for s in r.statics]
    temps, drift = _pose_temps(temp, t, statics)
    centre, scale = float((temps.max() + temps.min()) / 2), float(max(np.ptp(temps) / 2, 1e-9))
    fit = fit_ramp_accel([s.accel_mean for s in statics], [s.accel_se for s in statics], temps, base.accel_model,
                         gravity=gravity, max_order=max_order, start=_bin_start(base, centre, scale, max_order))
    nodes = np.linspace(temps.min(), temps.max(), NODES)
    a_model = sampled(_accel_model(base, fit, base.points[0].results[0].accel.param_names), nodes)
    g_model = sampled(base.gyro, nodes)
    rate = float(median([abs(_slope(t[p.start:p.stop], temp[p.start:p.stop])) for p in bins]) * 60.0)
    notes = list(fit.quality.warnings)
    if np.any(drift > POSE_DRIFT):
        notes.append(f"{int(np.sum(drift > POSE_DRIFT))} of {len(statics)} poses drift by more than "
                     f"{POSE_DRIFT:g} degC (up to {drift.max():.2f}): each is taken at its mean temperature, "
                     "exact where the parameters are linear across the pose; slow the ramp or shorten the poses")
    notes.append(f"temperature ramp of {rate:.2g} degC/min: a temperature sensor lagging the sensors by tau s reads "
                 f"{rate:.2g} * tau / 60 degC off, which one ramp direction cannot show; ramp both ways to see it")
    ramp = {"poses": len(statics), "bins": [[p.start, p.stop] for p in bins], "rate_degC_per_min": rate,
            "pose_temperature": temps.tolist(), "pose_drift_degC": drift.tolist(), "max_pose_drift_degC":
            float(drift.max()), "orders": fit.orders.tolist(), "order_rule": f"highest power dropped while its joint Wald test has p > {DROP_P:g}",
            "fit": fit.quality.to_dict()}
    return ImuRampResult(points=base.points, accel_model=base.accel_model, gyro_model=base.gyro_model,
                         accel=a_model, gyro=g_model, reference=base.reference, notes=base.notes + tuple(notes),
                         ramp=ramp)
