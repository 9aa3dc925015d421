"""Per-sample simulation of the servo method's six-observation protocol, reduced to windows.

This is the reference generator: it draws every sample, then reduces each window
exactly as :func:`gyrocal.observe` would. It follows the servo method of Wang et al., section III-A:

* readings ``m = g / k - b + noise`` (eq. 1 solved for ``m``), white Gaussian noise;
* one full revolution per axis and sense (Fig. 1) at ``speed``, ``n = round(2 pi / speed * fs)``
  samples;
* speed jitter ``speed * (1 + jitter * N(0, 1))`` per sample, re-centred so that the
  window mean equals ``speed`` exactly. The servo turns exactly 360 deg per window, so
  only the time-profile of the rate varies (the paper's "vibration"), not the angle;
* mounting misalignment: the rotation axis is the nominal axis tilted by an angle
  ``U(0, misalignment)`` [rad] towards a uniformly random direction perpendicular to it.
  The paper's "U(0 %, 10 %)" is read as the size of the tilt, ``0.10 rad`` ~ 5.7 deg;
  the tilt is drawn independently for every window.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .._validation import finite_array, positive
from .._white import difference_variance
from ..errors import InputError
from ..observations import ObservationSet
from ..segmentation.windows import axis_vector

__all__ = ["PAPER_AXES", "axis_vector", "paper_observations"]

#: The paper's Fig. 1 order: +-x, +-y, +-z.
PAPER_AXES: tuple[str, ...] = ("+x", "-x", "+y", "-y", "+z", "-z")
_CHUNK_SAMPLES = 2_000_000  # samples x batch items drawn at once (~50 MB of float64 per array)


def _tilted_axes(e: np.ndarray, misalignment: float, size: int, rng: np.random.Generator) -> np.ndarray:
    """(size, 3) unit vectors tilted from `e` by U(0, misalignment) rad in a random direction."""
    helper = np.roll(np.abs(e), 1)  # any vector not parallel to e
    p1 = np.cross(e, helper)
    p1 /= np.linalg.norm(p1)
    p2 = np.cross(e, p1)
    tilt = rng.uniform(0.0, misalignment, size)[:, None]
    phi = rng.uniform(0.0, 2 * np.pi, size)[:, None]
    return np.cos(tilt) * e + np.sin(tilt) * (np.cos(phi) * p1 + np.sin(phi) * p2)


def check_protocol_args(k, b, speed, sample_rate, noise_std, jitter, misalignment, static_duration):
    """Validate the protocol arguments shared by the per-sample and fast generators.

    Returns ``k, b`` as (B, 3) arrays, ``speed`` [rad/s], ``sample_rate`` [Hz] and
    ``noise_std`` as (3,) [rad/s].
    """
    k = np.atleast_2d(finite_array("k", k, shape_tail=(3,)))
    b = np.atleast_2d(finite_array("b", b, shape_tail=(3,)))
    if k.ndim != 2 or k.shape != b.shape:
        raise InputError(f"k and b must both have shape (B, 3), got {k.shape} and {b.shape}")
    if np.any(k <= 0):
        raise InputError("k must be > 0 for every gyro and axis")
    speed = positive("speed", speed)
    fs = positive("sample_rate", sample_rate)
    sd = np.broadcast_to(finite_array("noise_std", noise_std), (3,))
    if np.any(sd < 0) or not (jitter >= 0 and misalignment >= 0 and static_duration >= 0):
        raise InputError("noise_std, jitter, misalignment and static_duration must be >= 0")
    return k, b, speed, fs, sd


def _reduce(m: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Window mean, mean of squares and first-difference noise variance of (B, n, 3) readings."""
    d = np.diff(m, axis=1)
    return m.mean(axis=1), np.einsum("bni,bni->bi", m, m) / m.shape[1], difference_variance(d, axis=1)


def paper_observations(
    k,
    b,
    *,
    speed: float,
    sample_rate: float = 200.0,
    noise_std=0.035,
    jitter: float = 0.05,
    misalignment: float = 0.10,
    static_duration: float = 0.0,
    axes: Sequence[str] = PAPER_AXES,
    rng: np.random.Generator,
) -> ObservationSet:
    """Simulate the servo protocol sample by sample for a batch of gyros.

    Parameters
    ----------
    k, b : array_like, shape (B, 3) or (3,)
        True scale factors [-] and biases [rad/s] (the servo method of Wang et al., eq. 1).
    speed : float
        Servo speed [rad/s] (the paper: 60 deg/s = pi/3).
    sample_rate : float
        Sampling rate [Hz].
    noise_std : float or array_like of shape (3,)
        Per-sample white-noise standard deviation of the readings [rad/s].
    jitter : float
        Relative standard deviation of the per-sample true speed [-] (paper: 0.05).
    misalignment : float
        Largest tilt of a rotation axis from its nominal direction [rad] (paper: 0.10).
    static_duration : float
        Length of a static window recorded after each turn [s]; 0 for none.
    axes : sequence of str
        Signed nominal rotation axes, one revolution each (default: the paper's six).
    rng : numpy.random.Generator
        Source of randomness.

    Returns
    -------
    ObservationSet
        Batched (B, n_windows, 3); rotation windows carry ``rate = speed``, each followed
        by its static window when ``static_duration > 0``.
    """
    k, b, speed, fs, sd = check_protocol_args(k, b, speed, sample_rate, noise_std, jitter, misalignment, static_duration)
    e_axes = [axis_vector(a) for a in axes]
    n_rot = round(2 * np.pi / speed * fs)
    n_sta = round(static_duration * fs)
    if n_rot < 2 or (static_duration > 0 and n_sta < 2):
        raise InputError(f"windows need at least 2 samples; speed={speed} rad/s and sample_rate={fs} Hz give {n_rot}")

    B = len(k)
    stats: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    count, static = [], []
    for e in e_axes:
        stats.append(_simulate(k, b, n_rot, speed, e, sd, jitter, misalignment, rng))
        count.append(n_rot)
        static.append(False)
        if n_sta:
            stats.append(_simulate(k, b, n_sta, 0.0, e, sd, 0.0, 0.0, rng))
            count.append(n_sta)
            static.append(True)
    mean, mean_sq, noise_var = (np.stack(s, axis=1) for s in zip(*stats))
    count_arr = np.array(count, dtype=float)
    static_arr = np.array(static)
    rate = np.where(static_arr, 0.0, speed)
    return ObservationSet(mean, mean_sq, noise_var, np.broadcast_to(rate, (B, len(count))), count_arr,
                          count_arr / fs, static_arr)


def _simulate(k, b, n, speed, e, sd, jitter, misalignment, rng):
    """Reductions (mean, mean_sq, noise_var), each (B, 3), of one window, drawn in batch chunks."""
    B = len(k)
    chunk = max(1, _CHUNK_SAMPLES // n)
    out = [np.empty((B, 3)) for _ in range(3)]
    for s in range(0, B, chunk):
        sl = slice(s, min(B, s + chunk))
        size = sl.stop - sl.start
        if speed > 0:
            rate = speed * (1.0 + jitter * rng.standard_normal((size, n)))
            rate += speed - rate.mean(axis=1, keepdims=True)  # exactly one revolution per window
            axis = _tilted_axes(e, misalignment, size, rng)
            g = rate[:, :, None] * axis[:, None, :]
        else:
            g = np.zeros((size, n, 3))
        m = g / k[sl, None, :] - b[sl, None, :] + rng.standard_normal((size, n, 3)) * sd
        for dst, src in zip(out, _reduce(m)):
            dst[sl] = src
    return tuple(out)
