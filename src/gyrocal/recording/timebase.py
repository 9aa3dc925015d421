"""The time base of a recording: nominal rate, jitter, delayed deliveries and real gaps.

Logs stamped when a PC *receives* the samples come in bursts: the steps alternate short and
long (for example 3 ms and 17 ms around a 10 ms sensor clock), and a late packet is a long
step followed by a burst of short ones. The sensor clock stays regular under all this, so:

* the nominal period is the mean step of the regular clock, found robustly as the median of
  block-mean steps (a block of 64 steps averages bursts away; the median ignores the few
  blocks that hold a gap), never the median of the single steps;
* a long step is a **real gap** only when samples are missing: the clock residual
  ``t_i - i P`` (its lower envelope, the least-delayed samples) jumps by at least half a
  period across it and stays there. A delayed delivery makes the residual rise and fall
  back within the burst, and loses nothing.

Angles are then integrals on the actual stamps (trapezoid weights, see
:func:`gyrocal.observations.observe`); a turn that straddles a real gap has lost angle that
no stamp can give back.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import median
from ..errors import InputError
from .breaks import BREAK_PERIODS, BREAK_S, describe_breaks
from .timegaps import LATE_STEP as _LATE_STEP
from .timegaps import Gap, find_gaps

__all__ = ["Gap", "TimeBase", "analyse_time", "nominal_period"]

_BLOCK = 64  # steps per block of the robust period estimate
_ENVELOPE = 50  # samples each side over which the clock residual's lower envelope is taken, at least
_ENVELOPE_S = 0.5  # [s] and at least this long: a late packet's burst must drain inside it
_STRETCH = 1 << 16  # samples per pass over long logs: the temporaries stay in the cache
#: A late delivery (a step over `_LATE_STEP` periods that lost nothing) is, with several samples per packet,
#: longer than the packets' own step by this many periods and by `_LATE_HOLD` [s] (at 1 kHz a PC's scheduling jitter alone spans a few periods).
_LATE_EXTRA = 2.0
_LATE_HOLD = 0.01


def nominal_period(t: np.ndarray) -> float:
    """Period of the sensor clock [s]: the median of block-mean steps of up to `_BLOCK` steps.

    Equal to the mean step ``span / (N - 1)`` for a log without gaps, whatever its jitter,
    and unaffected by a few gaps (they move only the blocks that hold them).
    """
    t = np.asarray(t, dtype=float)
    n = len(t) - 1
    if n < 1:
        raise InputError(f"a time base needs at least two samples, got {len(t)}")
    block = min(_BLOCK, max(1, n // 8))
    if n < 2 * block:
        return float(t[-1] - t[0]) / n
    ends = t[::block]
    return float(median(np.diff(ends))) / block


@dataclass(frozen=True)
class TimeBase:
    """Facts about a recording's time stamps.

    Attributes
    ----------
    n : int
        Samples.
    span : float
        ``t[-1] - t[0]`` [s].
    period : float
        Nominal period of the sensor clock [s] (:func:`nominal_period`).
    mean_step, median_step : float
        Mean and median of the single steps [s].
    jitter : float
        Standard deviation of the single steps, gaps left out [s].
    delayed : int
        Long steps (over 3 periods) that lost no sample: late deliveries caught up by a burst.
    gaps : tuple of Gap
        Real gaps (samples missing).
    has_time : bool
        Whether the stamps came from the data (False: built from a declared rate).
    regular_clock : bool
        Whether the stamps follow a regular sensor clock (with its gaps) up to bounded delays:
        the lower envelope of ``t_i - i P`` stays within half a period of a straight line. Then
        :meth:`clock_times` rebuilds the sample times on that clock.
    clock_start, clock_period : float
        The regular clock ``t = clock_start + clock_period x (sample number, gaps counted)`` [s].
    breaks : tuple of int
        Samples that start a new part of a log that is not contiguous (:mod:`gyrocal.recording.breaks`): the
        recording's own (a counter, time stepping back) and time steps forward far beyond the clock.
    """

    n: int
    span: float
    period: float
    mean_step: float
    median_step: float
    jitter: float
    delayed: int
    gaps: tuple[Gap, ...]
    has_time: bool = True
    regular_clock: bool = False
    clock_start: float = 0.0
    clock_period: float = 0.0
    breaks: tuple[int, ...] = ()

    @property
    def sample_rate(self) -> float:
        """Nominal rate [Hz]: of the regular sensor clock when there is one, else of the block-mean steps."""
        return 1.0 / (self.clock_period if self.regular_clock else self.period)

    @property
    def counted(self) -> bool:
        """Whether the time is a count of samples at a nominal rate rather than a clock's reading.

        True without a time column (the rate was declared) and for stamps that step by one round period
        (a whole number of 0.1 Hz), up to a microsecond's rounding (104 Hz written with six decimals), lost
        samples aside: a sample counter times the chip's nominal rate. A chip's own oscillator runs off
        that rate by a fraction of a per cent or more, and every angle integrated on such a time base
        carries that error. A PC's receive times (jitter), or a logger's crystal (a period off round by
        its ppm), measure time.
        """
        if not self.has_time:
            return True
        rate = (self.n - 1 + self.lost) / self.span  # over the whole log: a microsecond's rounding averages out
        return self.jitter <= max(1e-6, 1e-6 * self.period) and abs(rate * 10 - round(rate * 10)) <= 1e-6 * rate

    @property
    def lost(self) -> int:
        """Samples missing in all gaps."""
        return sum(g.lost for g in self.gaps)

    @property
    def bursty(self) -> bool:
        """Whether the single steps scatter by more than 10 % of the period (receive-time stamps)."""
        return self.jitter > 0.1 * self.period

    def clock_numbers(self) -> np.ndarray:
        """Each sample's number on the sensor clock (N,): its index plus the samples lost before it."""
        k = np.arange(self.n, dtype=float)
        if self.gaps:
            add = np.zeros(self.n)
            for g in self.gaps:
                add[g.index] += g.lost
            k += np.cumsum(add)
        return k

    def clock_times(self) -> np.ndarray | None:
        """Sample times [s] on the regular sensor clock, gaps included; None without a regular clock.

        Receive-time stamps place a sample when it arrived, up to a late delivery's delay after it
        was taken; during a ramp that misplaces rate. The sensor's own clock does not.
        """
        if not self.regular_clock:
            return None
        return self.clock_start + self.clock_period * self.clock_numbers()

    def gaps_in(self, start: int, stop: int) -> tuple[Gap, ...]:
        """Gaps between samples ``start`` and ``stop - 1`` (inside a window ``start:stop``)."""
        return tuple(g for g in self.gaps if start < g.index < stop)

    def to_document(self) -> dict:
        """JSON-ready facts (the calibration file's ``observed.time_base``), times in seconds."""
        return {"nominal_rate": self.sample_rate, "has_time": self.has_time, "mean_step": self.mean_step,
                "median_step": self.median_step, "jitter": self.jitter, "late_deliveries": self.delayed,
                "gaps": len(self.gaps), "lost_samples": self.lost, "regular_clock": self.regular_clock,
                "breaks": list(self.breaks)}

    def describe(self) -> list[str]:
        """Plain lines for people: rate, steps, jitter, delayed deliveries and gaps."""
        ms = 1e3
        if not self.has_time:
            return [f"time base: no time column; {self.sample_rate:.6g} Hz as declared, {self.n} samples",
                    *self._break_lines()]
        jitter = f"{self.jitter * ms:.3g} ms" if self.jitter > 1e-6 * self.period else "none"
        lines = [
            f"time base: {self.sample_rate:.6g} Hz nominal (mean step of the sensor clock); "
            f"steps mean {self.mean_step * ms:.4g} ms, median {self.median_step * ms:.4g} ms, jitter {jitter}"
        ]
        if self.counted:
            lines.append("  every step is the same, a round period: a sample counter times the chip's nominal rate?")
        if self.bursty:
            on = ("the sensor's regular clock rebuilt from them" if self.regular_clock else "the stamps")
            lines.append(f"  steps are bursty (receive-time stamps?): angles are integrated on {on}, and the rate "
                         "is the mean one, never the median step")
        if self.delayed:
            lines.append(f"  {self.delayed} late deliveries (a long step caught up by a burst; no sample lost)")
        if self.gaps:
            worst = max(self.gaps, key=lambda g: g.lost)
            lines.append(f"  {len(self.gaps)} gap(s), {self.lost} sample(s) missing; longest {worst.step * ms:.4g} ms "
                         f"at sample {worst.index} ({worst.lost} lost): a turn across a gap keeps it as a bound on its angle, "
                         "or is left out when that bound exceeds 1 %")
        return lines + self._break_lines()

    def _break_lines(self) -> list[str]:
        if not self.breaks:
            return []
        return ["  " + describe_breaks(self.breaks, self.clock_start + self.period * np.asarray(self.breaks))]


