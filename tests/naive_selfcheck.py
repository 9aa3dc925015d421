"""The straightforward implementations that the calibration's fast paths replaced, kept as their reference.

Each function here reduces the way gyrocal did before the speed work (window by window, full-rate passes,
one whole-recording array after another), on the plain re-implementations of ``tests/naive_reference.py``:
nothing here calls gyrocal.observations.longrun, gyrocal.recording.timebase or gyrocal.recording.timegaps (their TimeBase and Gap are only
the containers :func:`analyse_time` fills for :func:`install`), so a slip in any of them shows as a
difference. ``tests/test_fast_paths.py`` compares the fast paths with them on seeded data (equal to
rounding), and ``bench/bench_selfcheck.py`` times them as its naive baseline in the same process.
:func:`install` swaps them into the library, so that a whole calibration runs the old way.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from contextlib import contextmanager
from types import MappingProxyType
from typing import Any

import naive_reference as ref
import numpy as np

from gyrocal._validation import finite_array, positive
from gyrocal.errors import InputError
from gyrocal.observations import Observation
from gyrocal.observations.partial_cycles import partial_cycles, weigh_readings


def _time_weights(t: np.ndarray, n: int) -> np.ndarray:
    if t.shape != (n,):
        raise InputError(f"t has {len(t)} sample times but the window has {n} samples")
    step = np.diff(t)
    if np.any(step <= 0):
        raise InputError("t must increase strictly inside a window")
    w = np.empty(n)
    w[0], w[-1] = step[0], step[-1]
    w[1:-1] = (step[:-1] + step[1:]) / 2
    return w


def observe(samples, sample_rate, kind, *, speed=None, angle=None, t=None, level=None, mean_var=None) -> Observation:
    """One window reduced with ``np.average`` and ``np.diff`` (gyrocal.observations.observe as it was)."""
    m = finite_array("samples", samples, shape_tail=(3,), ndim=2)
    fs = positive("sample_rate", sample_rate)
    if t is None:
        weights, duration = None, len(m) / fs
    else:
        weights = _time_weights(finite_array("t", t, ndim=1), len(m))
        duration = float(weights.sum())
    if kind == "speed":
        rate, ang = abs(float(speed)), math.nan
    elif kind == "angle":
        ang = 2 * math.pi if angle is None else abs(float(angle))
        rate = ang / duration
    else:
        rate, ang = 0.0, math.nan
    d = np.diff(m, axis=0)
    return Observation(
        mean=np.average(m, axis=0, weights=weights) if level is None else level, mean_var=mean_var,
        mean_sq=np.average(m * m, axis=0, weights=weights), noise_var=(d * d).mean(axis=0) / 2.0,
        count=len(m), duration=duration, kind=kind, rate=rate, angle=ang,
    )


def observe_windows(rec, windows, reference, speed, *, long_run=True, ripple=True, times=None):
    """Every window reduced on its own (gyrocal.observations.window_stats.observe_windows as it was)."""
    times = rec.t if times is None else times
    stats = {}
    if long_run or ripple:
        stats = window_stats(rec, windows, reference, times, long_run=long_run, ripple=ripple)
    out = []
    for i, w in enumerate(windows):
        samples = rec.gyro[w.start:w.stop]
        samples = samples if rec.gyro.flags.f_contiguous else np.asfortranarray(samples)
        t, extra = times[w.start:w.stop], stats.get(i, {})
        if w.kind == "static":
            out.append(observe(samples, rec.sample_rate, "static", t=t, **extra))
        elif reference == "speed":
            out.append(observe(samples, rec.sample_rate, "speed", speed=speed, t=t, **extra))
        else:
            out.append(observe(samples, rec.sample_rate, "angle", angle=w.angle, t=t, mean_var=extra.get("mean_var")))
    return tuple(out)


def newey_west_var(x, lags=None, *, prewhiten=True):
    """Long-run variance of the mean, column by column of an (n, k) array (gyrocal.observations.longrun as it was)."""
    x = np.asarray(x, dtype=float)
    n = len(x)
    d = x - x.mean(axis=0)
    rho = np.zeros(d.shape[1])
    if prewhiten and n > 3:
        den = np.einsum("ij,ij->j", d[:-1], d[:-1])
        rho = np.clip(np.einsum("ij,ij->j", d[1:], d[:-1]) / np.where(den > 0, den, 1.0), -0.97, 0.97)
        d = d[1:] - rho * d[:-1]
    m = len(d)
    if lags is None:
        lags = int(np.floor(4 * (m / 100.0) ** (2.0 / 9.0)))
    lags = max(0, min(lags, m - 1))
    s = np.einsum("ij,ij->j", d, d) / m
    for h in range(1, lags + 1):
        s = s + 2 * (1 - h / (lags + 1)) * np.einsum("ij,ij->j", d[h:], d[:-h]) / m
    return np.maximum(s, 0.0) / (1.0 - rho) ** 2 / n


def fit_level(x, t, lines):
    """One plateau's regression on its own design matrix (gyrocal.observations.longrun as it was)."""
    if not lines:
        level = x.mean(axis=0)
        return level, 1.0 / len(x), x - level
    X = ref.design(t, lines)
    inv = np.linalg.inv(X.T @ X)
    coef = inv @ (X.T @ x)
    return coef[0], float(inv[0, 0]), x - X @ coef


