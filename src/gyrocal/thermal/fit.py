"""Per-temperature 12-parameter least squares (the full-temperature-range method, eq. 13-19).

Eq. 13 stacks ``w = Kg Omega`` for every step. Because each gyro axis has its own
four unknowns (one row of K and one bias), the 12-parameter problem splits exactly
into three 4-parameter problems sharing the regressors ``[w~x, w~y, w~z, 1]``;
:func:`fit_point` solves those, and :func:`kg_eq19` keeps the paper's literal form
(the tests check that the two agree).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DegenerateDesignError
from ..models import KG_INDEX, kb_to_kg
from .session import Steps

__all__ = ["PointFit", "ThermalFit", "fit_point", "fit_session", "kg_eq19", "kg_from_beta", "omega_matrix"]


def omega_matrix(reference: np.ndarray) -> np.ndarray:
    """The paper's regressor matrix Omega-hat (12, 3n) for reference rates (n, 3) (eq. 15-17)."""
    n = len(reference)
    om = np.zeros((n, 3, 12))
    for e, (row, col) in enumerate(KG_INDEX):  # gyro axis `row` reads K[row, col] w~col (eq. 11)
        om[:, row, e] = reference[:, col]
    for row in range(3):
        om[:, row, 9 + row] = 1.0  # ... + B[row]
    return om.reshape(3 * n, 12).T


def kg_eq19(reference: np.ndarray, means: np.ndarray) -> np.ndarray:
    """Kg (12,) by eq. 19 as written: ``Kg = w^ Omega^T (Omega Omega^T)^-1``."""
    om = omega_matrix(reference)
    w = np.asarray(means, dtype=float).reshape(1, -1)  # eq. 18 order: x, y, z of step 1, then step 2, ...
    return (w @ om.T @ np.linalg.inv(om @ om.T)).ravel()


def kg_from_beta(beta: np.ndarray) -> np.ndarray:
    """Kg (..., 12) from per-axis solutions ``beta`` (..., 4, 3): ``beta[c, j] = K[j, c]``, ``beta[3, j] = B[j]``."""
    return kb_to_kg(np.swapaxes(beta[..., :3, :], -1, -2), beta[..., 3, :])


@dataclass(frozen=True)
class PointFit:
    """The fit at one temperature point.

    Attributes
    ----------
    kg : ndarray, shape (12,)
        Eq. 14 vector; K dimensionless, B [rad/s].
    std : ndarray, shape (12,)
        1-sigma from the residual variance of each gyro axis (dof = steps - 4).
    std_noise : ndarray, shape (12,)
        1-sigma predicted from each step's white noise and sample count.
    residuals : ndarray, shape (n, 3)
        Step means minus the fitted model [rad/s].
    """

    kg: np.ndarray
    std: np.ndarray
    std_noise: np.ndarray
    residuals: np.ndarray


def fit_point(reference, means, noise_var, count) -> PointFit:
    """Least squares of eq. 19 at one temperature.

    Parameters
    ----------
    reference : array_like, shape (n, 3)
        Reference body rates of the steps [rad/s].
    means : array_like, shape (n, 3)
        Step means [rad/s].
    noise_var : array_like, shape (n, 3)
        Per-sample noise variance of each step [rad/s]^2.
    count : array_like, shape (n,)
        Samples behind each mean.
    """
    ref = np.asarray(reference, float)
    X = np.column_stack([ref, np.ones(len(ref))])
    XtX = X.T @ X
    if len(ref) < 4 or np.linalg.cond(XtX) > 1e12:
        raise DegenerateDesignError(f"{len(ref)} steps cannot determine K and B at this temperature; each of x, y, z "
                                    "needs a non-zero table rate along it")
    inv = np.linalg.inv(XtX)
    beta = inv @ (X.T @ np.asarray(means, float))  # (4, 3), the full-temperature-range method, eq. 19 per axis
    resid = means - X @ beta
    dof = max(len(ref) - 4, 1)
    s2 = (resid ** 2).sum(axis=0) / dof  # (3,)
    var_resid = np.diag(inv)[:, None] * s2[None, :]  # (4, 3)
    H = inv @ X.T  # (4, n)
    var_noise = (H ** 2) @ (np.asarray(noise_var, float) / np.asarray(count, float)[:, None])
    return PointFit(kg=kg_from_beta(beta), std=np.sqrt(kg_from_beta(var_resid)),
                    std_noise=np.sqrt(kg_from_beta(var_noise)), residuals=resid)


@dataclass(frozen=True)
class ThermalFit:
    """Per-temperature fits of a session.

    Attributes
    ----------
    temps : ndarray, shape (p,)
        Temperature points [degC], increasing.
    kg, std, std_noise : ndarray, shape (p, 12)
        Eq. 14 vectors and their 1-sigma (see :class:`PointFit`).
    residual_rms : ndarray, shape (p, 3)
        RMS step residual per gyro axis [rad/s].
    steps : Steps
        The steps used.
    residuals : ndarray, shape (n, 3)
        Residual of each step [rad/s].
    """

    temps: np.ndarray
    kg: np.ndarray
    std: np.ndarray
    std_noise: np.ndarray
    residual_rms: np.ndarray
    steps: Steps
    residuals: np.ndarray


def fit_session(steps: Steps) -> ThermalFit:
    """Fit eq. 19 at every temperature point of grouped steps (see :func:`session_steps`)."""
    temps = steps.point_temps
    ref = steps.reference
    out = []
    resid = np.zeros_like(steps.mean)
    for p in range(len(temps)):
        sel = steps.point == p
        try:
            fp = fit_point(ref[sel], steps.mean[sel], steps.noise_var[sel], steps.count[sel])
        except DegenerateDesignError as exc:
            raise DegenerateDesignError(f"temperature point {temps[p]:.1f} degC: {exc}") from None
        resid[sel] = fp.residuals
        out.append(fp)
    rms = np.stack([np.sqrt(np.mean(f.residuals ** 2, axis=0)) for f in out])
    return ThermalFit(temps=temps, kg=np.stack([f.kg for f in out]), std=np.stack([f.std for f in out]),
                      std_noise=np.stack([f.std_noise for f in out]), residual_rms=rms, steps=steps, residuals=resid)
