"""Calibrations of one unit compared parameter by parameter, in units of their 1-sigma.

A unit calibrated twice (after a power cycle, a week later, on another rig) should give
parameters that differ by no more than their uncertainties allow. Each calibration is
compared with the first: the difference of every parameter divided by the combined
1-sigma ``sqrt(s_first**2 + s_other**2)`` (a z-score), and, where both carry a full
covariance, the joint ``chi2 = d^T (C_first + C_other)^-1 d`` with its p-value.

Calibrations of one model compare in that model's parameters: ``k`` and ``b`` of the
servo method of Wang et al. (eq. 1) or ``Kg`` of the full-temperature-range method
(eq. 14). A scale-bias calibration compared with an affine one is mapped to ``Kg``
(``K = diag(1/k)``, ``B = -b``) with its covariance. Thermal tables compare point by point
at shared temperatures, with their per-element 1-sigma (the table keeps no covariance, so
the joint figure there treats the elements as independent).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..models import KG_NAMES, ScaleBias
from ..results.calibration import Calibration
from ..thermal.model import ThermalCalibration

__all__ = ["Comparison", "compare_calibrations"]

#: Joint p-value under which calibrations are said to differ (without a tolerance).
P_DIFFER = 0.01


@dataclass(frozen=True)
class Comparison:
    """Parameters of several calibrations and their differences from the first.

    Attributes
    ----------
    labels : tuple of str
        One per calibration (file names, usually).
    names : tuple of str
        Parameter names.
    units : tuple of str
        Unit of each parameter as shown (``""`` for dimensionless).
    values, std : ndarray, shape (n, p)
        Parameters and 1-sigma in the shown units (std NaN when a file has none).
    diff : ndarray, shape (n - 1, p)
        ``values[i] - values[0]``.
    z : ndarray, shape (n - 1, p)
        ``diff`` over the combined 1-sigma (NaN without both 1-sigma).
    chi2 : ndarray, shape (n - 1,)
        Joint chi-square of each difference (NaN without covariances).
    dof : ndarray of int, shape (n - 1,)
        Its degrees of freedom: the parameters both covariances constrain.
    p_value : ndarray, shape (n - 1,)
        Probability of a chi2 this large when the calibrations agree.
    joint : str
        ``"covariance"``, or ``"diagonal"`` when only per-parameter 1-sigma were known.
    """

    labels: tuple[str, ...]
    names: tuple[str, ...]
    units: tuple[str, ...]
    values: np.ndarray
    std: np.ndarray
    diff: np.ndarray
    z: np.ndarray
    chi2: np.ndarray
    dof: np.ndarray
    p_value: np.ndarray
    joint: str

    @property
    def max_abs_z(self) -> np.ndarray:
        """Largest |z| of each comparison with the first (NaN when unknown)."""
        return np.array([np.nan if np.all(np.isnan(row)) else float(np.nanmax(np.abs(row))) for row in self.z])

    def within(self, tolerance: float) -> np.ndarray:
        """Whether every parameter of each calibration lies within `tolerance` combined
        1-sigma of the first (bool, shape (n - 1,)). Needs every 1-sigma."""
        if np.isnan(self.z).any():
            missing = [self.labels[i + 1] for i in range(len(self.z)) if np.isnan(self.z[i]).any()]
            raise InputError(f"{', '.join(missing)} (or {self.labels[0]}) carries no 1-sigma for some parameters, so "
                             "no difference can be measured in sigmas; recalibrate with a gyrocal that writes them")
        return np.all(np.abs(self.z) <= tolerance, axis=1)

    def verdicts(self, tolerance: float | None = None) -> list[str]:
        """One sentence per comparison with the first."""
        out = []
        within = None if tolerance is None else self.within(tolerance)
        for i, label in enumerate(self.labels[1:]):
            worst = int(np.nanargmax(np.abs(self.z[i]))) if not np.all(np.isnan(self.z[i])) else None
            where = "" if worst is None else f" (largest: {self.names[worst]} at {self.z[i, worst]:+.2f} sigma)"
            if within is not None:
                verdict = "within" if within[i] else "OUTSIDE"
                out.append(f"{label}: {verdict} {tolerance:g} sigma of {self.labels[0]}{where}")
            elif math.isnan(self.p_value[i]):
                out.append(f"{label}: no uncertainties to judge the difference from {self.labels[0]}{where}")
            else:
                agree = "agrees with" if self.p_value[i] >= P_DIFFER else "differs from"
                out.append(f"{label}: {agree} {self.labels[0]}: chi2 {self.chi2[i]:.1f} for {self.dof[i]} parameters, "
                           f"p = {self.p_value[i]:.2g}{where}")
        return out


def _scale_bias_to_kg(params: np.ndarray, cov: np.ndarray | None) -> tuple[np.ndarray, np.ndarray | None]:
    """Kg (12,) and its covariance from scale-bias ``(k, b)`` and theirs (K = diag(1/k), B = -b)."""
    k, b = params[:3], params[3:]
    kg = np.concatenate([1.0 / k, np.zeros(6), -b])
    if cov is None:
        return kg, None
    jac = np.zeros((12, 6))
    jac[np.arange(3), np.arange(3)] = -1.0 / k**2
    jac[np.arange(9, 12), np.arange(3, 6)] = -1.0
    return kg, jac @ cov @ jac.T


def _calibration_parameters(cals: Sequence[Calibration]):
    """Values, covariances (internal units), names and kind shared by all."""
    internal = {c.internal_units for c in cals}
    if len(internal) > 1:
        raise InputError("the calibrations do not share a unit: some are for raw counts without a sensitivity, "
                         "others for rates; their scale factors cannot be compared")
    kinds = {c.model.kind for c in cals}
    if len(kinds) == 1:
        return ([np.asarray(c.model.params, float) for c in cals], [c.covariance for c in cals],
                tuple(cals[0].model.param_names), kinds.pop())
    values, covs = [], []
    for c in cals:
        if isinstance(c.model, ScaleBias):
            v, cov = _scale_bias_to_kg(np.asarray(c.model.params, float), c.covariance)
        else:
            v, cov = np.asarray(c.model.params, float), c.covariance
        values.append(v)
        covs.append(cov)
    return values, covs, KG_NAMES, "affine"


def _display(names: tuple[str, ...], first: Calibration) -> tuple[np.ndarray, tuple[str, ...]]:
    """Multipliers from internal units to shown units, and the units' names: biases in the
    first calibration's input units, scale terms as stored (rad/s per count for raw counts)."""
    bias = np.array([n.lower().startswith("b") for n in names])
    scale = np.where(bias, 1.0 / first.input_scale, 1.0)
    other = "rad/s per count" if first.internal_units == "counts" else ""
    return scale, tuple(first.input_units if b else other for b in bias)


