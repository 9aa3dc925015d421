"""Arbitrary rate profiles turned into recordings of a virtual gyro.

A profile is either a callable ``rates(t) -> (N, 3)`` [rad/s] of time [s], or
tabulated samples ``(t, w)``, linearly interpolated onto the gyro's sample times
(for example read from a CSV of ``t, wx, wy, wz`` with :func:`gyrocal.io.read_profile`).
"""

from __future__ import annotations

from typing import Callable, Union

import numpy as np

from .._validation import finite_array, positive
from ..errors import InputError
from ..recording import Recording
from .gyro import VirtualGyro

__all__ = ["RateProfile", "profile_rates", "simulate_profile"]

RateProfile = Union[Callable[[np.ndarray], np.ndarray], tuple[np.ndarray, np.ndarray]]


def profile_rates(profile: RateProfile, t: np.ndarray) -> np.ndarray:
    """True body rates (N, 3) [rad/s] of `profile` at times `t` (N,) [s]."""
    if callable(profile):
        w = finite_array("profile(t)", profile(t), shape_tail=(3,), ndim=2)
        if len(w) != len(t):
            raise InputError(f"profile(t) returned {len(w)} rows for {len(t)} times")
        return w
    try:
        tp, wp = profile
    except (TypeError, ValueError):
        raise InputError("profile must be a callable rates(t) or a pair (t, w) of arrays") from None
    tp = finite_array("profile t", tp, ndim=1)
    wp = finite_array("profile w", wp, shape_tail=(3,), ndim=2)
    if len(tp) != len(wp) or len(tp) < 2 or np.any(np.diff(tp) <= 0):
        raise InputError(f"profile needs >= 2 strictly increasing times with one rate row each, "
                         f"got {len(tp)} times and {len(wp)} rows")
    if t[0] < tp[0] or t[-1] > tp[-1]:
        raise InputError(f"profile covers t = {tp[0]:g}..{tp[-1]:g} s but {t[0]:g}..{t[-1]:g} s was asked")
    return np.stack([np.interp(t, tp, wp[:, j]) for j in range(3)], axis=1)


def simulate_profile(
    gyro: VirtualGyro,
    profile: RateProfile,
    *,
    duration: float,
    sample_rate: float = 200.0,
    rng: np.random.Generator,
    temp: Callable[[np.ndarray], np.ndarray] | float | None = None,
) -> tuple[Recording, np.ndarray]:
    """Record `gyro` following `profile` for `duration` seconds.

    Parameters
    ----------
    gyro : VirtualGyro
        The sensor.
    profile : callable or (t, w)
        True body rates [rad/s] as a function of time [s], or tabulated.
    duration : float
        Length of the recording [s].
    sample_rate : float
        Sampling rate [Hz].
    rng : numpy.random.Generator
    temp : callable or float, optional
        Sensor temperature [degC], constant or ``temp(t)``; needed by thermal gyros.

    Returns
    -------
    recording : Recording
        Readings [rad/s] with time [s] (and temperature when given).
    rates : ndarray, shape (N, 3)
        The true rates [rad/s].
    """
    fs = positive("sample_rate", sample_rate)
    n = int(round(positive("duration", duration) * fs))
    if n < 2:
        raise InputError(f"duration={duration} s at {fs} Hz gives {n} sample(s); need at least 2")
    t = np.arange(n) / fs
    w = profile_rates(profile, t)
    temps = None if temp is None else np.broadcast_to(temp(t) if callable(temp) else float(temp), (n,)).astype(float)
    m = gyro.measure(w, fs, rng, temp=temps)
    return Recording(t=t, gyro=m, sample_rate=fs, temp=temps), w
