"""Goodness of fit and covariance of a weighted least-squares fit, shared by the accelerometer and gyro fits."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import stats

__all__ = ["FitQuality", "covariance", "group_factors", "quality", "redundancy", "relative_rank"]

#: A fit is scaled by its Birge ratio when chi2 / dof is above 1 with a p-value below this.
SCALE_P = 0.05
#: Columns whose scaled singular value is below this fraction of the largest are not determined.
RANK_RTOL = 1e-7


@dataclass(frozen=True)
class FitQuality:
    """Chi-square summary of normalised residuals.

    Attributes
    ----------
    chi2 : float
    dof : int
        Equations minus parameters.
    p_value : float
        Probability of a chi2 at least this large if the noise model held (NaN when dof = 0).
    birge_ratio : float
        ``sqrt(chi2 / dof)`` (NaN when dof = 0).
    covariance_scaled : bool
        Whether the covariance was multiplied by ``birge_ratio**2`` (residuals above the noise).
    warnings : tuple of str
    """

    chi2: float
    dof: int
    p_value: float
    birge_ratio: float
    covariance_scaled: bool
    warnings: tuple[str, ...] = field(default_factory=tuple)

    def to_dict(self) -> dict:
        return {"chi2": float(self.chi2), "dof": int(self.dof), "p_value": _finite_or_none(self.p_value),
                "birge_ratio": _finite_or_none(self.birge_ratio), "covariance_scaled": bool(self.covariance_scaled),
                "warnings": list(self.warnings)}


def _finite_or_none(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


#: How a model choice says it took a model with too few spare equations (:func:`unchecked_warning`).
UNCHECKED = "too few to check it"


def unchecked_warning(sensor: str, choice) -> list[str]:
    """A warning when the `sensor`'s model was taken with too few spare equations to check it."""
    line = next((c for c in choice if UNCHECKED in c), None)
    if line is None:
        return []
    return [f"the {sensor} model was fitted with too few spare equations to check it ({line}): its 1-sigma leaves "
            "out what the larger models fit (a real sensor's axes are a few tenths of a degree from orthogonal), so "
            "it may be several sigmas off; add poses (a dozen or more) so that the full model can check itself"]


def quality(residuals: np.ndarray, n_params: int, what: str) -> FitQuality:
    """Chi-square of normalised `residuals` with `n_params` fitted; `what` names the fit in warnings."""
    r = np.asarray(residuals, dtype=float)
    chi2, dof = float(r @ r), int(r.size - n_params)
    if dof <= 0:
        return FitQuality(chi2, max(dof, 0), np.nan, np.nan, False,
                          (f"{what}: as many equations as parameters, so the fit cannot be checked; "
                           "the uncertainty assumes the noise model holds",))
    p = float(stats.chi2.sf(chi2, dof))
    birge = float(np.sqrt(chi2 / dof))
    scaled = birge > 1.0 and p < SCALE_P
    warnings = ()
    if scaled:
        warnings = (f"{what}: residuals are {birge:.2g} times the noise (chi2 = {chi2:.1f} for {dof} dof, "
                    f"p = {p:.2g}); the uncertainties are scaled up by that factor",)
    return FitQuality(chi2, dof, p, birge, scaled, warnings)


def relative_rank(jac: np.ndarray) -> tuple[int, np.ndarray]:
    """Numerical rank of a Jacobian after scaling its columns to unit norm, and the scaled singular values."""
    norms = np.linalg.norm(jac, axis=0)
    scaled = jac / np.where(norms > 0, norms, 1.0)
    s = np.linalg.svd(scaled, compute_uv=False)
    return int(np.sum(s > RANK_RTOL * s[0])) if s.size and s[0] > 0 else 0, s


def covariance(jac: np.ndarray, fit: FitQuality) -> np.ndarray:
    """Parameter covariance from the Jacobian of normalised residuals, Birge-scaled when `fit` says so."""
    _, s, vt = np.linalg.svd(jac, full_matrices=False)
    cov = (vt.T / s**2) @ vt
    return cov * fit.birge_ratio**2 if fit.covariance_scaled else cov


def redundancy(jac: np.ndarray, groups: np.ndarray, n_groups: int) -> np.ndarray:
    """Sum over each group of its equations' redundancy numbers ``1 - h_ii``: the group's share of the dof."""
    u, s, _ = np.linalg.svd(jac, full_matrices=False)
    u = u[:, s > RANK_RTOL * s[0]] if s.size and s[0] > 0 else u[:, :0]
    r = 1.0 - np.einsum("ij,ij->i", u, u)
    return np.array([r[groups == k].sum() for k in range(n_groups)])


def group_factors(residuals: np.ndarray, groups: np.ndarray, factors: np.ndarray, expected: np.ndarray) -> np.ndarray:
    """One step of variance-component estimation: new noise factors (>= 1) of each equation group.

    Each group's chi-square is compared with what its noise model leads one to expect after the
    fit (`expected`, for example the sum of its equations' redundancy numbers ``1 - h_ii`` when
    the equations are independent). A group is inflated when its residuals are significantly
    above that (p < :data:`SCALE_P`), or keeps being adjusted once it has been; no group is ever
    trusted more than its noise model says. `residuals` are already divided by the current `factors`.
    """
    new = np.array(factors, dtype=float)
    for g in range(len(factors)):
        sel = groups == g
        if expected[g] < 0.5:
            continue
        chi2 = float(residuals[sel] @ residuals[sel])
        if factors[g] > 1.0 or stats.chi2.sf(chi2, expected[g]) < SCALE_P:
            new[g] = max(1.0, factors[g] * np.sqrt(chi2 / expected[g]))
    return new
