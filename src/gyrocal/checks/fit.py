"""The self-checks of a fit: goodness of fit, scatter beyond the noise carried into the covariance, plausibility.

:func:`check_fit` runs after the estimator: it tests the windows against their noise (all rows,
and the turns and the static levels as groups, :mod:`gyrocal.checks.quality`), widens the first-moment
covariance by each group's scatter beyond the noise (:mod:`gyrocal.checks.excess`; the paper's methods
are scaled by the Birge ratio instead), and judges the scale factors (:mod:`gyrocal.checks.plausibility`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from ..estimators import FitResult, window_residuals
from ..observations import ObservationSet
from .excess import widen
from .plausibility import Context, check_plausibility
from .quality import GoodnessOfFit, assess_fit

__all__ = ["check_fit", "single_turn_warnings", "with_common_scale"]


def check_fit(fit: FitResult, obs: ObservationSet, estimator, labels: Sequence[str], *, reference: str,
              ctx: Context, input_scale: float) -> tuple[FitResult, ObservationSet, GoodnessOfFit, list[str], list[str]]:
    """Check `fit` of `obs`; returns the fit to report (widened where the windows scatter), its windows,
    the goodness of fit, and the warnings and notes for people.

    `input_scale` is internal units per input unit (static levels are reported in the input unit).
    """
    first_moment = fit.method == "first-moment"
    what = "the turns and static windows" if first_moment else "the turns"
    residuals = window_residuals(fit, obs)  # in noise units, before any widening
    if first_moment:
        fit, obs, excess = widen(fit, obs, estimator, reference)
        quality = assess_fit(residuals, labels, len(fit.model.params), what=what, excess=excess,
                             widened=excess.describe(input_scale, ctx.units),
                             excess_document=excess.to_document(input_scale, ctx.units))
    else:
        quality = assess_fit(residuals, labels, len(fit.model.params), what=what)
        if quality.covariance_scaled and fit.covariance is not None:
            fit = dataclasses.replace(fit, covariance=fit.covariance * quality.birge_ratio**2)
    plausible, notes = check_plausibility(fit.model.k, ctx)
    return fit, obs, quality, list(quality.warnings) + plausible, list(quality.notes) + notes


def single_turn_warnings(axes: Sequence[str], reference: str, declared: float | None) -> list[str]:
    """A warning when some scale factor rests on one turn (`axes`: the turns' axes): its residual is zero,
    nothing checks it. `declared`: the one angle [rad] or speed declared, None for a windows file's angles."""
    alone = [a for a in "xyz" if list(axes).count(a) == 1]
    if not alone:
        return []
    many = len(alone) > 1
    if reference == "angle" and declared is not None:
        deg = math.degrees(declared)
        what = f"its declared angle (1 deg in {deg:g} is {1 / deg:.2g} in k)"
    else:
        what = f"its declared {'angle' if reference == 'angle' else 'speed'}"
    return [f"the scale factor{'s' if many else ''} of {', '.join(alone)} rest{'' if many else 's'} on one turn"
            f"{' each' if many else ''}: nothing in the data checks {what}; turn both ways or repeat the turns so "
            "that the fit can check itself"]


def with_common_scale(fit: FitResult, rel_sd: float) -> FitResult:
    """`fit` whose covariance carries a relative error `rel_sd` common to every reference rate (a known speed
    that is off on every plateau alike): each k moves with it, all three together; b does not."""
    if fit.covariance is None or not rel_sd:
        return fit
    j = np.concatenate([np.asarray(fit.model.k, dtype=float), np.zeros(3)])
    return dataclasses.replace(fit, covariance=fit.covariance + rel_sd**2 * np.outer(j, j))
