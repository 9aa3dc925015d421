"""A turn's angle from attitude kinematics, for turns whose axis wanders (hand tilts).

A declared angle is a rotation: the attitude at the end of the turn relative to its start. The
first-moment equations compare it with the *integral* of the rate vector, which is the same
thing only when the axis stays put (a robot joint, a turntable). A hand that tilts a board by
45 deg while its axis wobbles a few degrees makes an integral shorter than the rotation (the
wobble's coning): 3 deg of wobble read k 5e-4 high, several of its 1-sigma.

:func:`wander_ratios` integrates each turn's calibrated rate with quaternion kinematics on the
sample times (:mod:`gyrocal.quaternion`) and returns ``|integral of omega| / rotation angle``:
exactly 1 for a fixed axis, below 1 for a wandering one. The declared angle times this ratio is
what the integral should read. A rotation of nearly a whole revolution or more is no attitude
change one can tell from the noise (360 deg ends where it began), and such turns come from a
turntable or a robot joint, whose axis does not wander: turns over 300 deg keep ratio 1.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from .. import quaternion as quat
from ..segmentation.windows import Window
from . import Observation, ObservationSet
from .longrun import block_means

__all__ = ["follow_wander", "wander_ratios"]

_RATE = 200.0  # [Hz] block means behind the integration: hand wobbles are far slower
_LARGEST = math.radians(300.0)  # turns beyond this keep ratio 1 (see the module notes)


def _rotation_angle(m: np.ndarray, u: np.ndarray) -> float:
    """Angle [rad, 0 to 2 pi] of rotation matrix `m`, in the sense of unit axis `u` (the turn's)."""
    q = quat.from_matrix(m)  # w >= 0: the angle comes out in [0, pi] about +-axis
    a = 2.0 * math.atan2(float(np.linalg.norm(q[1:])), float(q[0]))
    return a if float(q[1:] @ u) >= 0 else 2 * math.pi - a


def wander_ratios(gyro: np.ndarray, t: np.ndarray, windows: Sequence[Window], k: np.ndarray, b: np.ndarray,
                  sample_rate: float) -> np.ndarray:
    """``|integral of omega dt| / rotation angle`` of each rotation window (1 for other windows).

    Parameters
    ----------
    gyro : ndarray, shape (N, 3)
        Raw readings [internal units].
    t : ndarray, shape (N,)
        Sample times [s] (the sensor clock the means were integrated on).
    windows : sequence of Window
    k, b : ndarray, shape (3,)
        The current scale factors and biases (``omega = diag(k) (m + b)`` [rad/s]).
    sample_rate : float
        Nominal rate [Hz].
    """
    d = max(1, int(round(sample_rate / _RATE)))
    out = np.ones(len(windows))
    for i, w in enumerate(windows):
        if w.kind != "rotation" or w.stop - w.start < 4 * d or abs(w.angle) > _LARGEST:  # declared over 300 deg
            continue
        omega = k * (block_means(np.asarray(gyro[w.start:w.stop], dtype=float), d) + b)
        tt = block_means(np.asarray(t[w.start:w.stop], dtype=float), d)
        h = np.diff(tt)[:, None]
        linear = np.sum(h * 0.5 * (omega[1:] + omega[:-1]), axis=0)
        size = float(np.linalg.norm(linear))
        if not 0 < size <= _LARGEST:
            continue
        angle = _rotation_angle(quat.attitude_matrices(tt, omega, np.array([[0, len(tt) - 1]]))[0], linear / size)
        if angle > 0:
            out[i] = size / angle
    return out


def follow_wander(rec, t: np.ndarray, windows: Sequence[Window], observations: Sequence[Observation],
                  obs: ObservationSet, fit, estimator):
    """Whole turns' reference rates times their :func:`wander_ratios` at `fit`, and the refit.

    Returns ``(observations, obs, fit)``: the inputs themselves when every turn kept its axis.
    """
    ratio = wander_ratios(rec.gyro, t, windows, fit.model.k, fit.model.b, rec.sample_rate)
    if not np.any(np.abs(ratio - 1) > 1e-9):
        return tuple(observations), obs, fit
    observations = tuple(dataclasses.replace(o, rate=o.rate * c) for o, c in zip(observations, ratio))
    obs = ObservationSet.from_observations(observations)
    return observations, obs, estimator.fit(obs)
