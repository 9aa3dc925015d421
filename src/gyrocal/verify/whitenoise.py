"""White-noise level of a moving gyro, from the scatter of its second differences.

Each sample is compared with the straight line through its two neighbours. Smooth motion
cancels in that difference and white noise of standard deviation ``s`` leaves
``s * sqrt(1 + l**2 + (1 - l)**2)`` (``l`` the neighbours' interpolation weight,
1/2 on an even grid), so the noise can be measured while the sensor turns. The robust
scale (median absolute deviation) ignores the samples where the motion bends sharply
(the start and end of a turn) as long as they are fewer than half. The plain RMS of the
same differences also holds that motion, and vibration faster than the rate resolves: the
part of the motion a linear interpolation between the samples cannot follow.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import median
from ..units import MAD_TO_SIGMA

__all__ = ["NoiseEstimate", "second_difference_noise"]

# n var(s_hat) / s^2 of the MAD scale of second differences on an even grid: 1.977. Neighbouring
# differences share samples (correlations -2/3 and 1/6); the figure is the asymptotic variance of
# a median, sum over lags of cov(1{|d_0| < q}, 1{|d_k| < q}) / (q * density of |d| at q)^2, with
# the bivariate normal probabilities at those correlations (1.36 for independent values).
_MAD_VARIANCE = 1.977


@dataclass(frozen=True)
class NoiseEstimate:
    """Per-axis noise figures of one log [unit of its rates].

    Attributes
    ----------
    std : ndarray, shape (3,)
        White-noise standard deviation per sample (robust).
    std_err : ndarray, shape (3,)
        Its 1-sigma, for white Gaussian noise.
    rms : ndarray, shape (3,)
        The same scale from the plain RMS: noise plus motion that linear interpolation
        between samples cannot follow.
    """

    std: np.ndarray
    std_err: np.ndarray
    rms: np.ndarray


def second_difference_noise(t: np.ndarray, w: np.ndarray) -> NoiseEstimate:
    """Noise of a log from its second differences.

    Parameters
    ----------
    t : ndarray, shape (N,)
        Sample times [s], increasing, N >= 3.
    w : ndarray, shape (N, 3)
        Rates [any unit].
    """
    h1, h2 = t[1:-1] - t[:-2], t[2:] - t[1:-1]
    lam = (h2 / (h1 + h2))[:, None]  # weight of the previous sample in the straight line
    d = (w[1:-1] - lam * w[:-2] - (1.0 - lam) * w[2:]) / np.sqrt(1.0 + lam**2 + (1.0 - lam) ** 2)
    std = MAD_TO_SIGMA * median(np.abs(d - median(d, axis=0)), axis=0)
    return NoiseEstimate(std=std, std_err=std * np.sqrt(_MAD_VARIANCE / len(d)), rms=np.sqrt(np.mean(d * d, axis=0)))
