"""Real gaps in a log's time stamps, told apart from late deliveries (see :mod:`gyrocal.recording.timebase`).

A long step is a real gap only when samples are missing: the clock residual ``t_i - t_0 - i P`` (its
lower envelope, the least-delayed samples) jumps by at least half a period across it and stays
there. Candidates are the long steps near a rise of the envelope; each is judged on the envelope
just before and just after it, with the gaps already found taken out. Long logs hold thousands of
candidates in bursty stamps, so those close together are judged at once: the least-delayed level of
every window comes from one rank filter over the stretch they share (the same values, window by
window, as a quantile of each).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import distinct

__all__ = ["CANDIDATE_STEP", "LATE_STEP", "Found", "Gap", "find_gaps", "least_delayed", "residual"]

#: Steps below this multiple of the period cannot hide a lost sample and are not examined.
CANDIDATE_STEP = 1.5
#: A step this many periods long that lost nothing is a late delivery (shorter ones are jitter).
LATE_STEP = 3.0


@dataclass(frozen=True)
class Gap:
    """Samples missing from a log: the step ``t[index - 1] -> t[index]`` lost `lost` samples.

    Attributes
    ----------
    index : int
        First sample after the gap.
    step : float
        The long step [s].
    lost : int
        Samples missing, from the jump of the regular clock.
    """

    index: int
    step: float
    lost: int


def least_delayed(x: np.ndarray) -> float:
    """A low quantile (the tenth) of `x`: the least-delayed level, unmoved by one late sample."""
    k = len(x) // 10
    return float(np.partition(x, k)[k])


def residual(t: np.ndarray, period: float, lo: int, hi: int) -> np.ndarray:
    """The clock residual ``t_i - t_0 - i P`` of samples ``lo:hi``, exactly as over the whole log."""
    return t[lo:hi] - t[0] - period * np.arange(lo, hi)


def _candidates(t: np.ndarray, period: float, floor: np.ndarray, size: int) -> np.ndarray:
    """Long steps (index of the sample before each) in the blocks where the envelope `floor` rises,
    in the order they are judged: the longest first, then the shorter ones in time order."""
    rise = np.flatnonzero(np.diff(floor) >= 0.5 * period)
    if not len(rise):
        return np.empty(0, dtype=np.int64)
    n = len(t)
    spans = [(int(a) * size, min(n - 1, (int(a) + 2) * size)) for a in rise]
    likely = distinct(np.concatenate(
        [a + np.flatnonzero(t[a + 1:b + 1] - t[a:b] > CANDIDATE_STEP * period) for a, b in spans]))
    step = t[likely + 1] - t[likely]
    long_first = likely[step >= LATE_STEP * period]
    return np.concatenate([long_first[np.argsort(-(t[long_first + 1] - t[long_first]), kind="stable")],
                           likely[step < LATE_STEP * period]])


class Found:
    """Gaps found so far, and the samples lost up to any sample (cumulative, whole numbers)."""

    def __init__(self):
        self.gaps: list[Gap] = []
        self._index, self._total = np.empty(0, dtype=np.int64), np.zeros(1)

    def add(self, gap: Gap) -> None:
        self.gaps = sorted([*self.gaps, gap], key=lambda g: g.index)
        self._index = np.array([g.index for g in self.gaps], dtype=np.int64)
        self._total = np.concatenate(([0.0], np.cumsum([float(g.lost) for g in self.gaps])))

    def upto(self, at) -> np.ndarray:
        """Samples lost before or at each sample number in `at`."""
        if not self.gaps:
            return np.zeros(np.shape(at))
        return self._total[np.searchsorted(self._index, at, side="right")]

    def upto_range(self, lo: int, hi: int) -> np.ndarray:
        """:meth:`upto` of the sample numbers ``lo:hi``, a step function laid out by its steps."""
        first, last = np.searchsorted(self._index, [lo, hi - 1], side="right")
        edges = np.concatenate(([lo], self._index[first:last], [hi]))
        return np.repeat(self._total[first:last + 1], np.diff(edges))


def _window_floors(t: np.ndarray, period: float, found: Found, i: np.ndarray, base: np.ndarray,
                   size: int) -> tuple[np.ndarray, np.ndarray]:
    """Least-delayed levels (:func:`least_delayed`) of the `size` samples up to and after each step ``i -> i + 1``.

    The residual is the clock residual less ``period (lost - base)`` (the samples found lost since the
    window's start). Steps that share a `base` and lie close together are judged on one stretch of it at
    once, by a rank filter (each window's tenth, the very value :func:`least_delayed` picks); isolated ones
    window by window.
    """
    k, half = size // 10, size // 2
    before, after = np.empty(len(i)), np.empty(len(i))
    order = np.lexsort((i, base))
    cut = np.flatnonzero((np.diff(base[order]) != 0) | (np.diff(i[order]) > 2 * size)) + 1
    for part in np.split(order, cut):
        a, b = int(i[part[0]]) - size + 1, int(i[part[-1]]) + 1 + size
        stretch = residual(t, period, a, b) - period * (found.upto_range(a, b) - base[part[0]])
        first, second = i[part] - size + 1 - a, i[part] + 1 - a  # where each window starts in the stretch
        if b - a < 50 * len(part):  # dense: one pass of the filter over the stretch
            from scipy.ndimage import rank_filter

            level = rank_filter(stretch, k, size=size, mode="nearest")
            before[part], after[part] = level[first + half], level[second + half]
        else:
            ahead = np.arange(size)
            before[part] = np.partition(stretch[first[:, None] + ahead], k, axis=1)[:, k]
            after[part] = np.partition(stretch[second[:, None] + ahead], k, axis=1)[:, k]
    return before, after


def _judge(t: np.ndarray, period: float, found: Found, steps: np.ndarray, size: int) -> np.ndarray:
    """Samples lost across each step ``steps[j] -> steps[j] + 1`` (0: none), given the gaps `found` so far.

    Each step is judged on the clock residual within `size` samples before and after it, less the
    samples already found lost there, as the levels its least-delayed samples show; the steps well
    inside the log all at once, those near its ends one by one (their windows are shorter).
    """
    n, out = len(t), np.zeros(len(steps), dtype=np.int64)
    inner = (steps >= size - 1) & (steps + 1 + size <= n)
    for j in np.flatnonzero(~inner):
        i = int(steps[j])
        lo, hi = max(0, i - size + 1), min(n, i + 1 + size)
        adj = residual(t, period, lo, hi) - period * (found.upto_range(lo, hi) - (found.upto(lo - 1) if lo else 0.0))
        before = least_delayed(adj[: i + 1 - lo])
        gone = int(np.rint((least_delayed(adj[i + 1 - lo:]) - before) / period))
        # the step from a late sample is short by that sample's delay: count it in the room
        room = int(np.rint((float(t[i + 1] - t[i]) + max(0.0, adj[i - lo] - before)) / period))
        out[j] = gone if 1 <= gone <= room else 0
    i = steps[inner]
    if len(i):
        lo = i - size + 1
        base = np.where(lo > 0, found.upto(lo - 1), 0.0)
        before, after = _window_floors(t, period, found, i, base, size)
        gone = np.rint((after - before) / period)
        late = t[i] - t[0] - period * i - period * (found.upto(i) - base) - before  # delay of the sample before
        room = np.rint((t[i + 1] - t[i] + np.maximum(0.0, late)) / period)
        out[inner] = np.where((gone >= 1) & (gone <= room), gone, 0)
    return out


#: Steps judged at once; after each gap found, the next ones are judged again with it taken out.
_JUDGED = 512


def find_gaps(t: np.ndarray, period: float, floor: np.ndarray, size: int) -> Found:
    """Real gaps: long steps across which the lower envelope of the clock residual rises for good.

    Blocks whose least-delayed level (`floor`, blocks of `size`) rises by half a period over the
    block before hold the candidates. Each long step there is confirmed by the least-delayed level
    (a low quantile, so that a few delayed samples at a gap's edge do not count) just before and
    just after it, with the gaps already found taken out: the longest steps first, then the shorter
    ones in time order, so that a burst's long step right after a real gap is judged with that gap
    removed. A step must also be long enough to hold the samples it lost (counting the delay of
    the sample before it, which shortens the step).
    """
    order = _candidates(t, period, floor, size)
    found, pos = Found(), 0
    while pos < len(order):  # in order, a batch at a time; a gap found changes the judgement of those after it
        batch = order[pos:pos + _JUDGED]
        gone = _judge(t, period, found, batch, size)
        hit = np.flatnonzero(gone)
        if not len(hit):
            pos += len(batch)
            continue
        i = int(batch[hit[0]])
        found.add(Gap(i + 1, float(t[i + 1] - t[i]), int(gone[hit[0]])))
        pos += int(hit[0]) + 1
    return found
