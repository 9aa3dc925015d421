"""White noise read off first differences: one definition for every caller that means it.

Successive differences of white noise of variance ``s^2`` have variance ``2 s^2`` and cancel any level or
slow drift, so half their mean square is the white variance of a window even while it turns at a constant
rate. Callers that need the same estimate for many windows at once from running sums
(:mod:`gyrocal.observations.moments`, :mod:`gyrocal.thermal.session`) compute this same quantity in that
form; the second-difference estimate of :mod:`gyrocal.verify.whitenoise` is a different one, robust to a
changing rate.
"""

from __future__ import annotations

import math

import numpy as np

from ._arrays import median
from .constants import MAD_TO_SIGMA

__all__ = ["difference_variance", "robust_difference_std"]


def difference_variance(d: np.ndarray, axis: int = 0) -> np.ndarray | float:
    """White-noise variance from first differences `d`: half their mean square along `axis` (0 when empty)."""
    d = np.asarray(d, dtype=float)
    if d.shape[axis] == 0:
        return np.zeros(np.delete(d.shape, axis)) if d.ndim > 1 else 0.0
    return np.mean(d * d, axis=axis) / 2.0


def robust_difference_std(d: np.ndarray, axis: int = 0) -> np.ndarray:
    """White-noise standard deviation from first differences `d`, robust to steps and turns: the MAD of the
    differences about their median, as a normal sigma, over sqrt(2)."""
    d = np.asarray(d, dtype=float)
    centre = median(d, axis=axis, keepdims=True)
    return MAD_TO_SIGMA * median(np.abs(d - centre), axis=axis) / math.sqrt(2.0)
