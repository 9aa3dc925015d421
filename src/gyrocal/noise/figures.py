"""The three noise figures read off an Allan deviation curve, each with its interval.

Read as in IEEE Std 952, annex C:

* white-noise density ``N`` (angle random walk for a gyro, velocity random walk for an
  accelerometer): the -1/2 slope line fitted where the curve follows it, read at ``tau = 1 s``
  (:mod:`.white`: the range fitted, the interval from the correlated points, departures);
* bias instability ``B``: the flat minimum divided by ``sqrt(2 ln 2 / pi) = 0.664``
  (not reached while the curve still falls at the longest averaging time);
* random walk ``K`` of the bias: the +1/2 slope line read at ``tau = 3 s`` (not seen when
  the curve never turns up). Kalibr's ``*_random_walk`` is this ``K`` (Kalibr wiki, "IMU
  Noise Model": the bias is Brownian motion driven by white noise of that strength).

``B`` and ``K`` are read at one point: ``K``'s line goes through the point of the long side
whose local log-log slope is closest to +1/2. Such a figure is the
Allan deviation at that point times a fixed factor, so its interval is the point's
interval (:func:`.allan.confidence`, from the edf of the noise type the line stands for)
times the same factor. Where ``K`` is not seen, the curve still bounds it: the Allan
variance at ``tau`` is at least ``K^2 tau / 3``, so ``K <= sigma(tau) sqrt(3 / tau)``,
taken at the 95 % upper limit of ``sigma`` and minimised over the long-tau side.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from .allan import confidence, edf
from .white import fit_white_line

__all__ = ["BI_FACTOR", "Figure", "read_figures"]

#: Flicker-floor factor: the Allan deviation of bias instability B levels at 0.664 B.
BI_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)
#: A point's local slope must be within this of the line's slope to be read.
_SLOPE_TOLERANCE = 0.25
#: Rows of every figure: the three axes, then the sensor (the axes' pooled Allan variance).
ROWS = ("x", "y", "z", "sensor")


@dataclass(frozen=True)
class Figure:
    """One noise figure for each axis and for the sensor, with its confidence interval.

    Attributes
    ----------
    value, low, high : ndarray, shape (4,)
        Estimate and interval for x, y, z and the sensor; NaN where not seen.
    tau : ndarray, shape (4,)
        Averaging time it was read at [s] (the density: 1 s, on its fitted line).
    edf : ndarray, shape (4,)
        Equivalent degrees of freedom (the density: of its fit).
    tau_min, tau_max : ndarray, shape (4,)
        The density's fitted range [s]; NaN for the other figures and in older files.
    """

    value: np.ndarray
    low: np.ndarray
    high: np.ndarray
    tau: np.ndarray
    edf: np.ndarray
    tau_min: np.ndarray = field(default_factory=lambda: np.full(4, math.nan))
    tau_max: np.ndarray = field(default_factory=lambda: np.full(4, math.nan))

    def __post_init__(self):
        for name in ("value", "low", "high", "tau", "edf", "tau_min", "tau_max"):
            arr = np.array(getattr(self, name), dtype=float)
            if arr.shape != (4,):
                raise InputError(f"{name} must have shape (4,), got {arr.shape}")
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    @classmethod
    def missing(cls) -> "Figure":
        nan = np.full(4, math.nan)
        return cls(nan, nan, nan, nan, nan)

    def scaled(self, factor: float) -> "Figure":
        """The same figure in other units (value and interval times `factor`)."""
        return Figure(self.value * factor, self.low * factor, self.high * factor, self.tau, self.edf,
                      self.tau_min, self.tau_max)


def _line_point(local: np.ndarray, slope: float, side: np.ndarray) -> int | None:
    """The point on `side` whose local slope is closest to `slope` (within tolerance)."""
    if not side.any():
        return None
    cand = np.flatnonzero(side)
    idx = cand[np.argmin(np.abs(local[cand] - slope))]
    return int(idx) if abs(local[idx] - slope) <= _SLOPE_TOLERANCE else None


def _read_row(taus, adev, fs, n, pooled, level):
    """Density line, figures (value, low, high, tau, edf) x 2 and the random-walk bound of one curve."""
    local = np.gradient(np.log(adev), np.log(taus))
    i_min = int(np.argmin(adev))
    idx = np.arange(len(taus))
    turned = i_min < len(taus) - 2  # a minimum at the record's end is not a flat floor yet
    mult = 3.0 if pooled else 1.0  # the sensor row pools three independent axes

    def at(i, alpha, factor):
        dof = mult * edf(alpha, round(taus[i] * fs), n)
        low, high = confidence(adev[i], dof, level)
        return adev[i] * factor, low * factor, high * factor, taus[i], dof

    none = (math.nan,) * 5
    density = fit_white_line(taus, adev, fs, n, i_min=i_min, mult=mult, level=level)
    bias = at(i_min, -1, 1.0 / BI_FACTOR) if turned else none
    i = _line_point(local, 0.5, idx >= i_min) if turned else None
    walk = none if i is None else at(i, -2, math.sqrt(3.0 / taus[i]))
    bound = math.nan
    if i is None:
        highs = [confidence(adev[j], mult * edf(-2, round(taus[j] * fs), n), 0.95)[1] * math.sqrt(3.0 / taus[j])
                 for j in range(max(i_min - 1, 0), len(taus))]
        bound = min(highs)
    return density, bias, walk, bound


def read_figures(taus, adev, sample_rate: float, n: int, *, level: float):
    """Density, bias instability and random walk of each axis and of the sensor.

    Parameters
    ----------
    taus : ndarray, shape (m,)
        Averaging times [s].
    adev : ndarray, shape (3, m)
        Allan deviation of each axis [unit].
    sample_rate : float
        Sampling rate [Hz].
    n : int
        Samples the curves were computed from.
    level : float
        Confidence of the intervals (0.683 for 1 sigma).

    Returns
    -------
    curves : ndarray, shape (4, m)
        The three axes' Allan deviations and the sensor's (root of the mean Allan variance).
    density, bias_instability, random_walk : Figure
        In [unit/sqrt(Hz)], [unit], [unit/s/sqrt(Hz)] = [unit/sqrt(s)] per sqrt(s).
    random_walk_bound : ndarray, shape (4,)
        95 % upper bound on the random walk where it is not seen (NaN where it is).
    lines : list of WhiteLine or None
        The density fit of each row, with where the curve leaves it at short tau.
    """
    adev = np.asarray(adev, dtype=float)
    if not np.all(adev > 0):
        raise InputError("the Allan deviation is zero at some averaging time: the readings repeat exactly "
                         "(constant, or quantised far coarser than the noise); no noise figure can be read")
    curves = np.vstack([adev, np.sqrt(np.mean(adev**2, axis=0))])
    rows = [_read_row(taus, curves[r], sample_rate, n, r == 3, level) for r in range(4)]
    lines = [row[0] for row in rows]
    nan = math.nan
    dens = np.array([(nan,) * 7 if w is None else (w.value, w.low, w.high, 1.0, w.edf, w.tau_min, w.tau_max)
                     for w in lines])
    figures = [Figure(*dens.T)]
    for k in (1, 2):
        cols = np.array([row[k] for row in rows], dtype=float)  # (4, 5)
        figures.append(Figure(*cols.T))
    bound = np.array([row[3] for row in rows])
    return curves, figures[0], figures[1], figures[2], bound, lines