def _joint(diff: np.ndarray, cov_a, cov_b) -> tuple[float, int]:
    """``chi2 = d^T (C_a + C_b)^+ d`` over the directions the covariances span, and their number."""
    if cov_a is None or cov_b is None:
        return math.nan, 0
    lam, vec = np.linalg.eigh(cov_a + cov_b)
    keep = lam > 1e-12 * max(float(lam.max()), np.finfo(float).tiny)
    proj = vec[:, keep].T @ diff
    return float(np.sum(proj**2 / lam[keep])), int(keep.sum())


def _compare_vectors(labels, names, units, values, stds, covs, joint: str) -> Comparison:
    from .._chi2 import chi2_sf

    values, stds = np.asarray(values), np.asarray(stds)
    diff = values[1:] - values[0]
    combined = np.sqrt(stds[1:] ** 2 + stds[0] ** 2)
    # a parameter both files fix (1-sigma 0) counts as agreeing when equal; without 1-sigma z is unknown
    fixed = np.where(diff == 0, 0.0, np.inf)
    z = np.where(np.isnan(combined), np.nan, np.where(combined > 0, diff / np.where(combined > 0, combined, 1.0), fixed))
    chi2, dof = (np.array(x) for x in zip(*(_joint(diff[i], covs[0], covs[i + 1]) for i in range(len(diff)))))
    p = np.array([math.nan if math.isnan(c) or d == 0 else chi2_sf(float(d), float(c)) for c, d in zip(chi2, dof)])
    return Comparison(tuple(labels), tuple(names), tuple(units), values, stds, diff, z, chi2, dof, p, joint)


