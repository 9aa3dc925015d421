"""Which candidate turns are the calibration turns: recognised by structure, checked against the declaration.

A declared angle (or speed) is a hypothesis, not a fact. A candidate turn is taken for the
declared one when

* its measured size (raw angle, or plateau rate) is what the declared one reads through a
  scale factor in `k_range` (default 0.45-2.2, so a poor gyro with k from 0.5 to 2 is found;
  the calibration then warns about k far from 1), and
* it agrees with the other turns about the same axis: one scale factor per axis explains
  every accepted turn, within `agree_tol`. The reference turn of an axis is the one closest
  to the declaration; the others must match it.

Turns left out keep their measured size in the reason, so a person sees what was there.
"""

from __future__ import annotations

import math

import numpy as np

from .._arrays import median

__all__ = ["K_RANGE", "AGREE_TOL", "select_by_axis"]

#: Scale factors a detected turn may imply: a poor gyro (k 0.5-2.0, the servo paper's extreme study
#: reaches 2.0) with room for noise. Beyond this a motion is not the declared turn.
K_RANGE = (0.45, 2.2)
#: Turns about one axis that differ by more than this (relative) are not the same declared turn.
AGREE_TOL = 0.10


def select_by_axis(
    size: np.ndarray,
    axis: np.ndarray,
    declared: float,
    *,
    eligible: np.ndarray | None = None,
    k_range: tuple[float, float] = K_RANGE,
    agree_tol: float = AGREE_TOL,
    describe,
) -> tuple[np.ndarray, list[str | None]]:
    """Keep the candidates whose measured `size` one per-axis scale factor explains.

    Parameters
    ----------
    size : ndarray, shape (R,)
        Measured size of each candidate, in the unit of `declared` (> 0).
    axis : ndarray of int, shape (R,)
        Dominant body axis (0, 1, 2) of each candidate.
    declared : float
        The declared size.
    eligible : ndarray of bool, shape (R,), optional
        Candidates with the structure of a turn; the others are neither kept nor judged
        (their reason is None: the caller gives it).
    k_range : (float, float)
        Scale factors a candidate may imply (``declared / size``).
    agree_tol : float
        Relative spread allowed between the turns of one axis.
    describe : callable
        ``describe(value) -> str``: a size in people's units (e.g. ``"178 deg"``).

    Returns
    -------
    keep : ndarray of bool, shape (R,)
    reasons : list of str or None
        Why each candidate that is not kept was left out.
    """
    size = np.asarray(size, dtype=float)
    axis = np.asarray(axis)
    ok = np.ones(len(size), dtype=bool) if eligible is None else np.asarray(eligible, dtype=bool)
    lo, hi = declared / k_range[1], declared / k_range[0]
    in_range = (size >= lo) & (size <= hi) & ok
    keep = np.zeros(len(size), dtype=bool)
    reasons: list[str | None] = [None] * len(size)
    tol = math.log1p(agree_tol)
    for j in range(3):
        mine = np.flatnonzero(in_range & (axis == j))
        if not len(mine):
            continue
        log = np.log(size[mine])
        anchor = log[np.argmin(np.abs(log - math.log(declared)))]
        centre = float(median(log[np.abs(log - anchor) <= tol]))
        agree = np.abs(log - centre) <= tol
        keep[mine[agree]] = True
        for i in mine[~agree]:
            reasons[i] = (f"{describe(size[i])} where the other {'xyz'[j]} turns make {describe(math.exp(centre))} "
                          f"(declared {describe(declared)}): one scale factor cannot explain both")
    for i in np.flatnonzero(~in_range & ok):
        k = declared / size[i]
        reasons[i] = (f"{describe(size[i])}, declared {describe(declared)}: that is a scale factor of {k:.3g}, "
                      f"outside {k_range[0]:g}-{k_range[1]:g}")
    return keep, reasons