def _pooled_lrv(residuals):
    total = sum(len(r) for r in residuals)
    step = max(1, int(np.ceil(total / 20_000)))
    chosen = np.concatenate(residuals[::step])
    return newey_west_var(chosen) * len(chosen)


def window_stats(rec, windows, reference, times, *, long_run, ripple):
    """Plateau levels and long-run variances, plateau by plateau (gyrocal.observations.window_stats as it was)."""
    d = max(1, int(round(rec.sample_rate / 200.0)))
    gyro = ref.block_means(rec.gyro, d)
    clock = ref.block_means(np.asarray(times, dtype=float), d)
    span = {i: (-(-w.start // d), w.stop // d) for i, w in enumerate(windows)}
    blocks = {i: gyro[a:b] for i, (a, b) in span.items() if b - a >= 4}
    plateaus = [i for i in blocks if windows[i].kind == "rotation" and reference == "speed"]
    turns = [i for i, w in enumerate(windows) if w.kind == "rotation" and reference == "angle"]
    statics = [i for i in blocks if windows[i].kind == "static"]
    lines = []
    if ripple and plateaus:
        b = blocks[max(plateaus, key=lambda i: len(blocks[i]))]
        lines = ref.find_lines(b[:, int(np.argmax(np.abs(b.mean(axis=0))))])
    out, resid, factor = {}, {}, {}
    for i in plateaus:
        t = clock[span[i][0]:span[i][1]]
        t = (t - t[0]) / float(np.median(np.diff(t)))
        level, factor[i], resid[i] = fit_level(blocks[i], t, lines)
        if ripple:
            out[i] = {"level": level, "cycles": partial_cycles(gyro, span[i], blocks[i], t, lines, level)}
    if long_run and plateaus:
        a, b = ref.span_variance([resid[i] for i in plateaus])
        for i in plateaus:
            out.setdefault(i, {})["mean_var"] = b * factor[i] + a * factor[i] ** 2
    lrv = None
    if long_run and statics:
        lrv = _pooled_lrv([blocks[i] - blocks[i].mean(axis=0) for i in statics])
        for i in statics:
            out[i] = {"mean_var": lrv / len(blocks[i])}
        for i in turns:
            out[i] = {"mean_var": lrv * d / len(windows[i])}
    if ripple and plateaus:  # the two readings of the declared speed, as the library weighs them
        weigh_readings(out, {i: windows[i] for i in plateaus}, {i: blocks[i] for i in statics}, lrv)
    return out


# -- the time base: whole-log arrays of steps and clock residuals, candidate gaps judged one by one --

def _floors(r: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """The least-delayed sample of each block of `size` (the last one may be short): values and indices."""
    at = np.array([lo + int(np.argmin(r[lo:lo + size])) for lo in range(0, len(r), size)])
    return r[at], at


def _candidates(step: np.ndarray, period: float, floor: np.ndarray, size: int) -> list[int]:
    """Long steps in the two blocks around each rise of the envelope by half a period: the longest
    first (ties in time order), then the shorter ones in time order."""
    n_steps = len(step)
    rises = [b for b in range(len(floor) - 1) if floor[b + 1] - floor[b] >= 0.5 * period]
    likely = sorted({i for b in rises for i in range(b * size, min(n_steps, (b + 2) * size))
                     if step[i] > ref.CANDIDATE_STEP * period})
    late = sorted((i for i in likely if step[i] >= ref.LATE_STEP * period), key=lambda i: -step[i])
    return late + [i for i in likely if step[i] < ref.LATE_STEP * period]


def _find_gaps(r: np.ndarray, step: np.ndarray, period: float, floor: np.ndarray, size: int) -> list[tuple]:
    """Real gaps ``(index, step, lost)``: each candidate step judged, in order, on the least-delayed level
    of the `size` samples up to it and from the sample after it, with the gaps found so far taken out;
    a gap when that level rises by whole periods, no more of them than the step (lengthened by the delay
    of the sample before it, which shortens it) can hold."""
    n = len(r)
    lost_at = np.zeros(n)  # samples lost just before each sample, as found so far
    for i in _candidates(step, period, floor, size):
        lo, hi = max(0, i - size + 1), min(n, i + 1 + size)
        adj = r[lo:hi] - period * np.cumsum(lost_at[lo:hi])  # levels relative within the window
        before = ref.least_delayed(adj[: i + 1 - lo])
        lost = int(np.rint((ref.least_delayed(adj[i + 1 - lo:]) - before) / period))
        room = int(np.rint((step[i] + max(0.0, adj[i - lo] - before)) / period))
        if 1 <= lost <= room:
            lost_at[i + 1] = lost
    return [(int(j), float(step[j - 1]), int(lost_at[j])) for j in np.flatnonzero(lost_at)]


def time_facts(t, *, has_time: bool = True) -> dict:
    """The facts of gyrocal.recording.timebase.TimeBase for stamps `t`, as a dict (gaps as ``(index, step, lost)``)."""
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or len(t) < 2:
        raise InputError(f"a time base needs at least two sample times, got shape {t.shape}")
    n, step = len(t), np.diff(t)
    period = ref.nominal_period(t)
    # the documented even spread of up to 20 000 steps for the median and the jitter
    spread = np.linspace(0, n - 2, min(n - 1, 20_000)).astype(np.intp)
    regular = float(step.max() - step.min()) <= 1e-9 * period * n  # a clock's own stamps, up to rounding
    gaps: list[tuple] = []
    clock = (float(t[0]), float(t[-1] - t[0]) / (n - 1))
    if not regular:
        r = t - t[0] - period * np.arange(n)  # clock residual; its lower envelope: the least-delayed samples
        size = ref.block_size(period, n)
        floor, k = _floors(r, size)
        gaps = _find_gaps(r, step, period, floor, size)
        if gaps:  # the envelope again, with the lost samples counted (a block may straddle a gap)
            lost = np.zeros(n)
            for index, _, gone in gaps:
                lost[index] = gone
            lost = np.cumsum(lost)
            floor, at = _floors(r - period * lost, size)
            k = at + lost[at]
        clock = ref.fit_clock(float(t[0]), period, floor, k)
    across = {index - 1 for index, _, _ in gaps}  # the gaps' own steps are left out of the spread
    sample = np.array([step[j] for j in spread if int(j) not in across]) if len(across) else step[spread]
    sample = sample if len(sample) else step[spread]
    mean = float(sample.sum()) / len(sample)
    return {
        "n": n, "span": float(t[-1] - t[0]), "period": period, "mean_step": float(t[-1] - t[0]) / (n - 1),
        "median_step": ref.median(sample),
        "jitter": math.sqrt(float(np.sum((sample - mean) ** 2)) / len(sample)) if len(sample) > 1 else 0.0,
        "delayed": _late(step, sample, period, gaps), "gaps": tuple(gaps), "has_time": has_time,
        "regular_clock": clock is not None, "clock_start": clock[0] if clock else float(t[0]),
        "clock_period": clock[1] if clock else period,
    }


def _late(step, sample, period, gaps) -> int:
    """Long steps that lost nothing, longer than 3 periods and than the packets' own step (the median sampled
    step over half a period) plus the larger of 2 periods and 10 ms."""
    packets = sample[sample > 0.5 * period]
    packet = ref.median(packets) if len(packets) else period
    limit = max(ref.LATE_STEP * period, packet + max(ref.LATE_EXTRA * period, ref.LATE_HOLD))
    return int(np.count_nonzero(step > limit)) - sum(1 for _, s, _ in gaps if s > limit)


def analyse_time(t, *, has_time: bool = True, breaks=()):
    """:func:`time_facts` in the library's container (for :func:`install`: the pipeline reads a TimeBase).

    The reference reads contiguous logs only: the breaks the recording found are passed through."""
    from gyrocal.recording.timebase import TimeBase
    from gyrocal.recording.timegaps import Gap

    facts = time_facts(t, has_time=has_time)
    return TimeBase(**{**facts, "gaps": tuple(Gap(*g) for g in facts["gaps"]), "breaks": tuple(breaks)})


# -- the calibration's other pieces as they were --

def _spread_blocks(gyro: np.ndarray, sample_rate: float, most: int = 200) -> np.ndarray:
    """Up to `most` whole blocks of half a second (:data:`gyrocal.observations.observed.QUIET_BLOCK`), evenly spread over `gyro`.

    The quiet-noise level is a pooled standard deviation of quiet blocks: two hundred of them
    give it to a fraction of a per cent, for a fraction of the work on a long log.
    """
    size = max(8, int(round(0.5 * sample_rate)))  # gyrocal.observations.observed.QUIET_BLOCK = 0.5 s
    blocks = len(gyro) // size
    if blocks <= most:
        return gyro
    pick = np.linspace(0, blocks - 1, most).astype(np.intp)
    return gyro[(pick[:, None] * size + np.arange(size)).ravel()]


def _freeze(value: Any, where: str) -> Any:
    """A JSON value made immutable (objects -> read-only mappings, lists -> tuples); numpy becomes Python."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    elif isinstance(value, np.generic):
        value = value.item()
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, float)):
        if not math.isfinite(value):
            raise InputError(f"{where} must be finite, got {value!r}")
        return value
    if isinstance(value, Mapping):
        if not all(isinstance(k, str) for k in value):
            raise InputError(f"{where} must have text keys, got {list(value)!r}")
        return MappingProxyType({k: _freeze(v, f"{where}.{k}") for k, v in value.items()})
    if isinstance(value, (list, tuple)):
        return tuple(_freeze(v, f"{where}[{i}]") for i, v in enumerate(value))
    raise InputError(f"{where} must be a JSON value (number, text, list, object or null), got {type(value).__name__}")


def pipeline_windows(rec, windows, reference, speed, *, long_run=True, ripple=True, times=None, period=None):
    """What the pipeline reduced before: stamps on a regular clock without gaps rebuilt as clock times."""
    if period is not None:
        tb = analyse_time(rec.t, has_time=rec.has_time)
        times = None if not tb.gaps and tb.jitter <= 1e-9 * tb.period else tb.clock_times()
    return observe_windows(rec, windows, reference, speed, long_run=long_run, ripple=ripple, times=times)


def _patches() -> list[tuple[object, str, object]]:
    import gyrocal.pipeline
    import gyrocal.recording
    import gyrocal.results.sections

    return [(gyrocal.recording, "analyse_time", analyse_time), (gyrocal.pipeline, "observe_windows", pipeline_windows),
            (gyrocal.pipeline, "_spread_blocks", _spread_blocks), (gyrocal.results.sections, "_freeze", _freeze)]


def install(monkeypatch) -> None:
    """Swap the straightforward implementations into gyrocal (a pytest ``monkeypatch``, undone after the test)."""
    for module, name, value in _patches():
        monkeypatch.setattr(module, name, value)


@contextmanager
def installed():
    """The straightforward implementations in gyrocal for the duration of a ``with`` block (the benches)."""
    saved = [(module, name, getattr(module, name)) for module, name, _ in _patches()]
    try:
        for module, name, value in _patches():
            setattr(module, name, value)
        yield
    finally:
        for module, name, value in saved:
            setattr(module, name, value)
