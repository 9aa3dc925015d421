"""Turntable sessions: constant-rate steps and temperature points.

A step is a run of samples with one commanded table rate, one body axis along the
table, and no time gap. Its first ``settle`` seconds (the table's and the sensor's
transient) are dropped and the rest is reduced to a mean, which is one observation
of the full-temperature-range method's eq. 13. Consecutive steps within ``temp_tolerance`` of each other
form a temperature block; a session needs one block per temperature point.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

from .._arrays import distinct
from .._validation import positive
from ..errors import InputError
from ..recording import Recording
from ..recording.saturation import find_saturation
from ._warn import DroppedStepsWarning, SaturatedStepsWarning

__all__ = ["AXES", "Steps", "drop_saturated", "drop_unstable", "find_steps", "session_steps"]

AXES = ("x", "y", "z")
_SPAN_CHUNKS = 8  # a step's temperature stability is judged on the means of this many chunks


@dataclass(frozen=True)
class Steps:
    """Reduced turntable steps (one row per step).

    Attributes
    ----------
    temp : ndarray, shape (n,)
        Mean temperature reading over the kept samples [degC].
    axis : ndarray of int, shape (n,)
        Body axis along the table (0, 1, 2 for x, y, z).
    rate : ndarray, shape (n,)
        Signed commanded table rate [rad/s].
    mean : ndarray, shape (n, 3)
        Mean reading over the kept samples [rad/s].
    noise_var : ndarray, shape (n, 3)
        Per-sample white-noise variance from first differences [rad/s]^2.
    count : ndarray of int, shape (n,)
        Kept samples.
    start, stop : ndarray of int, shape (n,)
        Kept sample range in its recording (after settling).
    source : ndarray of int, shape (n,)
        Index of the recording the step came from.
    saturated : ndarray of bool, shape (n,)
        Whether any kept sample sits at full scale.
    temp_span : ndarray, shape (n,)
        Highest minus lowest of the means of 8 equal chunks of the kept samples, so
        quantisation flicker and reading noise average out but drift shows [degC].
    point : ndarray of int, shape (n,)
        Temperature point (0 = coldest); -1 before grouping.
    """

    temp: np.ndarray
    axis: np.ndarray
    rate: np.ndarray
    mean: np.ndarray
    noise_var: np.ndarray
    count: np.ndarray
    start: np.ndarray
    stop: np.ndarray
    source: np.ndarray
    saturated: np.ndarray
    temp_span: np.ndarray
    point: np.ndarray

    def __len__(self) -> int:
        return len(self.rate)

    def take(self, index) -> Steps:
        """The steps at `index` (mask or indices)."""
        return Steps(**{f.name: getattr(self, f.name)[index] for f in fields(self)})

    @staticmethod
    def concat(parts: Sequence[Steps]) -> Steps:
        return Steps(**{f.name: np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(Steps)})

    @property
    def reference(self) -> np.ndarray:
        """Reference body rate of each step, (n, 3) [rad/s]: the table rate along its axis."""
        ref = np.zeros((len(self), 3))
        ref[np.arange(len(self)), self.axis] = self.rate
        return ref

    def label(self, i: int) -> str:
        """Human name of step `i`, for messages."""
        return f"{self.temp[i]:.1f} degC, axis {AXES[self.axis[i]]}, {np.degrees(self.rate[i]):+g} deg/s"

    @property
    def point_temps(self) -> np.ndarray:
        """Mean temperature of each point [degC] (weighted by kept samples)."""
        p = self.point.max() + 1
        w = np.bincount(self.point, self.count * self.temp, minlength=p)
        return w / np.bincount(self.point, self.count, minlength=p)


def _axis_codes(axis: np.ndarray) -> np.ndarray:
    a = np.asarray(axis)
    return (a == "y").astype(np.int8) + 2 * (a == "z").astype(np.int8)


def _chunk_span(temp: np.ndarray, start: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Spread of chunk means of each step's temperature readings [degC]."""
    cs = np.concatenate([[0.0], np.cumsum(temp - temp.mean())])
    k = np.arange(_SPAN_CHUNKS + 1)
    edges = start[:, None] + (count[:, None] * k[None, :]) // _SPAN_CHUNKS
    means = np.diff(cs[edges], axis=1) / np.maximum(np.diff(edges, axis=1), 1)
    return means.max(axis=1) - means.min(axis=1)


