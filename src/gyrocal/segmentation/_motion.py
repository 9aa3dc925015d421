"""Where a recording moves: static level, noise band and motion runs, all vectorised.

Thresholds are relative to the data (noise measured on the quietest stretches, rotation
level measured on the clearly moving samples), so readings in counts without a
sensitivity segment as well as readings in rad/s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import median, percentile

__all__ = ["Motion", "detect_motion", "runs_of", "static_level"]

_MAX_STATS = 1_000_000  # samples enough for a quantile; more only costs time
_MAX_CLUSTER = 800  # quiet blocks compared pairwise (those nearest zero, where standstill is)
_FLOOR_BLOCKS = 8  # the noise floor is the spread of the 8th quietest block (2 s of rest at 0.25 s blocks)


@dataclass(frozen=True)
class Motion:
    """Motion detected in a recording.

    Attributes
    ----------
    baseline : ndarray, shape (3,)
        Reading at standstill (minus the biases) [reading units].
    noise_std : ndarray, shape (3,)
        Per-sample noise on the quietest stretches [reading units].
    smooth : int
        Width of the centred moving average behind `level` [samples].
    level : ndarray, shape (N,)
        ``|moving_average(m) - baseline|`` [reading units].
    csum : ndarray, shape (N + 1, 3)
        Cumulative sum of ``m - baseline``; window sums are two look-ups.
    clevel : ndarray, shape (N + 1,)
        Cumulative sum of `level`.
    low, high : float
        Noise band and core threshold on `level` [reading units].
    runs : ndarray, shape (R, 2)
        ``start, stop`` of motion runs (`level` above `low` around a core above `high`), padded.
    busy : ndarray, shape (Q, 2)
        Every stretch above `low`, cores or not (for the static windows).
    """

    baseline: np.ndarray
    noise_std: np.ndarray
    smooth: int
    level: np.ndarray
    csum: np.ndarray
    clevel: np.ndarray
    low: float
    high: float
    runs: np.ndarray
    busy: np.ndarray

    def sums(self, start, stop) -> np.ndarray:
        """Sums of ``m - baseline`` over ``start:stop`` (vectorised) [reading units x samples]."""
        return self.csum[stop] - self.csum[start]

    def mean_level(self, start, stop) -> np.ndarray:
        """Mean of `level` over ``start:stop`` (vectorised)."""
        return (self.clevel[stop] - self.clevel[start]) / np.maximum(np.asarray(stop) - start, 1)


def runs_of(mask: np.ndarray) -> np.ndarray:
    """``(R, 2)`` start/stop of the True runs of a boolean array."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.view(np.int8), [0]))))
    return edges.reshape(-1, 2)


def _merge_overlaps(runs: np.ndarray) -> np.ndarray:
    if len(runs) < 2:
        return runs
    reach = np.maximum.accumulate(runs[:, 1])
    new = np.concatenate(([True], runs[1:, 0] > reach[:-1]))
    first = np.flatnonzero(new)
    last = np.concatenate((first[1:], [len(runs)])) - 1
    return np.stack([runs[first, 0], reach[last]], axis=1)


def _split_turnarounds(runs, level, labels, csum, high, min_len) -> np.ndarray:
    """Split motion runs between turns that follow each other without a static gap.

    `labels` holds the signed dominant axis of the smoothed rate (0..5), or -1 below the core
    threshold `high`. Stretches of one label lasting at least `min_len` samples are the turns;
    two consecutive ones in the same run are cut apart, at the slowest sample between them, when
    they differ in axis or sense (sizes within 4x, so a wobble is no turn) or when the rate
    between them drops below half the core threshold (one turn stopping, the next starting).
    """
    if not len(runs) or not np.isfinite(high):
        return runs
    change = np.flatnonzero(np.diff(labels)) + 1
    starts = np.concatenate(([0], change))
    stops = np.concatenate((change, [len(labels)]))
    keep = (labels[starts] >= 0) & (stops - starts >= min_len)
    s0, s1, lab = starts[keep], stops[keep], labels[starts[keep]]
    if len(s0) < 2:
        return runs
    owner = np.searchsorted(runs[:, 0], s0, side="right")
    size = np.linalg.norm(csum[s1] - csum[s0], axis=1)
    points = []
    for i in np.flatnonzero(owner[1:] == owner[:-1]):
        a, b = int(s1[i]), int(s0[i + 1])
        dip = level[a:b].min() if b > a else np.inf
        comparable = min(size[i], size[i + 1]) >= 0.25 * max(size[i], size[i + 1])
        if (lab[i] != lab[i + 1] and comparable) or dip < high / 2:
            points.append(a + int(np.argmin(level[a:b])) if b > a else a)
    if not points:
        return runs
    pts = np.array(points)
    return np.stack([np.sort(np.concatenate((runs[:, 0], pts))), np.sort(np.concatenate((runs[:, 1], pts)))], axis=1)


