"""Windows of a recording reduced to :class:`~gyrocal.observations.Observation` objects, with honest variances.

* Means are integrals on the sample times (trapezoid weights): the sensor's regular clock rebuilt
  from the stamps, gaps included, or the stamps themselves when no regular clock underlies them.
  Bursty receive-time stamps and dropped rows then give the right angle and plateau mean.
* With ``ripple=True`` a constant-speed plateau (speed reference) has the periodic speed ripple
  of a servo or robot joint regressed out with its level: the ripple lines are found once, on
  the longest plateau (all plateaus run at the declared speed), by
  :func:`gyrocal.longrun.find_lines`.
* With ``long_run=True`` the variance of each window mean holds for correlated noise and what
  is left of the ripple. The static windows pool one long-run (Newey-West) variance per axis
  (sensor noise at standstill is one process; a variance estimated window by window would
  scatter, and its inverse read the windows as disagreeing more than they do). A whole turn
  (angle reference) integrates the same sensor noise, so its mean takes that long-run variance
  too: a chip's internal low-pass filter makes successive samples alike, and the white noise of
  first differences then understates a turn's angle noise (twenty times at 1 kHz behind a 41 Hz
  filter). The plateaus' residuals hold the sensor noise and the servo's bounded angle error
  (vibration), which :func:`gyrocal.longrun.span_variance` separates.

The plateau and static statistics work on block means at about 200 Hz: the same level, the
same variance of the mean, a fifth of the work at 1 kHz.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .longrun import block_means, find_lines, fit_level, newey_west_var, span_variance
from .observations import Observation, observe
from .recording import Recording
from .windows import Window

__all__ = ["observe_windows"]

_STATS_RATE = 200.0  # [Hz] rate of the block means behind the plateau and static statistics


def _samples(rec: Recording, w: Window) -> np.ndarray:
    # Column-major windows make the per-axis reductions contiguous (about 4x faster than C order):
    # readers give column-major recordings; others are copied window by window, not whole.
    samples = rec.gyro[w.start:w.stop]
    return samples if rec.gyro.flags.f_contiguous else np.asfortranarray(samples)


def _observe(rec: Recording, w: Window, reference: str, speed, times, **stats) -> Observation:
    samples, t = _samples(rec, w), times[w.start:w.stop]
    if w.kind == "static":
        return observe(samples, rec.sample_rate, "static", t=t, **stats)
    if reference == "speed":
        return observe(samples, rec.sample_rate, "speed", speed=speed, t=t, **stats)
    return observe(samples, rec.sample_rate, "angle", angle=w.angle, t=t, mean_var=stats.get("mean_var"))


#: Block-mean samples enough for a pooled long-run variance (about 3 % precision); whole windows,
#: spread over the session, are taken up to this many.
_POOL_ROWS = 20_000


def _pooled_lrv(residuals: list[np.ndarray]) -> np.ndarray:
    """Long-run variance per block-mean sample (3,), pooled over windows' residuals (each mean zero)."""
    total = sum(len(r) for r in residuals)
    step = max(1, int(np.ceil(total / _POOL_ROWS)))
    chosen = np.concatenate(residuals[::step])
    return newey_west_var(chosen) * len(chosen)


def observe_windows(rec: Recording, windows: Sequence[Window], reference: str, speed: float | None, *,
                    long_run: bool = True, ripple: bool = True,
                    times: np.ndarray | None = None) -> tuple[Observation, ...]:
    """Reduce every window of `rec` for the `reference` (``"speed"`` or ``"angle"``).

    Parameters
    ----------
    rec : Recording
    windows : sequence of Window
    reference : {"speed", "angle"}
    speed : float or None
        Known speed [rad/s] (speed reference).
    long_run : bool
        Give plateaus and static windows their measured mean variances (see the module notes).
    ripple : bool
        Regress a periodic speed ripple out of the plateaus' levels (first-moment only: the paper's
        mean of squares needs the plain mean).
    times : ndarray, shape (N,), optional
        Sample times [s] to integrate on; default the recording's stamps. The pipeline passes the
        regular sensor clock rebuilt from them (:meth:`gyrocal.timebase.TimeBase.clock_times`).
    """
    times = rec.t if times is None else times
    stats: dict[int, dict] = {}
    if long_run or ripple:
        stats = _window_stats(rec, windows, reference, times, long_run=long_run, ripple=ripple)
    return tuple(_observe(rec, w, reference, speed, times, **stats.get(i, {})) for i, w in enumerate(windows))


def _window_stats(rec: Recording, windows: Sequence[Window], reference: str, times: np.ndarray, *,
                  long_run: bool, ripple: bool) -> dict[int, dict]:
    """``{window index: {"level": ..., "mean_var": ...}}`` for the plateaus and static windows."""
    d = max(1, int(round(rec.sample_rate / _STATS_RATE)))
    gyro = block_means(rec.gyro, d)  # one pass over the recording; windows take the blocks inside them
    clock = block_means(np.asarray(times, dtype=float), d)
    span = {i: (-(-w.start // d), w.stop // d) for i, w in enumerate(windows)}
    blocks = {i: gyro[a:b] for i, (a, b) in span.items() if b - a >= 4}
    plateaus = [i for i in blocks if windows[i].kind == "rotation" and reference == "speed"]
    turns = [i for i, w in enumerate(windows) if w.kind == "rotation" and reference == "angle"]
    statics = [i for i in blocks if windows[i].kind == "static"]
    lines: list[float] = []
    if ripple and plateaus:
        b = blocks[max(plateaus, key=lambda i: len(blocks[i]))]
        lines = find_lines(b[:, int(np.argmax(np.abs(b.mean(axis=0))))])
    out: dict[int, dict] = {}
    resid, factor = {}, {}
    for i in plateaus:
        t = clock[span[i][0]:span[i][1]]
        t = (t - t[0]) / ((t[-1] - t[0]) / (len(t) - 1))  # block centres on the sample clock, in block steps
        level, factor[i], resid[i] = fit_level(blocks[i], t, lines)
        if ripple:
            out[i] = {"level": level}
    if long_run and plateaus:
        a, b = span_variance([resid[i] for i in plateaus])
        for i in plateaus:
            out.setdefault(i, {})["mean_var"] = b * factor[i] + a * factor[i] ** 2
    if long_run and statics:
        lrv = _pooled_lrv([blocks[i] - blocks[i].mean(axis=0) for i in statics])
        for i in statics:
            out[i] = {"mean_var": lrv / len(blocks[i])}
        for i in turns:  # the turn's mean integrates the same sensor noise over its length
            out[i] = {"mean_var": lrv * d / len(windows[i])}
    return out
