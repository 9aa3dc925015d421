"""Where a log is not contiguous: parts glued out of order, a restart, or a long pause.

A *break* is a sample before which the log does not continue the samples before it, so no
window, pose or turn may span it (an integral across it joins two unrelated motions). Three
things show one:

* a sample counter (a column named ``samples``, ``n_samples``, ``counter`` or ``seq``) that
  steps back, or forward by more than :data:`BREAK_S` of samples (a step of a few samples is
  lost samples, a gap); a counter that wraps (``2^k - 1 -> 0``) is no break;
* a time column that steps back by more than :data:`BACK_PERIODS` periods (jitter steps back
  by less): the parts are laid end to end, one nominal period apart;
* a time step forward longer than :data:`BREAK_S` and :data:`BREAK_PERIODS` periods
  (:func:`gyrocal.recording.timebase.analyse_time`).
"""

from __future__ import annotations

import numpy as np

from .._arrays import median

__all__ = ["BACK_PERIODS", "BREAK_PERIODS", "BREAK_S", "COUNTER_NAMES", "MIN_PART", "counter_breaks",
           "describe_breaks", "find_counter", "join_backward_parts", "spans_break", "split_spans"]

#: Columns read as a sample counter (case-insensitive).
COUNTER_NAMES = ("samples", "n_samples", "counter", "seq")
#: A forward jump longer than this [s] (and than `BREAK_PERIODS` periods) is a break, not a gap.
BREAK_S = 1.0
BREAK_PERIODS = 100
#: A backward time step longer than this many periods is a break; shorter ones are jitter (refused).
BACK_PERIODS = 10
#: Parts shorter than this [samples] are not read as glued parts (the time column is refused instead).
MIN_PART = 16


def find_counter(extra: dict) -> tuple[str, np.ndarray] | None:
    """The sample counter among the pass-through columns: ``(name, values)``, or None."""
    lower = {k.strip().lower(): k for k in extra}
    for name in COUNTER_NAMES:
        if name in lower:
            values = np.asarray(extra[lower[name]], dtype=float)
            if len(values) > 1 and np.isfinite(values).all() and np.array_equal(values, np.round(values)):
                return lower[name], values
    return None


def counter_breaks(counter: np.ndarray, max_jump: float) -> tuple[np.ndarray, np.ndarray]:
    """Breaks of a sample counter and the samples lost before each sample.

    Returns ``(breaks, lost)``: the indices of the samples that start a new part, and for every
    sample the count lost (a forward step of 2 to `max_jump`) since the one before it.
    """
    d = np.diff(np.asarray(counter, dtype=float))
    wrap = (counter[1:] == 0) & np.isin(counter[:-1] + 1, [2.0**8, 2.0**16, 2.0**32])
    brk = ((d <= 0) & ~wrap) | (d > max_jump)
    lost = np.zeros(len(counter))
    lost[1:] = np.where(~brk & ~wrap & (d > 1), d - 1, 0.0)
    return np.flatnonzero(brk) + 1, lost


def join_backward_parts(t: np.ndarray, period: float | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """Stamps that step back by more than `BACK_PERIODS` periods between increasing parts, laid end to end.

    Returns ``(t, breaks)``, or None when the stamps do not step back that way (then they are
    checked as they are).
    """
    step = np.diff(t)
    if len(step) < 2 * MIN_PART or not (step <= 0).any():
        return None
    forward = step[step > 0]
    period = period or (float(median(forward)) if len(forward) else 0.0)
    cut = np.flatnonzero(step < -BACK_PERIODS * period)
    if period <= 0 or not len(cut) or np.count_nonzero(step <= 0) != len(cut):
        return None
    breaks = cut + 1
    if np.min(np.diff(np.concatenate(([0], breaks, [len(t)])))) < MIN_PART:
        return None
    shift = np.zeros(len(t))
    shift[breaks] = period - step[cut]  # each part starts one period after the last one ended
    return t + np.cumsum(shift), breaks


def split_spans(start: int, stop: int, breaks) -> list[tuple[int, int]]:
    """``start:stop`` cut at the breaks inside it (a break at ``i`` starts a part at ``i``)."""
    inner = [int(b) for b in breaks if start < b < stop]
    edges = [start, *inner, stop]
    return list(zip(edges[:-1], edges[1:]))


def spans_break(start: int, stop: int, breaks) -> bool:
    """Whether samples ``start:stop`` hold a break (samples on both sides of one)."""
    return any(start < b < stop for b in breaks)


def describe_breaks(breaks, times, source: str = "") -> str:
    """One line for people: where the log is not contiguous (`times`: of each break [s])."""
    at = ", ".join(f"{int(b)} ({float(s):.2f} s)" for b, s in list(zip(breaks, times))[:5])
    more = ", ..." if len(breaks) > 5 else ""
    return (f"{source}the log is not contiguous: {len(breaks)} break(s), before sample(s) {at}{more}; no window, "
            "pose or turn spans one")
