"""Windows of a recording reduced to :class:`~gyrocal.observations.Observation` objects, with honest variances.

* Means are integrals on the sample times (trapezoid weights): the sensor's regular clock rebuilt
  from the stamps, gaps included, or the stamps themselves when no regular clock underlies them.
  Bursty receive-time stamps and dropped rows then give the right angle and plateau mean.
* With ``ripple=True`` a constant-speed plateau (speed reference) has the periodic speed ripple
  of a servo or robot joint regressed out with its level: the ripple lines are found once, on
  the longest plateau (all plateaus run at the declared speed), by
  :func:`gyrocal.observations.longrun.find_lines`.
* With ``long_run=True`` the variance of each window mean holds for correlated noise and what
  is left of the ripple. The static windows pool one long-run (Newey-West) variance per axis
  (sensor noise at standstill is one process; a variance estimated window by window would
  scatter, and its inverse read the windows as disagreeing more than they do). A whole turn
  (angle reference) integrates the same sensor noise, so its mean takes that long-run variance
  too: a chip's internal low-pass filter makes successive samples alike, and the white noise of
  first differences then understates a turn's angle noise (twenty times at 1 kHz behind a 41 Hz
  filter). Without static windows the turns' non-rotating axes give that long-run variance
  (:func:`_turns_lrv`). The plateaus' residuals hold the sensor noise and the servo's bounded angle error
  (vibration), which :func:`gyrocal.observations.longrun.span_variance` separates.

The plateau and static statistics work on block means at about 200 Hz: the same level, the
same variance of the mean, a fifth of the work at 1 kHz.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from .._arrays import median
from ..recording import Recording
from ..segmentation.windows import Window
from . import Observation, observe_many
from .longrun import block_means, find_lines, fit_levels, newey_west_var, span_variance
from .partial_cycles import partial_cycles, weigh_readings

__all__ = ["observe_windows", "white_floor"]

_STATS_RATE = 200.0  # [Hz] rate of the block means behind the plateau and static statistics


#: Block-mean samples enough for a pooled long-run variance (about 3 % precision); whole windows,
#: spread over the session, are taken up to this many.
_POOL_ROWS = 20_000


def _pooled_lrv(residuals: list, sizes: list[int]) -> np.ndarray:
    """Long-run variance per block-mean sample (3,), pooled over windows' residuals (each mean zero).

    `residuals[i]` is a window's residuals (n_i, 3), or a function giving them, so that only the windows
    chosen (every `step`-th, up to :data:`_POOL_ROWS` rows) are computed; `sizes` are their lengths n_i.
    """
    step = max(1, int(np.ceil(sum(sizes) / _POOL_ROWS)))
    chosen = np.concatenate([r() if callable(r) else r for r in residuals[::step]])
    return newey_west_var(chosen) * len(chosen)


def observe_windows(rec: Recording, windows: Sequence[Window], reference: str, speed: float | None, *,
                    long_run: bool = True, ripple: bool = True,
                    times: np.ndarray | None = None, period: float | None = None) -> tuple[Observation, ...]:
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
        regular sensor clock rebuilt from them when it has gaps (:meth:`gyrocal.recording.timebase.TimeBase.clock_times`).
    period : float, optional
        The period [s] of a regular clock without gaps that the samples lie on (the pipeline knows it from
        the time base, :attr:`gyrocal.recording.timebase.TimeBase.clock_period`): the trapezoid weights on such a
        clock are even, so the windows are weighted evenly and last ``count x period``; `times` is unused.
    """
    times = None if period is not None else rec.t if times is None else times
    stats: dict[int, dict] = {}
    if long_run or ripple:
        stats = _window_stats(rec, windows, reference, times, long_run=long_run, ripple=ripple)
    kinds = ["static" if w.kind == "static" else reference for w in windows]
    return observe_many(rec.gyro, [w.start for w in windows], [w.stop for w in windows], rec.sample_rate, kinds,
                        speed=speed, angles=[w.angle if k == "angle" else None for w, k in zip(windows, kinds)],
                        t=times, period=period, levels=[stats.get(i, {}).get("level") for i in range(len(windows))],
                        mean_vars=[stats.get(i, {}).get("mean_var") for i in range(len(windows))])


