"""Accelerometer calibration from still poses: scale, non-orthogonality and bias.

Canonical form, as for the gyro: ``f = A (u - o)`` maps readings ``u`` [reading units] to the
specific force ``f`` [m/s^2]. Three models, by the entries of ``A`` they free:

* ``scale-bias`` (6 parameters): ``A`` diagonal.
* ``triangular`` (9): ``A`` lower triangular, the model of Tedaldi et al. (ICRA 2014): scale
  factors and three non-orthogonality angles, with the corrected x axis along the sensor's x
  axis and y in the sensor's xy plane. This is all the gravity magnitude can determine:
  ``|A (u - o)| = g`` holds for any rotation of ``A``'s output frame.
* ``affine`` (12): full ``A``, the Ferraris et al. model as imucal computes it, possible only
  when each pose's gravity direction is known in a reference frame (the six faces of a box:
  ``x_p`` with x up, ``x_a`` with x down, ...). The frame is then the box's.

Without known directions the fit minimises ``sum ((|A (u_p - o)| - g) / sigma_p)^2`` over the
poses, with ``sigma_p`` the standard error of ``|A u_p|`` from the pose's own noise. With known
directions it solves the linear model ``u_p = A^-1 g d_p + o`` by weighted least squares.

``fit_accelerometer(..., model="auto")`` fits the largest model the poses determine, with at
least :data:`MIN_DOF` spare equations so the fit can be checked, and says which it chose and why.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, get_args

import numpy as np
from scipy.optimize import least_squares

from .._arrays import median, rows_times
from .._validation import finite_array, positive
from ..errors import DegenerateDesignError, InputError
from ..units import STANDARD_GRAVITY
from . import _fit
from .poses import coverage, triangular_frame

__all__ = [
    "ACCEL_MODELS",
    "MIN_DOF",
    "AccelFit",
    "AccelModel",
    "directions_of",
    "fit_accelerometer",
    "model_matrices",
    "normal_gravity",
    "param_names",
]

AccelModel = Literal["affine", "triangular", "scale-bias"]
ACCEL_MODELS: tuple[str, ...] = get_args(AccelModel)
#: Spare equations a model needs before "auto" picks it (so its residuals can be checked).
MIN_DOF = 3
#: A matrix entry or offset is "not determined" when its 1-sigma exceeds this fraction of scale or of g.
DETERMINED_REL = 0.05
_MASKS = {
    "scale-bias": np.eye(3, dtype=bool),
    "triangular": np.tril(np.ones((3, 3), dtype=bool)),
    "affine": np.ones((3, 3), dtype=bool),
}
_AXES = "xyz"


def normal_gravity(latitude_deg: float, height_m: float = 0.0) -> float:
    """Normal gravity of the WGS84 ellipsoid (Somigliana) with the free-air gradient [m/s^2]."""
    s2 = np.sin(np.radians(latitude_deg)) ** 2
    g0 = 9.7803253359 * (1 + 0.00193185265241 * s2) / np.sqrt(1 - 0.00669437999013 * s2)
    return float(g0 - 3.086e-6 * height_m)


def param_names(model: AccelModel) -> tuple[str, ...]:
    """Names of the free entries of ``A`` (``A_yx``: row y, column x) and of ``o``."""
    rows, cols = np.nonzero(_MASKS[model])
    return tuple(f"A_{_AXES[r]}{_AXES[c]}" for r, c in zip(rows, cols)) + ("o_x", "o_y", "o_z")


@dataclass(frozen=True)
class AccelFit:
    """An accelerometer calibration with its uncertainty.

    Attributes
    ----------
    model : {"affine", "triangular", "scale-bias"}
    matrix : ndarray, shape (3, 3)
        ``A`` [m/s^2 per reading unit].
    offset : ndarray, shape (3,)
        ``o`` [reading units].
    covariance : ndarray, shape (p, p)
        Of the parameters named in :attr:`param_names` [m/s^2 per reading unit; reading units].
    gravity : float
        The ``g`` the fit used [m/s^2].
    residuals : ndarray
        Normalised residuals: one per pose (|f| - g), or three per pose with known directions.
    fit : FitQuality
    directions : ndarray, shape (n, 3)
        Unit specific-force direction of each pose in the corrected frame.
    direction_std : ndarray, shape (n,)
        1-sigma of each direction from the pose's noise [rad, per tangent axis].
    choice : tuple of str
        Why this model and not a larger one (one line per model tried).
    pose_se : ndarray, shape (n, 3)
        Standard errors of the pose means the fit was given [reading units].
    gain : ndarray, shape (p, n, 3)
        Derivative of each parameter with respect to each pose mean, to carry the poses' noise
        into what is computed from both (the gyro's fit uses the same poses).
    """

    model: AccelModel
    matrix: np.ndarray
    offset: np.ndarray
    covariance: np.ndarray
    gravity: float
    residuals: np.ndarray
    fit: _fit.FitQuality
    directions: np.ndarray
    direction_std: np.ndarray
    choice: tuple[str, ...] = field(default_factory=tuple)
    pose_se: np.ndarray | None = None
    gain: np.ndarray | None = None

    @property
    def param_names(self) -> tuple[str, ...]:
        return param_names(self.model)

    @property
    def params(self) -> np.ndarray:
        return np.concatenate([self.matrix[_MASKS[self.model]], self.offset])

    @property
    def std(self) -> np.ndarray:
        return np.sqrt(np.diag(self.covariance))

    def correct(self, readings) -> np.ndarray:
        """Specific force (..., 3) [m/s^2] from readings (..., 3) [reading units]."""
        return rows_times(np.asarray(readings, dtype=float) - self.offset, self.matrix)

    def sensor_axes(self) -> dict[str, tuple[float, float]]:
        """Frame-free figures with 1-sigma: sensitivity of each axis and the angles between axes.

        ``sens_x`` is the reading change per m/s^2 along the sensor's x axis [reading units per
        m/s^2]; ``angle_xy`` the angle between the sensor's x and y axes [deg] (90 when orthogonal).
        Unlike ``A``, these do not depend on how the output frame is chosen, so they compare
        directly with a datasheet or another tool's calibration.
        """
        def figures(p):
            m = np.linalg.inv(_matrix(self.model, p))
            n = np.linalg.norm(m, axis=1)
            u = m / n[:, None]
            ang = np.degrees(np.arccos(np.clip([u[0] @ u[1], u[0] @ u[2], u[1] @ u[2]], -1, 1)))
            return np.concatenate([n, ang])

        value, std = _propagate(figures, self.params, self.covariance)
        names = ("sens_x", "sens_y", "sens_z", "angle_xy", "angle_xz", "angle_yz")
        return {k: (float(v), float(s)) for k, v, s in zip(names, value, std)}


def model_matrices(model: AccelModel, params) -> np.ndarray:
    """Matrices ``A`` (N, 3, 3) of `model` from parameter rows (N, p) ordered as :func:`param_names`."""
    p = np.atleast_2d(np.asarray(params, dtype=float))
    a = np.zeros((len(p), 3, 3))
    a[:, _MASKS[model]] = p[:, : _MASKS[model].sum()]
    return a


def _matrix(model: AccelModel, p: np.ndarray) -> np.ndarray:
    a = np.zeros((3, 3))
    a[_MASKS[model]] = p[: _MASKS[model].sum()]
    return a


def _propagate(fn, p: np.ndarray, cov: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Value and 1-sigma of ``fn(p)`` by the delta method (central differences)."""
    f0 = np.asarray(fn(p))
    jac = np.empty((f0.size, p.size))
    for j in range(p.size):
        h = 1e-6 * max(abs(p[j]), 1e-3 * np.abs(p).max())
        dp = np.zeros_like(p)
        dp[j] = h
        jac[:, j] = (np.asarray(fn(p + dp)) - np.asarray(fn(p - dp))) / (2 * h)
    return f0, np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", jac, cov, jac), 0.0))


