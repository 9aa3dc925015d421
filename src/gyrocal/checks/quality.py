"""Goodness of fit: do the windows agree with the model within their noise?

Every fit leaves residuals: a turn's mean rate against its reference, a static window's mean
against the bias. In noise units (each divided by its own predicted standard deviation) their
sum of squares is chi-squared with ``rows - parameters`` degrees of freedom when the model and
the noise are right; so is each group's (the turns, the static levels) with its own degrees of
freedom. A p-value below 0.001, of all rows or of one group, says they are not: the covariance
built from the noise alone is then too small, and a warning names the windows that disagree
most. The first-moment fit then carries each group's scatter beyond the noise into its
covariance (:mod:`gyrocal.checks.excess`); the paper's methods scale it by chi^2 / dof (the Birge ratio
squared, as metrology and particle-physics averages do). With no degrees of freedom left the
fit cannot check itself, and says so.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["P_THRESHOLD", "GoodnessOfFit", "assess_fit"]

#: Below this p-value the windows disagree beyond their noise and the covariance is scaled.
P_THRESHOLD = 1e-3
#: Below this p-value (of a group) a scatter beyond the noise is worth a note; the 1-sigma carries it either way.
NOTE_P = 1e-2
_NAMED = 3  # windows named in a warning


@dataclass(frozen=True)
class GoodnessOfFit:
    """How well the windows agree with the fitted model.

    Attributes
    ----------
    chi2 : float
        Sum of squared residuals in noise units.
    dof : int
        Degrees of freedom: residual rows minus parameters (0: nothing to check).
    p_value : float or None
        Probability of a chi2 at least this large if the model and noise were right; None
        without degrees of freedom.
    birge_ratio : float or None
        ``sqrt(chi2 / dof)``; None without degrees of freedom.
    covariance_scaled : bool
        Whether the reported covariance was multiplied by ``birge_ratio**2``.
    labels : tuple of str
        One name per window, in the order of the calibration's windows.
    residuals : tuple of tuple of float
        Each window's residuals in noise units: one for a rotation, three (x, y, z) for a static window.
    disagree : tuple of int
        Windows that disagree most (largest share of chi2), when the fit is flagged.
    warnings : tuple of str
        Lines for people (the command line prints each as ``warning: ...``).
    excess : dict or None
        The scatter beyond the noise carried into the covariance (:meth:`gyrocal.checks.excess.Excess.to_document`),
        with each group's noise-only chi2 and degrees of freedom; None when none was looked for.
    notes : tuple of str
        Lines for people that are not warnings (a scatter beyond the noise too small to flag).
    """

    chi2: float
    dof: int
    p_value: float | None
    birge_ratio: float | None
    covariance_scaled: bool
    labels: tuple[str, ...]
    residuals: tuple[tuple[float, ...], ...]
    disagree: tuple[int, ...] = ()
    warnings: tuple[str, ...] = ()
    excess: dict | None = None
    notes: tuple[str, ...] = ()

    @property
    def chi2_per_dof(self) -> float | None:
        return self.chi2 / self.dof if self.dof > 0 else None

    def summary(self) -> str:
        """One line: chi2/dof, p-value and what was done."""
        if self.dof == 0:
            return f"fit quality: chi2 {self.chi2:.3g} with no residual degrees of freedom (nothing to check)"
        text = (f"fit quality: chi2/dof {self.chi2:.4g}/{self.dof} = {self.chi2 / self.dof:.3g}, "
                f"p = {self.p_value:.3g}")
        if self.covariance_scaled and self.excess is None:
            text += f"; 1-sigma scaled by the Birge ratio {self.birge_ratio:.3g}"
        for g in (self.excess or {}).get("groups", ()):
            if g["dof"] > 0.5:
                text += f"; {g['name']} {g['chi2']:.4g}/{g['dof']:.3g}"
        return text

    def to_document(self) -> dict:
        """JSON-ready record (the calibration file's ``fit`` section)."""
        return {
            "chi2": self.chi2,
            "dof": self.dof,
            "chi2_per_dof": self.chi2_per_dof,
            "p_value": self.p_value,
            "birge_ratio": self.birge_ratio,
            "covariance_scaled": self.covariance_scaled,
            "residuals": [list(z) for z in self.residuals],
            "labels": list(self.labels),
            "disagree": list(self.disagree),
            "warnings": list(self.warnings),
            "excess": self.excess,
            "notes": list(self.notes),
        }

    @classmethod
    def from_document(cls, doc: dict) -> GoodnessOfFit:
        """Inverse of :meth:`to_document`."""
        res = doc.get("residuals") or []
        return cls(
            chi2=float(doc["chi2"]), dof=int(doc["dof"]),
            p_value=None if doc.get("p_value") is None else float(doc["p_value"]),
            birge_ratio=None if doc.get("birge_ratio") is None else float(doc["birge_ratio"]),
            covariance_scaled=bool(doc.get("covariance_scaled", False)),
            labels=tuple(str(lab) for lab in doc.get("labels") or [""] * len(res)),
            residuals=tuple(tuple(float(v) for v in z) for z in res),
            disagree=tuple(int(i) for i in doc.get("disagree", ())),
            warnings=tuple(str(w) for w in doc.get("warnings", ())),
            excess=doc.get("excess"),
            notes=tuple(str(n) for n in doc.get("notes", ())),
        )


def _name(i: int, label: str, z: Sequence[float]) -> str:
    size = float(np.sqrt(np.sum(np.square(z))))
    return f"window {i} ({label}, {size:.3g} sigma)"


def _group_p(groups) -> list[tuple[str, float, float, float]]:
    """``(name, chi2, dof, p)`` of each group with degrees of freedom."""
    from .._chi2 import chi2_sf

    return [(g.name, g.chi2, g.dof, float(chi2_sf(g.dof, g.chi2))) for g in groups if g.dof > 0.5]


def assess_fit(residuals: Sequence[Sequence[float]], labels: Sequence[str], n_params: int, *,
               what: str = "the windows", excess=None, widened: str = "",
               excess_document: dict | None = None) -> GoodnessOfFit:
    """Goodness of fit from per-window residuals in noise units.

    Parameters
    ----------
    residuals : sequence of sequences of float
        Each window's residuals divided by their predicted standard deviation (noise alone).
    labels : sequence of str
        Window names, for the warning.
    n_params : int
        Parameters fitted.
    what : str
        What the rows are, for the messages.
    excess : Excess, optional
        The groups' noise-only chi2 and the extra variances the covariance carries
        (:func:`gyrocal.checks.excess.widen`); without it a flagged fit is scaled by the Birge ratio.
    widened : str
        The extra variances in words (:meth:`gyrocal.checks.excess.Excess.describe`), for the messages.
    excess_document : dict, optional
        Their record for the file (:meth:`gyrocal.checks.excess.Excess.to_document`).
    """
    from .._chi2 import chi2_sf  # the chi-square survival function without scipy's import

    z = [np.asarray(r, dtype=float).ravel() for r in residuals]
    per_window = np.array([float(np.dot(r, r)) for r in z])
    chi2 = float(per_window.sum())
    rows = sum(len(r) for r in z)
    dof = rows - n_params
    zs = tuple(tuple(r.tolist()) for r in z)
    if dof <= 0:
        note = (f"no residual degrees of freedom: {rows} equations for {n_params} parameters, so nothing checks "
                f"{what} against each other; add static windows or repeat turns to let the fit check itself")
        return GoodnessOfFit(chi2, 0, None, None, False, tuple(labels), zs, (), (note,))
    p = float(chi2_sf(dof, chi2))
    birge = math.sqrt(chi2 / dof)
    groups = _group_p(excess.groups) if excess is not None else []
    doc = excess_document
    widened_any = excess is not None and excess.any
    flagged = p < P_THRESHOLD or any(g[3] < P_THRESHOLD for g in groups)
    if not flagged:
        notable = [g for g in groups if g[3] < NOTE_P] if widened_any else []
        notes = (("; ".join(f"the {name} scatter beyond their noise (chi2 {c:.3g} for {d:.3g} dof, p = {q:.2g})"
                            for name, c, d, q in notable) + f", not enough to flag; the 1-sigma includes {widened}",)
                 if notable else ())
        return GoodnessOfFit(chi2, dof, p, birge, widened_any, tuple(labels), zs, excess=doc, notes=notes)
    worst = tuple(int(i) for i in np.argsort(-per_window)[:_NAMED])
    names = ", ".join(_name(i, labels[i], z[i]) for i in worst)
    split = "".join(f"; {name}: chi2 {c:.3g} for {d:.3g} dof (p = {q:.2g})" for name, c, d, q in groups)
    carried = (f"the 1-sigma includes their scatter beyond the noise: {widened}" if excess is not None
               else f"every 1-sigma is scaled by the Birge ratio {birge:.3g}")
    warning = (f"{what} disagree beyond their noise: chi2/dof = {chi2 / dof:.3g} ({dof} dof, p = {p:.2g}){split}; "
               f"most: {names}; {carried}. Check these windows (declared angle or speed, a slipping mount, "
               "a drifting bias)")
    return GoodnessOfFit(chi2, dof, p, birge, widened_any if excess is not None else True, tuple(labels), zs, worst,
                         (warning,), excess=doc)

