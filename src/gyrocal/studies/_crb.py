"""The Cramér–Rao bound of the servo method's protocol, from the core's design module."""

from __future__ import annotations

import numpy as np

from ..models import ScaleBias


def crb_std(k, b, *, speed: float, noise_std: float, sample_rate: float) -> np.ndarray:
    """Cramér–Rao standard deviations (G, 6) of ``(k, b)`` for gyros (G, 3) on the paper's six turns.

    Parameters
    ----------
    k, b : array_like, shape (G, 3)
        True scale factors [-] and biases [rad/s].
    speed : float
        Servo speed [rad/s].
    noise_std : float
        Per-sample white noise [rad/s].
    sample_rate : float
        Sampling rate [Hz].
    """
    from ..planning.design import Design, predicted_std

    design = Design.paper_six(speed)
    k, b = np.atleast_2d(k), np.atleast_2d(b)
    # One small information matrix per distinct gyro (tens), not per calibration.
    return np.stack([np.asarray(predicted_std(design, ScaleBias(ki, bi), noise_std, sample_rate), dtype=float)
                     for ki, bi in zip(k, b)])