def _neighbours(points: np.ndarray, radius: float, chunk: int = 256):
    """How many of `points` (q, 3) lie within `radius` of each, and a look-up of one's neighbours.

    Distances are taken `chunk` rows at a time, so memory stays at ``chunk x q`` whatever q is: a
    whole ``q x q`` matrix would be most of the peak memory of a long recording.
    """
    r2 = radius * radius

    def near(rows: slice) -> np.ndarray:
        # squared distances axis by axis: a (chunk, 3) @ (3, q) product is slow in BLAS for so few columns
        d2 = np.zeros((len(points[rows]), len(points)))
        for k in range(points.shape[1]):
            diff = np.subtract.outer(points[rows, k], points[:, k])
            d2 += diff * diff
        return d2 < r2

    count = np.concatenate([near(slice(i, i + chunk)).sum(axis=1) for i in range(0, len(points), chunk)])
    return count, lambda i: np.flatnonzero(near(slice(i, i + 1))[0])


def _block_stats(gyro: np.ndarray, block: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation (n, 3) of each of the `n` whole blocks, axis by axis.

    Every block counts: a stride over blocks steps over whole waits of a long log. Axis by axis on
    views, so a column-major log is not copied.
    """
    mean, std = np.empty((n, 3)), np.empty((n, 3))
    for k in range(3):
        col = gyro[: n * block, k].reshape(n, block)
        mean[:, k] = col.sum(axis=1) / block
        std[:, k] = np.einsum("ij,ij->i", col, col) / block
    np.sqrt(np.maximum(std - mean**2, 0.0), out=std)
    return mean, std


def _quiet_blocks(std: np.ndarray) -> np.ndarray:
    """Indices of the blocks whose spread is at the noise floor: within 2x of the quietest few.

    The floor is the `_FLOOR_BLOCKS`-th quietest block, not a share of all blocks: rest may be a tiny
    share of a long log. Blocks frozen on an axis (saturation, repeated samples) sit below any noise
    and would set a floor no standstill reaches, so they do not set it (they may still be quiet).
    """
    q = np.linalg.norm(std, axis=1)
    live = q[(std > 0).all(axis=1)]
    if not len(live):
        live = q
    k = min(_FLOOR_BLOCKS, len(live)) - 1
    return np.flatnonzero(q <= 2.0 * np.partition(live, k)[k] + 1e-300)


def static_level(gyro: np.ndarray, block: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Baseline, per-sample noise and bias drift of the standstill blocks of `block` samples.

    Quiet blocks (spread at the noise floor) are clustered by their mean. A steady turn may be as
    quiet as standstill; of the levels seen in at least two blocks, standstill is the one nearest
    zero, since biases are small next to any calibration turn. However small a share of the log
    rest is, its blocks are all quiet and nearest zero, so they are always among those compared.
    """
    n = len(gyro) // block
    if n < 1:
        return median(gyro, axis=0), gyro.std(axis=0), 0.0
    mean, std = _block_stats(np.asarray(gyro, dtype=float), block, n)
    quiet = _quiet_blocks(std)
    m, s = mean[quiet], std[quiet]
    sq = np.einsum("ij,ij->i", m, m)
    radius = 6.0 * float(np.linalg.norm(median(s, axis=0))) / np.sqrt(block) + 1e-12 * float(np.sqrt(sq.max()))
    # compared pairwise: the quiet blocks nearest zero (standstill's among them), at most _MAX_CLUSTER
    near = np.argsort(sq, kind="stable")[:_MAX_CLUSTER]
    count, _ = _neighbours(m[near], radius)
    dense = np.flatnonzero(count >= min(int(count.max()), 2))
    centre = m[near[dense[np.argmin(sq[near[dense]])]]]
    # its members among all quiet blocks, re-centred once: the block nearest zero is on the cluster's edge
    for _ in range(2):
        members = np.flatnonzero(np.einsum("ij,ij->i", m - centre, m - centre) < radius * radius)
        centre = median(m[members], axis=0)
    base, sd = centre, median(s[members], axis=0)
    # Bias drift between pauses: the spread of the standstill levels beyond what noise explains
    # (the 90th percentile of a 3-d normal's radius is about 2.5 sigma).
    p90 = float(percentile(np.linalg.norm(m[members] - base, axis=1), 90))
    drift = max(0.0, p90 - 2.5 * float(np.sqrt(np.mean(sd**2) / block)))
    return base, sd, drift


def detect_motion(gyro: np.ndarray, sample_rate: float, *, smooth_s: float = 0.1, nsigma: float = 5.0) -> Motion:
    """Find motion runs in readings ``(N, 3)`` [any units] sampled at `sample_rate` [Hz]."""
    N = len(gyro)
    fs = float(sample_rate)
    w = max(3, int(round(smooth_s * fs)) | 1)
    base, sd, spread = static_level(gyro, max(8, int(round(0.25 * fs))))
    scale = float(np.abs(gyro[:: max(1, N // _MAX_STATS)]).max()) or 1.0
    sd = np.maximum(sd, 1e-9 * scale)  # a perfectly constant static stretch still has a band
    csum = np.empty((N + 1, 3))
    csum[0] = 0.0
    np.cumsum(gyro - base, axis=0, out=csum[1:])
    w = min(w, max(1, (N - 1) | 1))
    h = w // 2
    win = csum[w:] - csum[: N + 1 - w]  # sums of samples j:j+w, centred on j + h
    level = np.empty(N)
    level[h : N - h] = np.sqrt(np.einsum("ij,ij->i", win, win)) / w
    level[:h], level[N - h :] = level[h], level[N - h - 1]
    dominant = np.abs(win).argmax(axis=1)
    labels = np.full(N, -1, dtype=np.int8)
    labels[h : N - h] = 2 * dominant + (win[np.arange(len(win)), dominant] < 0)
    clevel = np.concatenate(([0.0], np.cumsum(level)))
    low = nsigma * float(np.sqrt(np.sum(sd**2) / w)) + 2.0 * spread
    sub = level[:: max(1, N // _MAX_STATS)]
    strong = sub[sub > 2 * low]
    high = max(2 * low, 0.2 * float(median(strong))) if len(strong) else np.inf
    above = level > low
    busy = runs_of(above)
    core = np.concatenate(([0], np.cumsum(level > high)))
    labels[level <= high] = -1
    runs = _split_turnarounds(busy[core[busy[:, 1]] - core[busy[:, 0]] > 0], level, labels, csum, high,
                              max(2, round(0.25 * fs)))
    pad = 2
    busy = _merge_overlaps(np.clip(busy + [-pad, pad], 0, N))
    if len(runs):  # pad into standstill, each run taking at most half of the gap to its neighbour
        before = runs[:, 0] - np.concatenate(([0], runs[:-1, 1]))
        after = np.concatenate((runs[1:, 0], [N])) - runs[:, 1]
        runs = np.stack([runs[:, 0] - np.minimum(pad, before - before // 2),
                         runs[:, 1] + np.minimum(pad, after // 2)], axis=1)
    return Motion(base, sd, w, level, csum, clevel, low, high, runs, busy)
