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
    from scipy.signal import lfilter

    x = finite_array("temp", temp, ndim=1)
    if not (np.isfinite(tau) and tau >= 0):
        raise InputError(f"temp_tau must be >= 0 s, got {tau!r}")
    if tau == 0 or len(x) < 2:
        return x.copy()
    a = float(np.exp(-1.0 / (float(sample_rate) * tau)))
    b, den = [1.0 - a], [1.0, -a]
    y, _ = lfilter(b, den, x, zi=[a * x[0]])
    y, _ = lfilter(b, den, y[::-1], zi=[a * y[-1]])
    return y[::-1]
