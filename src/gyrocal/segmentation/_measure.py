"""What a window holds, measured on the data: its standstill level, a turn's angle and mean rate.

Used to show people what was there (``gyrocal segments``, reasons for ignoring a turn), never
the declared angle or speed: the raw integral carries the gyro's unknown scale, so it is what
the gyro read, which is what a person needs to compare with what the robot or hand did.
"""

from __future__ import annotations

import numpy as np

from ..recording import Recording
from ._motion import static_level
from .windows import Window

__all__ = ["measure_turn", "standstill_level"]


def standstill_level(rec: Recording, windows=()) -> np.ndarray:
    """Reading at standstill (3,) [reading units]: the mean of the static `windows`, else the data's quiet level."""
    statics = [w for w in windows if w.kind == "static"]
    if statics:
        return np.mean(np.concatenate([rec.gyro[w.start:w.stop] for w in statics]), axis=0)
    return static_level(rec.gyro, max(8, int(round(0.25 * rec.sample_rate))))[0]


def measure_turn(rec: Recording, w: Window, baseline: np.ndarray, times: np.ndarray | None = None) -> tuple[float, float]:
    """Angle turned in window `w` [reading units x s: rad for rad/s data] and its mean rate [reading units].

    The readings less the standstill `baseline` are integrated on the sample `times` (default the
    stamps; trapezoid), and the angle is the norm of that vector: a tilted turn axis turns the
    same angle.
    """
    t = (rec.t if times is None else times)[w.start:w.stop]
    d = rec.gyro[w.start:w.stop] - baseline
    if len(t) < 2:
        return 0.0, 0.0
    dt = np.diff(t)[:, None]
    angle = float(np.linalg.norm(np.sum((d[1:] + d[:-1]) / 2 * dt, axis=0)))
    return angle, angle / float(t[-1] - t[0])