def _calibration_comparison(cals: Sequence[Calibration], labels) -> Comparison:
    values, covs, names, _ = _calibration_parameters(cals)
    scale, units = _display(names, cals[0])
    shown = [v * scale for v in values]
    stds = [np.full(len(names), np.nan) if c is None else np.sqrt(np.diag(c)) * scale for c in covs]
    shown_covs = [None if c is None else c * np.outer(scale, scale) for c in covs]
    # A parameter fixed at zero in every file (the off-diagonal K of two scale-bias files) says nothing.
    keep = ~np.all([(np.asarray(s) == 0) & (np.asarray(v) == 0) for s, v in zip(stds, shown)], axis=0)
    shown_covs = [None if c is None else c[np.ix_(keep, keep)] for c in shown_covs]
    return _compare_vectors(labels, [n for n, k in zip(names, keep) if k], [u for u, k in zip(units, keep) if k],
                            [v[keep] for v in shown], [s[keep] for s in stds], shown_covs, "covariance")


def _thermal_comparison(tcs: Sequence[ThermalCalibration], labels) -> Comparison:
    temps = tcs[0].temps
    for tc, label in zip(tcs[1:], labels[1:]):
        if tc.temps.shape != temps.shape or not np.allclose(tc.temps, temps, rtol=0, atol=0.5):
            raise InputError(f"{label} is calibrated at other temperatures than {labels[0]} "
                             f"({np.round(tc.temps, 1).tolist()} against {np.round(temps, 1).tolist()} degC); "
                             "thermal tables compare point by point at the same temperatures")
        if tc.input_units != tcs[0].input_units or tc.output_units != tcs[0].output_units:
            raise InputError(f"{label} is for other units than {labels[0]}; compare tables of one unit setting")
    names = tuple(f"{n}@{t:g}C" for t in temps for n in KG_NAMES)
    unit = tcs[0].input_units
    units = tuple(unit if n.startswith("B") else "" for _ in temps for n in KG_NAMES)
    values = [tc.kg_user.ravel() for tc in tcs]
    stds = [np.full(12 * len(temps), np.nan) if tc.std is None else tc.to_user(tc.std).ravel() for tc in tcs]
    covs = [None if np.isnan(s).any() else np.diag(s**2) for s in stds]
    return _compare_vectors(labels, names, units, values, stds, covs, "diagonal")


def compare_calibrations(cals: Sequence[Calibration | ThermalCalibration], labels: Sequence[str] | None = None,
                         ) -> Comparison:
    """Compare calibrations of one unit with the first of them.

    Parameters
    ----------
    cals : sequence of Calibration or ThermalCalibration
        Two or more, all of one kind.
    labels : sequence of str, optional
        Names shown for them; default ``#1``, ``#2``, ...

    Returns
    -------
    Comparison
    """
    cals = list(cals)
    labels = tuple(labels) if labels is not None else tuple(f"#{i + 1}" for i in range(len(cals)))
    if len(cals) < 2 or len(labels) != len(cals):
        raise InputError(f"compare needs at least two calibrations and one label each, got {len(cals)} and "
                         f"{len(labels)}")
    if all(isinstance(c, Calibration) for c in cals):
        return _calibration_comparison(cals, labels)
    if all(isinstance(c, ThermalCalibration) for c in cals):
        return _thermal_comparison(cals, labels)
    raise InputError("compare calibration files with calibration files and thermal files with thermal files; "
                     "a thermal table has no single temperature to compare a calibration with")