def _initial(u: np.ndarray, gravity: float) -> tuple[np.ndarray, np.ndarray]:
    """A start for the magnitude fit: an ellipsoid through the poses when there are enough, else a sphere."""
    centre = u.mean(axis=0)
    if len(u) >= 10:
        # algebraic ellipsoid x^T Q x + 2 b^T x = 1 (centred data), 9 unknowns, linear least squares
        x = (u - centre) / np.abs(u - centre).max()
        design = np.column_stack([x**2, 2 * x[:, 0] * x[:, 1], 2 * x[:, 0] * x[:, 2], 2 * x[:, 1] * x[:, 2], 2 * x])
        coef, *_ = np.linalg.lstsq(design, np.ones(len(x)), rcond=None)
        q = np.array([[coef[0], coef[3], coef[4]], [coef[3], coef[1], coef[5]], [coef[4], coef[5], coef[2]]])
        if np.all(np.linalg.eigvalsh(q) > 0):
            c = -np.linalg.solve(q, coef[6:])
            k = 1 + c @ q @ c
            scale = np.abs(u - centre).max()
            root = np.linalg.cholesky(q / k).T  # root^T root = Q / k: |root (x - c)| = 1 on the ellipsoid
            a, _ = triangular_frame(root * gravity / scale)
            return a, centre + c * scale
    radius = median(np.linalg.norm(u - centre, axis=1))
    return np.eye(3) * gravity / radius, centre


