"""A window of a recording reduced to an :class:`~gyrocal.observations.Observation`, with an honest variance.

* Means are integrals on the sample times (trapezoid weights): the sensor's regular clock rebuilt
  from the stamps, gaps included, or the stamps themselves when no regular clock underlies them.
  Bursty receive-time stamps and dropped rows then give the right angle and plateau mean.
* With ``long_run=True`` the variance of each window mean is measured on the window itself:
  a constant-speed plateau has its periodic speed ripple regressed out with its level, and
  the residuals' long-run variance (Newey-West) covers correlated noise
  (:func:`gyrocal.longrun.plateau_mean`); a static window gets the long-run variance of its
  samples. A whole turn (angle reference) keeps white noise pooled by the estimator, since its
  integral is exact whatever the speed did.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from .longrun import newey_west_var, plateau_mean
from .observations import Observation, observe
from .recording import Recording
from .windows import Window

__all__ = ["observe_window", "pool_static_variance"]


def observe_window(rec: Recording, w: Window, reference: str, speed: float | None, *,
                   long_run: bool = True, ripple: bool = True, times: np.ndarray | None = None) -> Observation:
    """Reduce window `w` of `rec` for the `reference` (``"speed"`` or ``"angle"``).

    Parameters
    ----------
    rec : Recording
    w : Window
    reference : {"speed", "angle"}
    speed : float or None
        Known speed [rad/s] (speed reference).
    long_run : bool
        Measure each plateau's and static window's own mean variance (see the module notes).
    ripple : bool
        Regress a periodic speed ripple out of a plateau's level (first-moment only: the paper's
        mean of squares needs the plain mean).
    times : ndarray, shape (N,), optional
        Sample times [s] to integrate on; default the recording's stamps. The pipeline passes the
        regular sensor clock rebuilt from them (:meth:`gyrocal.timebase.TimeBase.clock_times`).
    """
    # Column-major windows make the per-axis reductions contiguous (about 4x faster than C order):
    # readers give column-major recordings; others are copied window by window, not whole.
    samples = rec.gyro[w.start:w.stop]
    if not rec.gyro.flags.f_contiguous:
        samples = np.asfortranarray(samples)
    fs, t = rec.sample_rate, (rec.t if times is None else times)[w.start:w.stop]
    if w.kind == "static":
        obs = observe(samples, fs, "static", t=t)
        return dataclasses.replace(obs, mean_var=newey_west_var(samples)) if long_run else obs
    if reference != "speed":
        return observe(samples, fs, "angle", angle=w.angle, t=t)
    obs = observe(samples, fs, "speed", speed=speed, t=t)
    if not (long_run or ripple):
        return obs
    level, var = plateau_mean(samples, t)
    return dataclasses.replace(obs, mean=level if ripple else obs.mean, mean_var=var if long_run else None)


def pool_static_variance(observations: Sequence[Observation]) -> tuple[Observation, ...]:
    """Static windows' mean variances from one long-run variance per axis, pooled by sample count."""
    statics = [o for o in observations if o.kind == "static" and o.mean_var is not None]
    if len(statics) < 2:
        return tuple(observations)
    n = np.array([o.count for o in statics], dtype=float)
    per_sample = np.sum([o.mean_var * o.count**2 for o in statics], axis=0) / n.sum()
    return tuple(dataclasses.replace(o, mean_var=per_sample / o.count) if o.kind == "static" and o.mean_var is not None
                 else o for o in observations)
