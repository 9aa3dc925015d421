"""Samples stuck at a sensor's full scale."""

from __future__ import annotations

import numpy as np

from .._arrays import median
from .._validation import positive
from ..errors import InputError

__all__ = ["find_saturation", "MIN_RUN"]

#: Consecutive identical extreme samples that make a saturation run.
MIN_RUN = 5


def _long_runs(mask: np.ndarray, min_run: int) -> np.ndarray:
    """Keep only the runs of True that are at least `min_run` long."""
    idx = np.flatnonzero(mask)
    out = np.zeros_like(mask)
    if len(idx) < min_run:
        return out
    breaks = np.flatnonzero(np.diff(idx) != 1) + 1
    lengths = np.diff(np.r_[0, breaks, len(idx)])
    out[idx[np.repeat(lengths >= min_run, lengths)]] = True
    return out


def find_saturation(gyro, full_scale: float | None = None, *, min_run: int = MIN_RUN) -> np.ndarray:
    """Mask of saturated samples, axis by axis.

    Parameters
    ----------
    gyro : array_like, shape (N, 3)
        Readings, in any unit (the same as `full_scale`).
    full_scale : float, optional
        Sensor limit [same unit as `gyro`]. Readings with ``|m| >= full_scale`` are saturated.
        Without it, a sample is saturated when it belongs to a run of at least `min_run`
        identical readings at the axis's maximum or at its minimum (each tested on its own),
        that level's magnitude is more than twice the axis's median magnitude (a quiet,
        constant axis is not saturated), and readings pile up there: more than twice as many
        as at the next level inward. A clipped axis collects every reading beyond its limit;
        a smooth peak (a chip's low-pass filter at 1 kHz holds a turn's top reading for a few
        samples) visits its top level about as often as the one below.
    min_run : int
        Shortest run of stuck samples counted when `full_scale` is not given.

    Returns
    -------
    ndarray of bool, shape (N, 3)

    Notes
    -----
    Without `full_scale` the test relies on sensor noise: a real reading at a constant
    rate wanders by a few LSB, a clipped one does not. Noise-free simulated data at a
    constant rate can therefore look saturated; pass `full_scale` (or opt out) there.
    """
    g = np.asarray(gyro)
    if g.ndim != 2 or g.shape[1] != 3:
        raise InputError(f"gyro must have shape (N, 3), got {g.shape}")
    if full_scale is not None:
        return np.abs(g) >= positive("full_scale", full_scale)
    if int(min_run) < 1:
        raise InputError(f"min_run must be >= 1, got {min_run!r}")
    if len(g) == 0:
        return np.zeros(g.shape, dtype=bool)
    return stuck_runs(g, g.max(axis=0), g.min(axis=0), int(min_run))


def _piles_up(col: np.ndarray, level: float, at_level: int, top: bool) -> bool:
    """Whether readings pile up at `level`, the top or bottom extreme: more than twice as many as at the next
    level inward."""
    inward = col[col < level] if top else col[col > level]
    if not len(inward):
        return True
    nearest = inward.max() if top else inward.min()
    return at_level > 2 * int(np.count_nonzero(col == nearest))


def stuck_runs(g: np.ndarray, hi: np.ndarray, lo: np.ndarray, min_run: int = MIN_RUN) -> np.ndarray:
    """:func:`find_saturation` without a full scale, given each axis's maximum and minimum (3,)."""
    mask = np.zeros(g.shape, dtype=bool)
    for j in range(3):
        col = g[:, j]
        typical = None
        # each extreme on its own: a run stuck at +32767 counts even when one sample reads -32768
        for level in {hi[j], lo[j]}:  # a set: one pass for a constant axis
            if not np.isfinite(level) or level == 0:
                continue
            stuck = col == level
            if np.count_nonzero(stuck) < min_run:  # the common case: no pile-up at this extreme
                continue
            runs = _long_runs(stuck, min_run)
            if runs.any() and _piles_up(col, level, np.count_nonzero(stuck), level == hi[j]):
                typical = median(np.abs(col)) if typical is None else typical  # a sort: only when needed
                if abs(level) > 2.0 * typical:
                    mask[:, j] |= runs
    return mask