def _magnitude_fit(u, se, gravity, model, a0, o0):
    """Weighted fit of |A (u - o)| = g; returns (A, o, normalised residuals, Jacobian)."""
    mask = _MASKS[model]
    k = int(mask.sum())

    def unpack(p):
        return _matrix(model, p), p[k:]

    def sigma(a, o):
        n = (u - o) @ a.T
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        return np.sqrt(np.einsum("pj,pj->p", (n @ a) ** 2, se**2))

    def resid(p, s):
        a, o = unpack(p)
        return (np.linalg.norm((u - o) @ a.T, axis=1) - gravity) / s

    def jac(p, s):
        a, o = unpack(p)
        v = u - o
        f = v @ a.T
        n = f / np.linalg.norm(f, axis=1, keepdims=True)
        d_a = (n[:, :, None] * v[:, None, :])[:, mask]
        return np.column_stack([d_a, -(n @ a)]) / s[:, None]

    p = np.concatenate([a0[mask], o0])
    for _ in range(2):  # weights from the current estimate, then once more from the converged one
        s = sigma(*unpack(p))
        sol = least_squares(resid, p, jac=jac, args=(s,), method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14)
        p = sol.x
    a, o = unpack(p)
    if np.linalg.det(a) < 0:  # |A v| cannot tell A from -A; keep the sign that reads +g when an axis is up
        a = -a
        p = np.concatenate([a[mask], o])
    f = (u - o) @ a.T
    n = f / np.linalg.norm(f, axis=1, keepdims=True)
    d_u = np.zeros((len(u), len(u), 3))  # d r_p / d u_q: only p = q
    d_u[np.arange(len(u)), np.arange(len(u))] = (n @ a) / s[:, None]
    return a, o, resid(p, s), jac(p, s), d_u.reshape(len(u), -1)