def find_steps(rec: Recording, *, settle: float = 2.0, full_scale: float | None = None,
               min_samples: int = 10, source: int = 0) -> Steps:
    """Split one turntable recording into constant-rate steps and reduce each.

    Parameters
    ----------
    rec : Recording
        Needs ``temp``, ``table_rate`` and ``axis``; readings in rad/s.
    settle : float
        Time dropped at the start of each step [s].
    full_scale : float, optional
        Gyro range [rad/s]; samples at it are flagged as saturated.
    min_samples : int
        Steps with fewer kept samples are dropped (with a warning).
    source : int
        Index stored in :attr:`Steps.source`.
    """
    missing = [n for n in ("temp", "table_rate", "axis") if getattr(rec, n) is None]
    if missing:
        raise InputError(f"a turntable recording needs the column(s) {', '.join(missing)}; "
                         "give table_rate (signed, data units), axis (x, y or z) and temp (degC)")
    if rec.units != "rad/s":
        raise InputError("readings are raw counts without a sensitivity; give the sensitivity in LSB per unit")
    if settle < 0:
        raise InputError(f"{{param}} must be >= 0 s, got {settle!r}", param="settle")
    t, rate, axis = rec.t, rec.table_rate, _axis_codes(rec.axis)
    n = len(t)
    gap = np.diff(t) > 5.0 / rec.sample_rate
    change = (np.diff(rate) != 0) | (np.diff(axis) != 0) | gap
    start = np.concatenate([[0], np.flatnonzero(change) + 1])
    stop = np.concatenate([start[1:], [n]])
    keep0 = np.minimum(np.searchsorted(t, t[start] + settle, side="left"), stop)
    count = stop - keep0
    ok = count >= max(int(min_samples), 2)
    if not ok.any():
        raise InputError(f"no rate step of the session{f' (recording {source + 1})' if source else ''} keeps "
                         f"{max(int(min_samples), 2)} samples after the {settle:g} s settling time", param="settle",
                         hint="lower {param}, or check the table_rate column")
    if not ok.all():
        warnings.warn(f"{int((~ok).sum())} step(s) have fewer than {max(int(min_samples), 2)} samples after "
                      f"the {settle:g} s settling time and were left out", DroppedStepsWarning, stacklevel=2)
    keep0, stop, count = keep0[ok], stop[ok], count[ok]
    bounds = np.stack([keep0, stop], axis=1).ravel()
    # reduceat sums [keep0, stop) at even slots; the last stop may equal n, which reduceat refuses
    bounds_safe = np.minimum(bounds, n - 1)

    def seg_sum(x: np.ndarray) -> np.ndarray:
        s = np.add.reduceat(x, bounds_safe, axis=0)[::2]
        if stop[-1] == n:
            s[-1] = x[keep0[-1]:].sum(axis=0)
        return s

    c = count.astype(float)
    mean = seg_sum(rec.gyro) / c[:, None]
    d = np.diff(rec.gyro, axis=0)
    d2 = np.concatenate([d * d, np.zeros((1, 3))])  # d2[i] = (g[i+1] - g[i])^2
    noise_var = (seg_sum(d2) - d2[stop - 1]) / (2.0 * (c[:, None] - 1))
    temp = seg_sum(rec.temp) / c
    sat = seg_sum(find_saturation(rec.gyro, full_scale=full_scale).any(axis=1).astype(np.int64)) > 0
    return Steps(temp=temp, axis=axis[keep0].astype(int), rate=rate[keep0], mean=mean, noise_var=noise_var,
                 count=count, start=keep0, stop=stop, source=np.full(len(count), source), saturated=sat,
                 temp_span=_chunk_span(rec.temp, keep0, count), point=np.full(len(count), -1))


def _blocks(steps: Steps, tol: float) -> np.ndarray:
    """Block id per step: a new block starts at a new source or a temperature jump > tol."""
    new = np.ones(len(steps), bool)
    new[1:] = (np.diff(steps.source) != 0) | (np.abs(np.diff(steps.temp)) > tol)
    return np.cumsum(new) - 1


def _key(steps: Steps) -> np.ndarray:
    """(axis, rate) key of each step; rates rounded to 1e-9 rad/s so unit conversions compare equal."""
    return np.round(steps.rate, 9) + 1e3 * steps.axis


def _describe_keys(keys) -> str:
    axis = np.round(np.asarray(keys) / 1e3).astype(int)
    rate = np.degrees(np.asarray(keys) - 1e3 * axis)
    out = [f"axis {AXES[a]} {r:+g} deg/s" for a, r in zip(axis[:6], rate[:6])]
    return ", ".join(out) + (", ..." if len(axis) > 6 else "")


