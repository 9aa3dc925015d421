"""Temperature plateaus of a chamber log: contiguous runs of samples at one temperature.

A plateau is a run of samples with no break inside it (:attr:`gyrocal.recording.timebase.TimeBase.breaks`:
a jump in time or in the counter, as when the soak between plateaus was not recorded) whose
temperature stays within ``tol`` of the run's first readings. Runs shorter than ``min_duration``
(the ramp between set points) are dropped. Plateaus whose mean temperatures lie within ``tol``
of one another are one temperature point (the chamber came back to a set point it had held).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import median
from .._validation import finite_array, positive
from ..errors import InputError

__all__ = ["Plateau", "find_plateaus", "temperature_points"]

#: Samples whose median temperature starts a plateau (robust against one noisy reading).
_HEAD = 25


@dataclass(frozen=True)
class Plateau:
    """One contiguous run of samples at one temperature.

    Attributes
    ----------
    start, stop : int
        Sample indices, stop exclusive.
    temperature : float
        Mean temperature of the run [degC].
    temp_std : float
        Standard deviation of the temperature readings in the run [degC].
    """

    start: int
    stop: int
    temperature: float
    temp_std: float


def _runs(temp: np.ndarray, start: int, stop: int, tol: float) -> list[tuple[int, int]]:
    """Cut ``start:stop`` where the temperature leaves ``tol`` of each run's first readings."""
    runs, i = [], start
    while i < stop:
        ref = float(median(temp[i:min(i + _HEAD, stop)]))
        away = np.abs(temp[i:stop] - ref) > tol
        j = stop if not away.any() else i + max(int(np.argmax(away)), 1)
        runs.append((i, j))
        i = j
    return runs


def find_plateaus(t, temp, *, breaks=(), tol: float = 1.0, min_duration: float = 30.0) -> list[Plateau]:
    """The plateaus of a log, in time order.

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s].
    temp : array_like, shape (N,)
        Temperature readings [degC].
    breaks : sequence of int
        Samples that start a new contiguous part of the log; no plateau spans one.
    tol : float
        Largest departure from a plateau's first readings [degC].
    min_duration : float
        Shortest plateau kept [s].
    """
    t = finite_array("t", t, ndim=1)
    temp = finite_array("temp", temp, ndim=1)
    if len(t) != len(temp):
        raise InputError(f"t and temp need one value per sample, got {len(t)} and {len(temp)}")
    tol = positive("tol", tol)
    edges = [0, *sorted(int(b) for b in breaks if 0 < b < len(t)), len(t)]
    out = []
    for a, b in zip(edges[:-1], edges[1:]):
        for i, j in _runs(temp, a, b, tol):
            if j - i > 1 and t[j - 1] - t[i] >= min_duration:
                seg = temp[i:j]
                out.append(Plateau(i, j, float(seg.mean()), float(seg.std())))
    return out


def temperature_points(plateaus: list[Plateau], tol: float = 1.0) -> list[list[int]]:
    """Indices of the plateaus at each temperature point, points in increasing temperature.

    Plateaus are sorted by temperature and joined while each lies within `tol` [degC] of the
    previous one in the same point.
    """
    order = sorted(range(len(plateaus)), key=lambda k: plateaus[k].temperature)
    points: list[list[int]] = []
    for k in order:
        if points and plateaus[k].temperature - plateaus[points[-1][-1]].temperature <= tol:
            points[-1].append(k)
        else:
            points.append([k])
    return [sorted(p) for p in points]
