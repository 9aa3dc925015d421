"""Stillness thresholds for poses held by hand: a sweep of multipliers, as imu_tk does.

The detector's thresholds are measured where the board rests best (a table, most often): a
hand's tremor (1-2 deg/s at 8-12 Hz) is far above them, so poses held by hand are not found.
Following imu_tk (Tedaldi et al., ICRA 2014), the thresholds are multiplied by each of
:data:`MULTIPLIERS` in turn and the accelerometer is fitted to the poses each finds:

* a multiplier that finds fewer than :data:`MIN_POSES` poses is not enough;
* of those that are, the residuals in noise units (Birge ratio) show which let motion into a
  pose: those more than :data:`WORSE` times the best (and above :data:`FLOOR`) are refused;
* of the rest, the one that finds the most poses is kept, the smallest on a tie (so a session on
  a table keeps the thresholds measured at rest).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..errors import GyrocalError
from .accel import fit_accelerometer
from .statics import StaticDetection, detect_statics

__all__ = ["FLOOR", "MIN_POSES", "MULTIPLIERS", "WORSE", "sweep_statics"]

#: Factors tried on the threshold variances (hand tremor reaches hundreds of times a table's noise variance).
MULTIPLIERS = (1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1000.0)
#: Poses a multiplier must find to be enough (imu_tk asks for more; 9 fit every accelerometer model).
MIN_POSES = 9
#: A residual this many times the best one means motion leaked into the poses ...
WORSE = 2.0
#: ... unless it stays below this many noise units.
FLOOR = 2.0


def _residual(det: StaticDetection, gravity: float, model) -> float:
    """The accelerometer fit's Birge ratio over the poses found (NaN where it cannot be fitted)."""
    if len(det.statics) < 4:
        return math.nan
    means = np.array([s.accel_mean for s in det.statics])
    se = np.array([s.accel_se for s in det.statics])
    try:
        return float(fit_accelerometer(means, se, gravity=gravity, model=model).fit.birge_ratio)
    except GyrocalError:
        return math.nan


def pick(tried) -> int:
    """Index into `tried` ``[(multiplier, poses, residual), ...]`` of the one kept (see the module)."""
    enough = [i for i, (_, n, r) in enumerate(tried) if n >= MIN_POSES and math.isfinite(r)]
    if not enough:
        return max(range(len(tried)), key=lambda i: (tried[i][1], -i))
    best = min(tried[i][2] for i in enough)
    fair = [i for i in enough if tried[i][2] <= max(WORSE * best, FLOOR)]
    return max(fair, key=lambda i: (tried[i][1], -i))


def sweep_statics(t, gyro, accel, *, min_duration: float, breaks=(), gravity: float, accel_model="auto",
                  multiplier: float | None = None) -> StaticDetection:
    """Still poses with the thresholds' multiplier chosen by the accelerometer fit (or the one given).

    Returns the :class:`~gyrocal.imu.statics.StaticDetection` kept, its ``sweep`` holding every
    ``(multiplier, poses, residual)`` tried.
    """
    if multiplier is not None:
        det = detect_statics(t, gyro, accel, min_duration=min_duration, breaks=breaks, multiplier=multiplier)
        return dataclasses.replace(det, sweep=((det.multiplier, len(det.statics),
                                                _residual(det, gravity, accel_model)),))
    found = [detect_statics(t, gyro, accel, min_duration=min_duration, breaks=breaks, multiplier=m)
             for m in MULTIPLIERS]
    tried = tuple((m, len(d.statics), _residual(d, gravity, accel_model)) for m, d in zip(MULTIPLIERS, found))
    return dataclasses.replace(found[pick(tried)], sweep=tried)