def _direction_fit(u, se, gravity, d):
    """Weighted linear fit of u_p = M g d_p + o (known directions); returns (A, o, residuals, Jacobian in A, o)."""
    n = len(u)
    rows = np.zeros((3 * n, 12))
    for i in range(3):
        rows[i::3, 3 * i : 3 * i + 3] = gravity * d
        rows[i::3, 9 + i] = 1.0
    w = 1.0 / se.reshape(-1)
    coef, *_ = np.linalg.lstsq(rows * w[:, None], u.reshape(-1) * w, rcond=None)
    m, o = coef[:9].reshape(3, 3), coef[9:]
    resid = (u.reshape(-1) - rows @ coef) * w
    a = np.linalg.inv(m)
    # Jacobian with respect to (A, o): dM = -M dA M
    d_m = -np.einsum("ik,lj->ijkl", m, m).reshape(9, 9)  # dM_ij / dA_kl
    jac_m = rows[:, :9] * w[:, None]
    jac = np.column_stack([-jac_m @ d_m, -rows[:, 9:] * w[:, None]])
    return a, o, resid, jac, np.diag(w)


def directions_of(fit: AccelFit, params, means) -> np.ndarray:
    """Unit specific-force directions (n, 3) of pose `means` under `fit`'s model with other `params`."""
    a = _matrix(fit.model, np.asarray(params, dtype=float))
    f = (np.asarray(means, dtype=float) - np.asarray(params, dtype=float)[-3:]) @ a.T
    return f / np.linalg.norm(f, axis=1, keepdims=True)


def _directions(a, o, u, se):
    """Unit specific-force directions (n, 3) and their 1-sigma per tangent axis [rad]."""
    f = (u - o) @ a.T
    norm = np.linalg.norm(f, axis=1)
    # noise of f across the direction: the mean of the two tangent components' variances
    var_f = np.einsum("ij,pj->pi", a**2, se**2)
    n = f / norm[:, None]
    across = (var_f.sum(axis=1) - np.einsum("pi,pi->p", n**2, var_f)) / 2
    return n, np.sqrt(across) / norm


def _undetermined(model, a, o_std, std_a, gravity) -> str | None:
    """Why a fitted model is not determined by the poses, or None."""
    scale = np.abs(np.diag(a)).mean()
    names = param_names(model)
    rel = np.concatenate([std_a / scale, o_std * scale / gravity])
    if not np.all(np.isfinite(rel)) or rel.max() > DETERMINED_REL:
        worst = int(np.nanargmax(np.where(np.isfinite(rel), rel, np.inf)))
        return f"{names[worst]} is not determined by these poses (1-sigma {rel[worst]:.2g} of its scale)"
    return None


def _fit_one(model, u, se, gravity, directions):
    """Fit one model: ``(A, o, residuals, Jacobian, d residuals / d pose means, rank)``."""
    if model == "affine":
        a, o, r, jac, d_u = _direction_fit(u, se, gravity, directions)
    else:
        a0, o0 = _initial(u, gravity)
        a, o, r, jac, d_u = _magnitude_fit(u, se, gravity, model, a0, o0)
    rank, _ = _fit.relative_rank(jac)
    return a, o, r, jac, d_u, rank


