"""Gyro calibration from a hand session: bias from the still poses, scale and axes from the turns between them.

Canonical form ``w = A (m - o - G f)``: ``A`` [rad/s per raw unit] holds scale, misalignment
and non-orthogonality and maps onto the corrected accelerometer frame, ``o`` is the bias [raw],
``G`` the optional g-sensitivity [raw per m/s^2] and ``f`` the calibrated specific force.

Models: ``affine`` (``A`` full, 9 + 3 parameters) and ``scale`` (``A`` diagonal, 3 + 3: the gyro
axes taken as the accelerometer's). ``model="auto"`` fits the largest one the turns determine
with a few spare equations, as for the accelerometer. All equations (still poses, pose pairs,
known-angle turns; see :mod:`gyrocal.imu._gyro_problem`) are fitted together, so the bias and
the scale share one covariance; the accelerometer's own uncertainty is carried into it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal, get_args

import numpy as np
from scipy import stats

from .._arrays import median
from ..errors import DegenerateDesignError, InputError
from . import _fit
from ._gyro_cov import noise_model
from ._gyro_problem import EARTH_RATE, GyroProblem, Turn, build_problem
from ._gyro_solve import MASKS, initial_scale, screen_pairs, solve, unpack
from .accel import AccelFit

__all__ = ["EARTH_RATE", "GYRO_MODELS", "GyroFit", "GyroModel", "PairCheck", "Turn", "fit_gyroscope"]

GyroModel = Literal["affine", "scale"]
GYRO_MODELS: tuple[str, ...] = get_args(GyroModel)
MIN_DOF = 3
DETERMINED_REL = 0.05
#: A pose pair or turn whose own chi-square has a p-value below this is named as disagreeing.
DISAGREE_P = 1e-3
#: Names of the equation groups, in residual order.
GROUPS = ("still poses", "turns between poses")
_AXES = "xyz"


@dataclass(frozen=True)
class PairCheck:
    """How one pose pair (or known-angle turn) agrees with the fit.

    Attributes
    ----------
    kind : {"pair", "turn"}
    label : str
        ``"pose 3 -> 4"`` or the turn's label.
    t_start, t_stop : float
        Span integrated [s].
    angle_deg : float
        Angle turned, from the corrected gyro [deg].
    residual_deg : float
        Size of the misfit [deg].
    chi2 : float
        Of this equation group (2 dof for a pair, 3 for a turn), against the scatter of its kind
        (the noise model times the group's noise factor).
    p_value : float
    poses : (int, int) or None
        Indices of the two still poses of a pair.
    noise_chi2 : float
        The same against the noise model alone (NaN: not known).
    """

    kind: str
    label: str
    t_start: float
    t_stop: float
    angle_deg: float
    residual_deg: float
    chi2: float
    p_value: float
    poses: tuple[int, int] | None = None
    noise_chi2: float = math.nan

    @property
    def disagrees(self) -> bool:
        """Whether it disagrees with the others of its kind (an outlier among them)."""
        return self.p_value < DISAGREE_P

    @property
    def noise_p(self) -> float:
        """p-value of the misfit against the noise model alone."""
        return float(stats.chi2.sf(self.noise_chi2, 2 if self.kind == "pair" else 3))

    @property
    def beyond_noise(self) -> bool:
        """Whether the misfit is beyond the noise model (whatever the others do)."""
        return bool(self.noise_p < DISAGREE_P)

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in ("kind", "label", "t_start", "t_stop", "angle_deg", "residual_deg",
                                              "chi2", "p_value", "noise_chi2")} | {
            "disagrees": self.disagrees, "noise_p": self.noise_p, "beyond_noise": self.beyond_noise,
                                                                     "poses": None if self.poses is None
                                                                     else list(self.poses)}


@dataclass(frozen=True)
class GyroFit:
    """A gyro calibration from a hand session, with its uncertainty.

    Attributes
    ----------
    model : {"affine", "scale"}
    matrix : ndarray, shape (3, 3)
        ``A`` [rad/s per raw unit].
    offset : ndarray, shape (3,)
        Bias ``o`` [raw units].
    g_sensitivity : ndarray, shape (3, 3), or None
        ``G`` [raw units per m/s^2].
    covariance : ndarray
        Of :attr:`params` in :attr:`param_names` order.
    fit : FitQuality
    checks : tuple of PairCheck
    choice : tuple of str
        Why this model (one line per model tried), and what became of the g-sensitivity.
    noise_factors : dict
        For each equation group (still poses; turns between poses, pose pairs and known-angle
        turns together), how many times its noise model its residuals scatter
        (variance-component estimation; 1 = as predicted).
    left_out : tuple of str
        Pose pairs left out of the fit as gross outliers (they stay in :attr:`checks`).
    """

    model: GyroModel
    matrix: np.ndarray
    offset: np.ndarray
    g_sensitivity: np.ndarray | None
    covariance: np.ndarray
    fit: _fit.FitQuality
    checks: tuple[PairCheck, ...]
    choice: tuple[str, ...] = field(default_factory=tuple)
    noise_factors: dict = field(default_factory=dict)
    left_out: tuple[str, ...] = ()

    @property
    def param_names(self) -> tuple[str, ...]:
        return _names(self.model, self.g_sensitivity is not None)

    @property
    def params(self) -> np.ndarray:
        extra = () if self.g_sensitivity is None else (self.g_sensitivity.ravel(),)
        return np.concatenate([self.matrix[MASKS[self.model]], self.offset, *extra])

    @property
    def std(self) -> np.ndarray:
        return np.sqrt(np.diag(self.covariance))

    @property
    def disagreeing(self) -> tuple[PairCheck, ...]:
        return tuple(c for c in self.checks if c.disagrees)


def _names(model: str, with_g: bool) -> tuple[str, ...]:
    rows, cols = np.nonzero(MASKS[model])
    names = tuple(f"A_{_AXES[r]}{_AXES[c]}" for r, c in zip(rows, cols)) + ("o_x", "o_y", "o_z")
    return names + (tuple(f"G_{_AXES[r]}{_AXES[c]}" for r in range(3) for c in range(3)) if with_g else ())


def _checks(prob: GyroProblem, p, model, with_g, statics, accel: AccelFit, means) -> tuple[PairCheck, ...]:
    """Each pair's and turn's misfit against its own variance under the noise model."""
    a, b, g = unpack(model, with_g, p)
    directions, directions_std = accel.directions, accel.direction_std
    var = np.diag(noise_model(prob, (a, b, g), accel, means))  # of the factor-free normalised equations
    n_static = prob.means.size
    out = []
    if len(prob.pairs):
        r = prob.pair_residuals(a, b, g, directions, directions_std).reshape(-1, 2)
        v = var[n_static:n_static + 2 * len(prob.pairs)].reshape(-1, 2)
        sig = prob.pair_sigma(a, directions_std)
        dq = quat_angles(prob.t_cat, prob.omega_params(a, b, g), prob.bounds)
        for (i, j), ri, vi, s, ang in zip(prob.pairs, r, v, sig, dq):
            chi2 = float(np.sum(ri**2 / vi))
            out.append(PairCheck("pair", f"pose {i + 1} -> {j + 1}", statics[i].t_stop, statics[j].t_start,
                                 float(np.degrees(ang)), float(np.degrees(np.linalg.norm(ri) * s)), chi2,
                                 float(stats.chi2.sf(chi2, 2)), (int(i), int(j)), chi2 * prob.factors[1] ** 2))
    if prob.turns:
        r = prob.turn_residuals(a, b, g).reshape(-1, 3)
        vec = prob.turn_vectors(a, b, g)
        want = np.array([s * t.angle * t.axis for s, t in zip(prob.turn_sign, prob.turns)])
        for tu, ri, v, miss, span in zip(prob.turns, r, vec, vec - want, prob.turn_span):
            chi2 = float(ri @ ri)
            out.append(PairCheck("turn", tu.label or f"turn at sample {tu.start}", float(span[0]), float(span[1]),
                                 float(np.degrees(np.linalg.norm(v))), float(np.degrees(np.linalg.norm(miss))),
                                 chi2, float(stats.chi2.sf(chi2, 3)), None, chi2 * prob.factors[2] ** 2))
    return tuple(out)


def quat_angles(t, omega, bounds) -> np.ndarray:
    """Rotation angle of each interval [rad]."""
    from .. import quaternion as quat

    q = quat.attitude_change(t, omega, bounds)
    return 2 * np.arccos(np.clip(np.abs(q[:, 0]), 0, 1))


def _why_not(model, p, cov, rank, k) -> str | None:
    if rank < k:
        return f"the turns leave {k - rank} parameter(s) free"
    a, _, _ = unpack(model, False, p)
    scale = float(np.abs(np.diag(a)).mean())
    n = int(MASKS[model].sum())
    rel = np.sqrt(np.diag(cov))[:n] / scale
    if rel.max() > DETERMINED_REL:
        return (f"{_names(model, False)[int(np.argmax(rel))]} is not determined by these turns "
                f"(1-sigma {rel.max():.2g} of the scale)")
    return None


def fit_gyroscope(t, gyro, force, statics, accel: AccelFit, *, pairs=None, turns=(), model="auto",
                  g_sensitivity: bool = False) -> GyroFit:
    """Fit the gyro of a hand session.

    Parameters
    ----------
    t : ndarray, shape (N,)
        Sample times [s] (the real stamps: integration uses them).
    gyro : ndarray, shape (N, 3)
        Raw readings [rad/s or counts].
    force : ndarray, shape (N, 3)
        Calibrated specific force [m/s^2] (``accel.correct`` of the readings).
    statics : sequence of Static
        The poses, in time order, as fitted by `accel` (one direction each).
    accel : AccelFit
    pairs : array_like, shape (P, 2), optional
        Pose pairs to join; default every consecutive pair.
    turns : sequence of Turn
        Known-angle turns about the vertical.
    model : {"auto", "affine", "scale"}
    g_sensitivity : bool
        Also fit ``G`` from the still poses, when they determine it.
    """
    if model not in ("auto", *GYRO_MODELS):
        raise InputError(f"model={model!r} is not one of auto, {', '.join(GYRO_MODELS)}")
    if len(statics) != len(accel.directions):
        raise InputError(f"{len(statics)} statics but the accelerometer fit has {len(accel.directions)} poses")
    pairs = np.array([(i, i + 1) for i in range(len(statics) - 1)]) if pairs is None else np.asarray(pairs, int)
    ctx = _Context(statics=tuple(statics), accel=accel, g_sensitivity=g_sensitivity,
                   means=np.array([s.accel_mean for s in statics]),
                   bias0=np.average([s.gyro_mean for s in statics], axis=0, weights=[s.count for s in statics]))
    d, d_std = accel.directions, accel.direction_std
    ctx.scale = initial_scale(build_problem(t, gyro, force, statics, pairs, turns, 1.0), ctx.bias0, d, d_std)
    ctx.everything = build_problem(t, gyro, force, statics, pairs, turns, ctx.scale)
    keep = screen_pairs(ctx.everything, np.concatenate([(ctx.scale * np.eye(3)).ravel(), ctx.bias0]), d, d_std)
    prob = ctx.everything if keep.all() else build_problem(t, gyro, force, statics, pairs[keep], turns, ctx.scale)
    ctx.left_out = tuple(f"pose {i + 1} -> {j + 1}" for i, j in pairs[~keep])
    if turns:
        sign = np.sign(np.einsum("ti,ti->t", prob.turn_vectors(ctx.scale * np.eye(3), ctx.bias0, None),
                                 np.array([tu.axis for tu in turns])))
        prob.turn_sign = ctx.everything.turn_sign = np.where(sign == 0, 1.0, sign)
    return _choose(prob, model, ctx)


@dataclass
class _Context:
    statics: tuple
    accel: AccelFit
    g_sensitivity: bool
    means: np.ndarray
    bias0: np.ndarray
    scale: float = 1.0
    everything: GyroProblem | None = None  # every pose pair, for the checks
    left_out: tuple[str, ...] = ()


def _choose(prob: GyroProblem, model, ctx: _Context) -> GyroFit:
    """Fit the largest model the turns determine with spare equations (or the one asked for)."""
    choice, fallback = [], None
    for m in ([model] if model != "auto" else list(GYRO_MODELS)):
        k = int(MASKS[m].sum()) + 3
        turn_eqs = prob.equations - 3 * len(ctx.statics)
        if turn_eqs + 3 < k:
            choice.append(f"{m}: {k} parameters but the turns give only {turn_eqs} equations")
            continue
        p0 = np.concatenate([(ctx.scale * np.eye(3))[MASKS[m]], ctx.bias0])
        p, r, jac, s = solve(prob, m, False, p0, ctx.accel, ctx.means)
        q = _fit.quality(r, k, "gyro fit")
        rank, _ = _fit.relative_rank(jac)
        why = _why_not(m, p, _covariance(jac, s, q) if rank == k else None, rank, k)
        if why is None and (q.dof >= MIN_DOF or model != "auto"):
            choice.append(f"{m}: fitted ({q.dof} spare equations)")
            return _finish(prob, (m, p, r, jac, q, s), choice, ctx)
        if why is None:
            why = f"only {q.dof} spare equation(s), {MIN_DOF} needed to check the fit"
            fallback = fallback or ((m, p, r, jac, q, s), prob.factors.copy(), len(choice))
        choice.append(f"{m}: {why}")
    if fallback is not None:
        solution, prob.factors, i = fallback
        choice[i] = f"{solution[0]}: fitted with {solution[4].dof} spare equation(s), {_fit.UNCHECKED}"
        return _finish(prob, solution, choice, ctx)
    raise DegenerateDesignError("the turns between the still poses determine no gyro model: "
                                + "; ".join(choice) + "; turn the board about each of its axes between poses")


def _covariance(jac, s, q) -> np.ndarray:
    """Of the whitened fit: ``(J^T J)^-1``, Birge-scaled when the fit asks (`s` is kept for the checks)."""
    return _fit.covariance(jac, q)


def _with_g(prob, solution, ctx, choice):
    """The solution refitted with a g-sensitivity, when the still poses determine it."""
    m, p, *_ = solution
    keep = prob.factors.copy()
    p_g, r_g, jac_g, s_g = solve(prob, m, True, np.concatenate([p, np.zeros(9)]), ctx.accel, ctx.means)
    rank, _ = _fit.relative_rank(jac_g)
    if rank < p_g.size:
        prob.factors = keep
        return solution, False, choice + ["g-sensitivity: not determined (it needs still poses in at least four "
                                          "orientations not in one plane)"]
    q_g = _fit.quality(r_g, p_g.size, "gyro fit")
    return (m, p_g, r_g, jac_g, q_g, s_g), True, choice + ["g-sensitivity: fitted from the still poses"]


#: Turns whose median misfit is this many times their noise were not measured by the gyro as the poses show.
FAR_BEYOND = 5.0


def _beyond_noise(checks) -> tuple[str, ...]:
    """One warning when the turns miss far beyond their noise (then none stands out from the others)."""
    z = np.array([math.sqrt(c.noise_chi2 / (2 if c.kind == "pair" else 3)) for c in checks])
    if not len(z) or not median(z) > FAR_BEYOND:
        return ()
    deg = median([c.residual_deg for c in checks])
    return (f"gyro: the turns miss by a median {deg:.2g} deg, {median(z):.2g} times their noise, and "
            f"{sum(c.beyond_noise for c in checks)} of {len(checks)} are beyond it: the gyro did not measure the "
            "turns the poses show (a log glued from parts, lost samples, a wrong rate or unit); do not trust "
            "this result",)


def _finish(prob, solution, choice, ctx: _Context) -> GyroFit:
    with_g = False
    if ctx.g_sensitivity:
        solution, with_g, choice = _with_g(prob, solution, ctx, choice)
    m, p, _, jac, q, s = solution
    accel = ctx.accel
    a, b, g = unpack(m, with_g, p)
    cov = _covariance(jac, s, q)
    ctx.everything.factors = prob.factors
    checks = _checks(ctx.everything, p, m, with_g, ctx.statics, accel, ctx.means)
    notes = tuple(f"gyro fit: the {name} scatter {f:.2g} times their noise model; they were given that much less "
                  "weight and the uncertainties include it" for name, f in zip(GROUPS, prob.factors[:2]) if f > 1.0)
    bad = tuple(f"gyro: {c.label} disagrees with the other {c.kind}s (misfit {c.residual_deg:.2g} deg, "
                f"p = {c.p_value:.1g}){' and was left out' if c.label in ctx.left_out else ''}: "
                "the board may have moved during a pose, or the gyro saturated"
                for c in checks if c.disagrees)
    q = _fit.FitQuality(q.chi2, q.dof, q.p_value, q.birge_ratio, q.covariance_scaled or bool(notes),
                        q.warnings + notes + _beyond_noise(checks) + bad)
    return GyroFit(model=m, matrix=a, offset=b, g_sensitivity=g, covariance=cov, fit=q, checks=checks,
                   choice=tuple(choice), noise_factors=dict(zip(GROUPS, prob.factors[:2].tolist())),
                   left_out=ctx.left_out)
