"""Scatter beyond the noise, estimated per group of windows and carried into the covariance.

The sensor's noise is not all a calibration's error. A robot reports each turn's angle to a few
hundredths of a degree, a hand to a degree; a servo's plateau runs a little off its commanded
speed; between static windows the bias wanders (flicker, temperature) and the Earth's rate
projects differently in each pose. None of this is in the noise of a window mean, and it is
different for the two kinds of rows: turns (their *reference* is uncertain) and static levels.

A single Birge factor over all rows lets the many static rows dilute the few turn rows: robot
turns whose angles scatter three times beyond their noise give chi2/dof 1.5 (p = 0.01: no
flag) while every scale factor's 1-sigma is a third of its error. Here each group gets its own
extra variance, as random-effects averages do (Paule and Mandel, J. Res. NBS 87, 1982):

* turns: one extra variance of the reference, ``tau^2``: of the angle [rad^2] for whole turns
  (a robot's or a hand's angle error does not shrink for a longer turn) or of the rate
  [rad^2/s^2] for plateaus at a known speed;
* static windows: one extra variance of the level per axis [reading units^2]: the bias wanders
  between windows (flicker, warming up, the Earth's rate in each pose), and it wanders under the
  turns as much, so every window's mean carries it; the turns' own extra variance is what is left
  beyond it.

Each is the value at which the group's chi-square equals its degrees of freedom
(``nu = sum over the group of (1 - leverage)``). It is looked for only where the group's
noise-only chi-square gives the noise alone little support (p < 0.1): below that, a few
degrees of freedom would widen clean fits at random. Estimated from ``nu`` degrees of freedom, it makes errors over the 1-sigma follow
Student's t rather than a normal law (variance ``nu / (nu - 2)``, 1.3 for the 9 of a robot's
twelve turns), so it is carried as ``nu / (nu - 2)`` times itself (1.5 times below ``nu = 6``, where the estimate is too rough to say more).
The fit is repeated with these variances until they settle, so the 1-sigma of every parameter
includes them and the rows are weighted by what they really know.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..estimators import FitResult
from ..estimators.first_moment import residuals_and_jacobian, row_noise_var, row_variance
from ..observations import ObservationSet

__all__ = ["Excess", "GroupFit", "widen"]

_ITERATIONS = 6
#: A group whose noise-only chi2 has a p-value at or above this keeps its noise alone.
EVIDENCE_P = 0.1
_SETTLED = 0.01  # relative change of every extra variance at which the iteration stops


@dataclass(frozen=True)
class GroupFit:
    """How one group of rows agrees with a fit in noise units: its chi2 and degrees of freedom."""

    name: str
    chi2: float
    dof: float
    rows: int


@dataclass(frozen=True)
class Excess:
    """Extra variances found beyond the noise, and the noise-only chi2 of each group.

    Attributes
    ----------
    reference : {"angle", "speed"}
    turn_sd : float
        Standard deviation of a turn's reference beyond the noise: its angle [rad] (angle
        reference) or its rate [rad/s] (speed reference); 0 when the turns agree within their noise.
    static_sd : ndarray, shape (3,)
        Standard deviation of a static level beyond the noise, per axis [reading units].
    groups : tuple of GroupFit
        Noise-only chi2 and degrees of freedom of the turns and of the static rows.
    """

    reference: str
    turn_sd: float
    static_sd: np.ndarray
    groups: tuple[GroupFit, ...]

    @property
    def any(self) -> bool:
        return self.turn_sd > 0 or bool(np.any(self.static_sd > 0))

    def to_document(self, input_scale: float, input_units: str) -> dict:
        """JSON-ready record (the calibration file's ``fit.excess``); levels in the input units."""
        return {"turn_reference_sd": math.degrees(self.turn_sd),
                "turn_reference_unit": "deg" if self.reference == "angle" else "deg/s",
                "static_level_sd": (np.asarray(self.static_sd) / input_scale).tolist(), "static_level_unit": input_units,
                "groups": [{"name": g.name, "chi2": g.chi2, "dof": g.dof, "rows": g.rows} for g in self.groups]}

    def describe(self, input_scale: float, input_units: str) -> str:
        """What the 1-sigma now includes, in words."""
        parts = []
        if self.turn_sd > 0:
            what = ("the turns' angles" if self.reference == "angle" else "the plateaus' speeds")
            unit = "deg" if self.reference == "angle" else "deg/s"
            parts.append(f"{what} {math.degrees(self.turn_sd):.2g} {unit}")
        if np.any(self.static_sd > 0):
            levels = "/".join(f"{v / input_scale:.2g}" for v in self.static_sd)
            parts.append(f"the static levels {levels} {input_units} (x/y/z)")
        return " and ".join(parts)


def _rows(p: np.ndarray, obs: ObservationSet, noise_var: np.ndarray):
    """Raw weighted residuals, Jacobian and variances of every row (m,), (m, 6), (m,)."""
    o = obs.as_batch()
    r, J, S = residuals_and_jacobian(p[None], o)
    var = row_variance(o, S, row_noise_var(o, noise_var[None]))
    return r[0], J[0], var[0]


def _leverage(J: np.ndarray, var: np.ndarray) -> np.ndarray:
    """Each row's leverage in the noise-weighted fit (its share of the parameters it determines)."""
    Jw = J / np.sqrt(var)[:, None]
    H = Jw.T @ Jw
    return np.einsum("ij,ji->i", Jw, np.linalg.solve(H, Jw.T))


def _t_factor(dof: float) -> float:
    """``nu / (nu - 2)``, the variance of Student's t over that of the normal law, capped at 1.5 (nu <= 6)."""
    return dof / (dof - 2) if dof > 6 else 1.5


def _solve_tau2(r2: np.ndarray, v: np.ndarray, c: np.ndarray, dof: float) -> float:
    """The extra variance ``tau2 >= 0`` at which ``sum r2 / (v + c tau2) = dof`` (0 if already below)."""
    if dof <= 0 or not len(r2) or float(np.sum(r2 / v)) <= dof:
        return 0.0
    grows = c > 0
    # at hi = sum(r2 / c) / dof the sum is below dof, since each term is below r2 / (c hi): a valid bracket
    lo, hi = 0.0, float(np.sum(r2[grows] / c[grows])) / dof if np.any(grows) else 0.0
    if hi <= 0:
        return 0.0
    for _ in range(60):  # bisection on a decreasing function: robust, and cheap for a few dozen rows
        mid = 0.5 * (lo + hi)
        if float(np.sum(r2 / (v + c * mid))) > dof:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _beyond_noise(z2: np.ndarray, h: np.ndarray, n_rot: int, axis: np.ndarray) -> np.ndarray:
    """Which groups (turns; static levels of x, y, z) have a noise-only chi2 with p < `EVIDENCE_P` (4,)."""
    from .._chi2 import chi2_sf

    parts = [slice(0, n_rot)] + [n_rot + np.flatnonzero(axis == j) for j in range(3)]
    out = np.zeros(4, dtype=bool)
    for g, rows in enumerate(parts):
        dof = float(np.sum(1 - h[rows]))
        out[g] = dof > 0.5 and float(chi2_sf(dof, float(np.sum(z2[rows])))) < EVIDENCE_P
    return out


def _with_extra(obs: ObservationSet, base_mean_var: np.ndarray, base_rate_var: np.ndarray, tau2_turn: float,
                tau2_static: np.ndarray, reference: str) -> ObservationSet:
    """`obs` with the extra variances added: the turns' reference, and the bias's wander under every window."""
    rot = ~obs.static
    per_turn = tau2_turn / obs.duration**2 if reference == "angle" else np.full(len(obs.duration), tau2_turn)
    rate_var = base_rate_var + np.where(rot, per_turn, 0.0)
    mean_var = base_mean_var + tau2_static  # the bias wanders under every window, turning or not
    return dataclasses.replace(obs, mean_var=mean_var, rate_var=rate_var)


def widen(fit: FitResult, obs: ObservationSet, estimator, reference: str) -> tuple[FitResult, ObservationSet, Excess]:
    """Estimate the extra variances of the turns and the static levels; refit with them.

    Parameters
    ----------
    fit : FitResult
        The first-moment fit of `obs` with the noise alone.
    obs : ObservationSet
        One gyro's windows (not batched).
    estimator
        The estimator that made `fit` (refits with the extra variances).
    reference : {"angle", "speed"}

    Returns
    -------
    fit, obs : the refit and the windows it used (`fit` and `obs` themselves when nothing was found)
    excess : Excess
    """
    # long function: one variance-component iteration (rows, leverages, one solve per group, refit), kept together
    noise_var = np.square(np.asarray(fit.noise_std, dtype=float))
    n = len(obs)
    rot = ~obs.static
    n_rot = int(rot.sum())
    base_rate_var = np.zeros(n) if obs.rate_var is None else np.asarray(obs.rate_var, dtype=float)
    base_mean_var = np.where(np.isnan(obs.mean_var), noise_var / obs.count[:, None], obs.mean_var) \
        if obs.mean_var is not None else noise_var / obs.count[:, None]
    count_rot = obs.count[rot]
    # a row's variance grows by c tau^2: turns count x (1 / T^2 for an angle), static rows k_j^2 count
    c_turn = count_rot / obs.duration[rot] ** 2 if reference == "angle" else count_rot
    axis = np.tile(np.arange(3), int(obs.static.sum()))
    count_sta = np.repeat(obs.count[obs.static], 3)
    tau_turn, tau_sta = 0.0, np.zeros(3)
    groups: tuple[GroupFit, ...] = ()
    seen = np.zeros(4, dtype=bool)  # which groups (turns, static x, y, z) scatter beyond their noise
    current, cur_obs = fit, obs
    plain = _with_extra(obs, base_mean_var, base_rate_var, 0.0, np.zeros(3), reference)
    for step in range(_ITERATIONS):
        r, J, var = _rows(current.model.params, cur_obs, noise_var)
        h = _leverage(J, var)
        r2 = r * r
        if step == 0:  # the noise-only check of each group, before any widening
            groups = (GroupFit("turns", float(np.sum(r2[:n_rot] / var[:n_rot])), float(np.sum(1 - h[:n_rot])), n_rot),
                      GroupFit("static levels", float(np.sum(r2[n_rot:] / var[n_rot:])),
                               float(np.sum(1 - h[n_rot:])), len(r2) - n_rot))
            seen = _beyond_noise(r2 / var, h, n_rot, axis)
        # each extra variance is found again from the variances without it: the static levels' from the noise
        # alone; the turns' from the noise and the bias's wander, which moves a turn's mean as it moves a level's
        k2 = np.square(current.model.k)[axis]
        v_sta = _rows(current.model.params, plain, noise_var)[2][n_rot:]
        dof_sta = [float(np.sum(1 - h[n_rot:][axis == j])) for j in range(3)]
        new_sta = np.array([_solve_tau2(r2[n_rot:][axis == j], v_sta[axis == j], (k2 * count_sta)[axis == j],
                                        dof_sta[j]) * _t_factor(dof_sta[j]) if seen[1 + j] else 0.0
                            for j in range(3)])
        wander = _with_extra(obs, base_mean_var, base_rate_var, 0.0, new_sta, reference)
        v_turn = _rows(current.model.params, wander, noise_var)[2][:n_rot]
        dof_turn = float(np.sum(1 - h[:n_rot]))
        new_turn = _solve_tau2(r2[:n_rot], v_turn, c_turn, dof_turn) * _t_factor(dof_turn) if seen[0] else 0.0
        settled = (abs(new_turn - tau_turn) <= _SETTLED * max(new_turn, 1e-300)
                   and np.all(np.abs(new_sta - tau_sta) <= _SETTLED * np.maximum(new_sta, 1e-300)))
        tau_turn, tau_sta = new_turn, new_sta
        if tau_turn == 0 and not np.any(tau_sta > 0) and step == 0:
            break
        cur_obs = _with_extra(obs, base_mean_var, base_rate_var, tau_turn, tau_sta, reference)
        current = estimator.fit(cur_obs)
        if settled:
            break
    excess = Excess(reference, math.sqrt(tau_turn), np.sqrt(tau_sta), groups)
    return (current, cur_obs, excess) if excess.any else (fit, obs, excess)