def _window_stats(rec: Recording, windows: Sequence[Window], reference: str, times: np.ndarray | None, *,
                  long_run: bool, ripple: bool) -> dict[int, dict]:
    """``{window index: {"level": ..., "mean_var": ...}}`` for the plateaus and static windows (`times`
    None: on a regular clock)."""
    d = max(1, int(round(rec.sample_rate / _STATS_RATE)))
    gyro = block_means(rec.gyro, d)  # one pass over the recording; windows take the blocks inside them
    span = {i: (-(-w.start // d), w.stop // d) for i, w in enumerate(windows)}
    blocks = {i: gyro[a:b] for i, (a, b) in span.items() if b - a >= 4}
    plateaus = [i for i in blocks if windows[i].kind == "rotation" and reference == "speed"]
    turns = [i for i, w in enumerate(windows) if w.kind == "rotation" and reference == "angle"]
    statics = [i for i in blocks if windows[i].kind == "static"]
    out: dict[int, dict] = {}
    if plateaus:
        out = _plateau_stats(gyro, blocks, span, plateaus, times, d, long_run=long_run, ripple=ripple)
    lrv = None
    if long_run and statics:
        lrv = _pooled_lrv([lambda b=blocks[i]: b - b.mean(axis=0) for i in statics], [len(blocks[i]) for i in statics])
        for i in statics:
            out[i] = {"mean_var": lrv / len(blocks[i])}
    elif long_run and turns:  # no standstill: the turns' own quiet axes hold the same sensor noise
        lrv = _turns_lrv([blocks[i] for i in turns if i in blocks])
    if lrv is not None:
        for i in turns:  # the turn's mean integrates the same sensor noise over its length
            out[i] = {"mean_var": lrv * d / len(windows[i])}
    if plateaus and ripple:
        weigh_readings(out, {i: windows[i] for i in plateaus}, {i: blocks[i] for i in statics},
                       None if lrv is None or not statics else lrv)
    return out


#: An axis is quiet in a turn when its reading follows the turning axis's by at most this factor (a
#: misaligned mount, cross-axis sensitivity); a turn about a diagonal has no quiet axis.
_QUIET_SLOPE = 0.2


def _turns_lrv(turns: list[np.ndarray]) -> np.ndarray | None:
    """Long-run variance per block-mean sample (3,) from the turns' non-rotating axes, or None.

    In a turn about one sensor axis the other two read the bias, the turning rate through the mount's
    misalignment, and the sensor's noise: regressed on the turning axis's reading, what is left is the
    noise (a chip's filter and the bias's wander within the turn included). Each axis pools its residuals
    from the turns where it is quiet; an axis quiet in none borrows the mean of the others.
    """
    pooled: list[list[np.ndarray]] = [[], [], []]
    for g in turns:
        j = int(np.argmax(np.abs(g.mean(axis=0))))
        X = np.column_stack([np.ones(len(g)), g[:, j] - g[:, j].mean()])
        coef, *_ = np.linalg.lstsq(X, g, rcond=None)
        resid = g - X @ coef
        for a in range(3):
            if a != j and abs(coef[1, a]) <= _QUIET_SLOPE:
                pooled[a].append(resid[:, a])
    lrv = np.array([newey_west_var(np.concatenate(r)[:, None])[0] * sum(map(len, r)) if r else np.nan
                    for r in pooled])
    if np.isnan(lrv).all():
        return None
    return np.where(np.isnan(lrv), np.nanmean(lrv), lrv)


def _plateau_stats(gyro: np.ndarray, blocks: dict, span: dict, plateaus: list[int], times: np.ndarray | None, d: int,
                   *, long_run: bool, ripple: bool) -> dict[int, dict]:
    """Levels (ripple regressed out) and mean variances of the plateaus, block means of `d` samples (`gyro`)."""
    lines: list[float] = []
    if ripple:
        b = blocks[max(plateaus, key=lambda i: len(blocks[i]))]
        lines = find_lines(b[:, int(np.argmax(np.abs(b.mean(axis=0))))])
    if times is None:  # a regular clock: the block centres are whole block steps apart
        ts = [np.arange(len(blocks[i]), dtype=float) for i in plateaus]
    else:
        clock = block_means(np.asarray(times, dtype=float), d)
        ts = []
        for i in plateaus:
            t = clock[span[i][0]:span[i][1]]
            # block centres on the sample clock, in block steps: the median step, which a gap inside the plateau
            # does not stretch (its own mean step would, and put the ripple's phase off)
            ts.append((t - t[0]) / float(median(np.diff(t))))
    fits = dict(zip(plateaus, fit_levels([blocks[i] for i in plateaus], ts, lines)))
    out: dict[int, dict] = {i: {"level": fits[i][0]} for i in plateaus} if ripple else {}
    if ripple:  # the two readings of a declared speed; weighed once the static windows are known
        for i, t in zip(plateaus, ts):
            out[i]["cycles"] = partial_cycles(gyro, span[i], blocks[i], t, lines, fits[i][0])
    if long_run:
        a, b = span_variance([fits[i][2] for i in plateaus])
        for i in plateaus:
            out.setdefault(i, {})["mean_var"] = b * fits[i][1] + a * fits[i][1] ** 2
    return out



def white_floor(observations, noise_std) -> tuple:
    """`observations` whose measured mean variances are at least the given white noise's, ``noise_std^2 / n``."""
    var = np.broadcast_to(np.square(np.asarray(noise_std, dtype=float)), (3,))
    return tuple(o if o.mean_var is None else dataclasses.replace(o, mean_var=np.maximum(o.mean_var, var / o.count))
                 for o in observations)