def drop_unstable(steps: Steps, temp_tolerance: float) -> Steps:
    """Leave out, with a warning, steps whose temperature readings span more than `temp_tolerance` [degC]."""
    unstable = steps.temp_span > temp_tolerance
    if unstable.any():
        warnings.warn(f"{int(unstable.sum())} step(s) span more than {temp_tolerance:g} degC (temperature not "
                      f"settled) and were left out, e.g. {steps.label(int(np.argmax(unstable)))}",
                      DroppedStepsWarning, stacklevel=3)
    return steps.take(~unstable)


def drop_saturated(steps: Steps) -> Steps:
    """Leave out, with a warning naming them, steps holding saturated samples."""
    bad = np.flatnonzero(steps.saturated)
    if bad.size:
        warnings.warn(f"{bad.size} step(s) have saturated samples and were left out: "
                      + "; ".join(steps.label(i) for i in bad[:8]) + ("; ..." if bad.size > 8 else ""),
                      SaturatedStepsWarning, stacklevel=3)
    return steps.take(~steps.saturated)


def session_steps(recordings: Sequence[Recording], *, settle: float = 2.0, full_scale: float | None = None,
                  temp_tolerance: float = 2.0, names: Sequence[str] | None = None) -> Steps:
    """Steps of a whole session, grouped into temperature points and checked.

    Parameters
    ----------
    recordings : sequence of Recording
        One recording holding every temperature point, or one per point.
    settle : float
        Time dropped at the start of each step [s].
    full_scale : float, optional
        Gyro range [rad/s] for saturation detection.
    temp_tolerance : float
        Steps whose readings span more than this are dropped (temperature not settled);
        points closer than this are duplicates [degC].
    names : sequence of str, optional
        Names of the recordings, for messages.

    Raises
    ------
    InputError
        Fewer than three positions, fewer than three or duplicate temperature points,
        or a temperature point missing rate steps.
    """
    tol = positive("temp_tolerance", temp_tolerance)
    names = list(names) if names is not None else [f"recording {i}" for i in range(len(recordings))]
    if not recordings:
        raise InputError("the session holds no recordings")
    steps = Steps.concat([find_steps(r, settle=settle, full_scale=full_scale, source=i)
                          for i, r in enumerate(recordings)])
    steps = drop_unstable(steps, tol)
    block = _blocks(steps, tol)
    n_blocks = block.max() + 1 if len(steps) else 0
    btemp = np.array([steps.temp[block == b].mean() for b in range(n_blocks)])
    order = np.argsort(btemp)
    close = np.flatnonzero(np.diff(btemp[order]) <= tol)
    if close.size:
        a, b = order[close[0]], order[close[0] + 1]
        def src(k):
            return names[int(steps.source[block == k][0])]
        raise InputError(f"duplicate temperature point: {btemp[a]:.2f} degC ({src(a)}) and {btemp[b]:.2f} degC "
                         f"({src(b)}) are within temp_tolerance={tol:g} degC; keep one of them")
    if n_blocks < 3:
        raise InputError(f"the session has {n_blocks} distinct temperature point(s) "
                         f"({', '.join(f'{x:.1f}' for x in np.sort(btemp))} degC); Lagrange interpolation needs at least 3")
    rank = np.empty(n_blocks, int)
    rank[order] = np.arange(n_blocks)
    steps = Steps(**{**{f.name: getattr(steps, f.name) for f in fields(Steps)}, "point": rank[block]})
    axes = sorted(set(steps.axis[steps.rate != 0].tolist()))
    if len(axes) < 3:
        raise InputError(f"the session turns about {len(axes)} position(s) ({', '.join(AXES[a] for a in axes) or 'none'}); "
                         "the 12-parameter fit needs three, with x, y and z in turn along the table axis")
    keys = _key(steps)
    every = distinct(keys)
    for p, temp in enumerate(steps.point_temps):
        present = set(keys[steps.point == p].tolist())
        missing = np.array([k for k in every.tolist() if k not in present], dtype=every.dtype)
        if missing.size:
            raise InputError(f"temperature point {temp:.1f} degC is missing {missing.size} rate step(s) that other "
                             f"points have: {_describe_keys(missing)}")
    steps = drop_saturated(steps)
    return steps
