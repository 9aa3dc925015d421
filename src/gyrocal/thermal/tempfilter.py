"""Smoothing of per-sample temperature readings before the table is evaluated.

Temperature sensors on MEMS parts often report whole degrees, or jitter by a few
tenths. Evaluating the table at such readings makes the corrected output jump at
every change of the reading. The die temperature itself changes slowly (thermal
time constants of tens of seconds to minutes), so gyrocal low-passes the readings
in time first: a first-order exponential filter run forward and then backward,
which has zero phase (no lag) and an effective time constant ``tau`` per pass.
A 1 degC step in the reading becomes a ramp spread over several ``tau``.
"""

from __future__ import annotations

import numpy as np

from .._validation import finite_array
from ..errors import InputError

__all__ = ["DEFAULT_TEMP_TAU", "smooth_temperature"]

#: Default time constant [s]: long against quantisation flicker, short against a soak chamber's drift.
DEFAULT_TEMP_TAU = 20.0


def smooth_temperature(temp, sample_rate: float, tau: float = DEFAULT_TEMP_TAU) -> np.ndarray:
    """Zero-phase first-order low-pass of temperature readings.

    Parameters
    ----------
    temp : array_like, shape (N,)
        Readings [degC].
    sample_rate : float
        Sampling rate [Hz].
    tau : float
        Time constant of each pass [s]; 0 returns the readings unchanged.

    Returns
    -------
    ndarray, shape (N,)
        Smoothed temperature [degC]. Each pass starts from the end value, so a
        constant signal passes unchanged and the ends are not pulled towards zero.
    """
    x = finite_array("temp", temp, ndim=1)
    if not (np.isfinite(tau) and tau >= 0):
        raise InputError(f"temp_tau must be >= 0 s, got {tau!r}", param="temp_tau", value=tau)
    if tau == 0 or len(x) < 2:
        return x.copy()
    a = float(np.exp(-1.0 / (float(sample_rate) * tau)))
    forward = _first_order(x, a, x[0])
    return _first_order(forward[::-1], a, forward[-1])[::-1]


def _first_order(x: np.ndarray, a: float, before: float) -> np.ndarray:
    """``y[n] = a y[n-1] + (1 - a) x[n]`` with ``y[-1] = before``, exactly, in blocks of numpy operations.

    Inside a block of B samples, ``y[i] = a^(i+1) y[-1] + (1 - a) a^i sum_{k<=i} a^-k x[k]``; B keeps
    ``a^-B <= 2^10``, so the sum loses at most ten bits to the growth of its terms (scipy's ``lfilter``
    gives the same to 1e-12 relative, at two seconds of import).
    """
    rate = -np.log(a)
    size = int(min(len(x), max(1, 10 * np.log(2) / rate)))
    k = np.arange(size)
    grow, decay = np.exp(k * rate), np.exp(-k * rate)
    y = np.empty_like(x)
    state = before
    for start in range(0, len(x), size):
        seg = x[start:start + size]
        m = len(seg)
        y[start:start + m] = decay[:m] * (a * state + (1 - a) * np.cumsum(seg * grow[:m]))
        state = y[start + m - 1]
    return y