def _block_size(period: float, n: int) -> int:
    """Samples over which the least-delayed level is taken: 50, and at least half a second."""
    return int(min(n, max(_ENVELOPE, round(_ENVELOPE_S / period))))


def _floors(r: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """The least-delayed sample of each block of `size` (the last one may be short): values and indices."""
    m = len(r) // size
    at = r[: m * size].reshape(m, size).argmin(axis=1) + np.arange(m) * size
    if m * size < len(r):
        at = np.append(at, m * size + int(np.argmin(r[m * size:])))
    return r[at], at


def _residual_floors(t: np.ndarray, period: float, size: int, lost=None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_floors` of the clock residual (less the samples `lost` up to each sample: a function of
    ``lo, hi`` giving them for samples ``lo:hi``), computed a cache-sized stretch of whole blocks at a time."""
    stretch = size * max(1, _STRETCH // size)
    numbers = np.arange(min(stretch, len(t)), dtype=float)
    clock, r = np.empty(len(numbers)), np.empty(len(numbers))

    def stretch_of(lo: int, hi: int) -> np.ndarray:
        # gyrocal.recording.timegaps.residual(t, period, lo, hi), in the same operations, into buffers kept in the cache
        m = hi - lo
        np.multiply(np.add(numbers[:m], lo, out=clock[:m]), period, out=clock[:m])
        np.subtract(np.subtract(t[lo:hi], t[0], out=r[:m]), clock[:m], out=r[:m])
        return r[:m] if lost is None else r[:m] - period * lost(lo, hi)

    parts = [_floors(stretch_of(lo, min(lo + stretch, len(t))), size) for lo in range(0, len(t), stretch)]
    return (np.concatenate([v for v, _ in parts]),
            np.concatenate([at + i * stretch for i, (_, at) in enumerate(parts)]))


def _steps(t: np.ndarray):
    """The steps of `t` a cache-sized stretch at a time (no array of every step)."""
    n = len(t) - 1
    step = np.empty(min(n, _STRETCH))  # one buffer, kept in the cache
    for a in range(0, n, _STRETCH):
        b = min(a + _STRETCH, n)
        yield np.subtract(t[a + 1:b + 1], t[a:b], out=step[:b - a])


def _step_range(t: np.ndarray) -> tuple[float, float]:
    """Shortest and longest step of `t`."""
    lo, hi = np.inf, -np.inf
    for step in _steps(t):
        lo, hi = min(lo, float(step.min())), max(hi, float(step.max()))
    return lo, hi


def _count_steps_over(t: np.ndarray, limit: float) -> int:
    """Steps of `t` longer than `limit`."""
    return sum(int(np.count_nonzero(step > limit)) for step in _steps(t))


def analyse_time(t, *, has_time: bool = True, breaks=()) -> TimeBase:
    """Read the time base of stamps `t` [s] (strictly increasing).

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s].
    has_time : bool
        Whether the stamps came from the data; a time base built from a declared rate is
        regular but may still hold gaps (rows dropped for saturation).
    breaks : sequence of int
        Known breaks (:attr:`gyrocal.recording.Recording.breaks`); steps forward longer than
        :data:`gyrocal.recording.breaks.BREAK_S` and :data:`gyrocal.recording.breaks.BREAK_PERIODS` periods are added.
    """
    # long function: the facts in the order they depend on each other, each pass a stretch at a time
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or len(t) < 2:
        raise InputError(f"a time base needs at least two sample times, got shape {t.shape}")
    period = nominal_period(t)
    # up to 20 000 evenly spread steps for the median and the jitter: exact enough, and cheap on long logs
    spread = np.linspace(0, len(t) - 2, min(len(t) - 1, 20_000)).astype(np.intp)
    sample = t[spread + 1] - t[spread]
    shortest, longest = _step_range(t)
    regular = longest - shortest <= 1e-9 * period * len(t)  # a clock's own stamps, up to rounding
    gaps: list[Gap] = []
    clock = (float(t[0]), float(t[-1] - t[0]) / (len(t) - 1))
    if not regular:
        size = _block_size(period, len(t))
        floor, at = _residual_floors(t, period, size)  # lower envelope of the clock residual: least-delayed samples
        found = find_gaps(t, period, floor, size)
        gaps = found.gaps
        k = None
        if gaps:  # the envelope again, with the lost samples counted (a block may straddle a gap)
            floor, at = _residual_floors(t, period, size, found.upto_range)
            k = at + found.upto(at)
        clock = _fit_clock(t, period, floor, at if k is None else k)
        if gaps:
            keep = np.ones(len(sample), dtype=bool)
            keep[np.isin(spread, [g.index - 1 for g in gaps])] = 0
            sample = sample[keep] if keep.any() else sample
    return TimeBase(
        n=len(t),
        span=float(t[-1] - t[0]),
        period=period,
        mean_step=float(t[-1] - t[0]) / (len(t) - 1),
        median_step=float(median(sample)),
        jitter=float(sample.std()) if len(sample) > 1 else 0.0,
        delayed=_late(t, longest, sample, period, gaps),
        gaps=tuple(gaps),
        has_time=has_time,
        regular_clock=clock is not None,
        clock_start=clock[0] if clock else float(t[0]),
        clock_period=clock[1] if clock else period,
        breaks=_breaks(t, longest, period, breaks),
    )


def _breaks(t: np.ndarray, longest: float, period: float, given) -> tuple[int, ...]:
    """The given breaks and the steps forward far beyond the clock."""
    limit = max(BREAK_S, BREAK_PERIODS * period)
    jumps = np.flatnonzero(np.diff(t) > limit) + 1 if longest > limit else ()
    return tuple(sorted({int(b) for b in given} | {int(b) for b in jumps}))


def _late(t: np.ndarray, longest: float, sample: np.ndarray, period: float, gaps) -> int:
    """Late deliveries: long steps that lost nothing, longer than the packets' own step by `_LATE_EXTRA` periods
    and `_LATE_HOLD`.

    With four samples per packet every fourth step is four periods long: that is the packet rhythm,
    not a delivery held up. `sample` is an even spread of the steps (the packets' step is their
    median above half a period).
    """
    packet = float(median(sample[sample > 0.5 * period])) if np.any(sample > 0.5 * period) else period
    limit = max(_LATE_STEP * period, packet + max(_LATE_EXTRA * period, _LATE_HOLD))
    if longest <= limit:
        return 0
    return _count_steps_over(t, limit) - sum(g.step > limit for g in gaps)


def _fit_clock(t: np.ndarray, period: float, floor: np.ndarray, k: np.ndarray) -> tuple[float, float] | None:
    """``(start, period)`` of the regular clock under stamps `t`, or None.

    The lower envelope of ``t - k P`` (`floor`: the least-delayed sample of each block, at clock
    number `k`: its index plus the samples lost before it) is fitted by a line; the clock is
    regular when the envelope stays within half a period of it.
    """
    if len(floor) < 2:
        return float(t[0]), period
    slope, icept = np.polyfit(k, floor, 1)
    resid = floor - (icept + slope * k)
    if float(resid.max() - resid.min()) >= 0.5 * period:
        return None
    return float(t[0] + icept), float(period + slope)