def fit_accelerometer(means, se, *, gravity: float = STANDARD_GRAVITY, model: AccelModel | Literal["auto"] = "auto",
                      directions=None) -> AccelFit:
    """Fit the accelerometer to still poses.

    Parameters
    ----------
    means : array_like, shape (n, 3)
        Mean reading of each pose [reading units].
    se : array_like, shape (n, 3)
        Standard error of each mean [reading units].
    gravity : float
        Local gravity [m/s^2] (see :func:`normal_gravity`).
    model : {"auto", "affine", "triangular", "scale-bias"}
        ``auto`` takes the largest model the poses determine with :data:`MIN_DOF` spare equations.
    directions : array_like, shape (n, 3), optional
        Known unit specific-force direction of each pose in a reference frame (needed by ``affine``).

    Raises
    ------
    DegenerateDesignError
        The poses determine no model; the message says how many more orientations are needed.
    """
    u = finite_array("means", means, shape_tail=(3,), ndim=2)
    se = finite_array("se", se, shape_tail=(3,), ndim=2)
    gravity = positive("gravity", gravity)
    if se.shape != u.shape or np.any(se <= 0):
        raise InputError("se must be > 0 with one row per pose")
    d = None if directions is None else finite_array("directions", directions, shape_tail=(3,), ndim=2)
    if d is not None:
        d = d / np.linalg.norm(d, axis=1, keepdims=True)
    if model not in ("auto", *ACCEL_MODELS):
        raise InputError(f"model={model!r} is not one of auto, {', '.join(ACCEL_MODELS)}", )
    if model == "affine" and d is None:
        raise InputError("the affine accelerometer model needs the known direction of each pose (directions=)")
    candidates = [model] if model != "auto" else [m for m in ACCEL_MODELS if m != "affine" or d is not None]
    choice, fallback = [], None
    for m in candidates:
        k = int(_MASKS[m].sum()) + 3
        equations = len(u) * (3 if m == "affine" else 1)
        if equations < k:
            choice.append(f"{m}: {k} parameters but only {equations} equations from {len(u)} poses")
            continue
        a, o, r, jac, d_u, rank = _fit_one(m, u, se, gravity, d)
        q = _fit.quality(r, k, "accelerometer fit")
        cov = _fit.covariance(jac, q) if rank == k else None
        why = (f"the poses leave {k - rank} parameter(s) free" if cov is None
               else _undetermined(m, a, np.sqrt(np.diag(cov))[-3:], np.sqrt(np.diag(cov))[:-3], gravity))
        if why is None and (q.dof >= MIN_DOF or model != "auto"):
            choice.append(f"{m}: fitted ({q.dof} spare equations)")
            return _result(m, a, o, cov, gravity, r, q, u, se, choice, _gain(jac, d_u, len(u)))
        if why is None:
            why = f"only {q.dof} spare equation(s), {MIN_DOF} needed to check the fit"
            fallback = fallback or (m, a, o, cov, r, q, len(choice), _gain(jac, d_u, len(u)))
        choice.append(f"{m}: {why}")
    if fallback is not None:
        m, a, o, cov, r, q, i, gain = fallback
        choice[i] = f"{m}: fitted with {q.dof} spare equation(s), {_fit.UNCHECKED}"
        return _result(m, a, o, cov, gravity, r, q, u, se, choice, gain)
    raise DegenerateDesignError(_too_few_message(u, choice))


def _gain(jac: np.ndarray, d_u: np.ndarray, n: int) -> np.ndarray:
    """d params / d pose means (p, n, 3) of a least-squares fit: ``-(J^T J)^-1 J^T dr/du``."""
    return -np.linalg.lstsq(jac, d_u, rcond=None)[0].reshape(jac.shape[1], n, 3)


def _result(m, a, o, cov, gravity, r, q, u, se, choice, gain) -> AccelFit:
    n, n_std = _directions(a, o, u, se)
    return AccelFit(model=m, matrix=a, offset=o, covariance=cov, gravity=gravity, residuals=r, fit=q,
                    directions=n, direction_std=n_std, choice=tuple(choice), pose_se=se, gain=gain)


def _too_few_message(u, choice) -> str:
    centred = u - u.mean(axis=0)
    # one pose (a log at rest), or poses all alike, leave nothing around the centre: use the directions
    cov = coverage(centred if np.all(np.linalg.norm(centred, axis=1) > 0) else u)
    need = max(0, 6 - cov.poses)
    where = ", ".join(f"{v:+.2f}" for v in cov.empty_cap_centre)
    more = (f"hold the board still in {need} more orientation(s)" if need
            else "add poses that face the direction the poses see least")
    return (f"the {len(u)} still poses ({cov.poses} distinct orientations, spread {cov.spread:.2f}) determine no "
            f"accelerometer model: at least 6 distinct orientations spread over the sphere are needed "
            f"(9 to check the fit, 12 for non-orthogonality); {more}, for example with the sensor direction "
            f"({where}) up [{'; '.join(choice)}]")
