"""A temperature sensor that lags the die: a first-order lag on a chamber log's temperature column.

The die follows the chamber: it is at a point's temperature from the moment the chamber leaves the
point before (the start of the unrecorded soak) to the end of that point's poses. A sensor with time
constant ``tau`` reads ``y' = (T_die - y) / tau``; with the die piecewise constant this is exact:
``y(t) = T_k + (y(t_k) - T_k) exp(-(t - t_k) / tau)`` from the step ``t_k`` (the last sample of the
point before). The first point starts settled. The column's reading noise is kept.
"""

from __future__ import annotations

import numpy as np

from .._validation import positive

__all__ = ["lagged_temperature"]


def lagged_temperature(t, temp, points, tau: float) -> np.ndarray:
    """The temperature column `temp` (N,) of a chamber log at times `t` (N,) [s] as a sensor lagging the die by
    `tau` [s] reads it; `points` as :func:`~gyrocal.simulation.chamber.chamber_session` returns them
    (``temperature_degC``, ``samples``), in time order."""
    tau = positive("tau", tau)
    t = np.asarray(t, dtype=float)
    out = np.array(temp, dtype=float, copy=True)
    level, t_step = None, None
    for p in points:
        a, b = p["samples"]
        die = float(p["temperature_degC"])
        if level is None:
            reading = np.full(b - a, die)
        else:
            reading = die + (level - die) * np.exp(-(t[a:b] - t_step) / tau)
        out[a:b] += reading - die
        level = die + (0.0 if t_step is None else (level - die) * np.exp(-(t[b - 1] - t_step) / tau))
        t_step = t[b - 1]
    return out
