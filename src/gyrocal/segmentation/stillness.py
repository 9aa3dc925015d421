"""Is a log still? Motion found in block means and block spreads, robust to slow drift.

A noise analysis (Allan deviation) or a bias-versus-temperature fit needs a sensor at
rest, but the bias of a warming MEMS gyro drifts by many noise units over minutes. So
the test is local: the data are cut into blocks (1 s by default), and a block moves when

* its mean leaves the running median of the block means (a few minutes wide) by more than
  `nsigma` robust standard deviations of that difference, on any axis; a running median
  follows a monotone drift exactly (the median of a monotone window is its middle), so a
  warm-up is not motion, while a turn, a tilt or a knock is; or
* its mean differs from the previous block's by more than `nsigma` sigmas of that difference
  (a tilt left in place, or a bias jump: steps the running median would follow); or
* its spread exceeds `spread_factor` times the typical block spread (vibration, or a
  back-and-forth whose mean cancels inside the block).

Every input channel is tested (gyro, and the accelerometer when there is one, where a tilt
shows as a change of the gravity components).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import median
from .._validation import finite_array, positive
from ..errors import InputError
from ..units import MAD_TO_SIGMA

__all__ = ["Stillness", "find_motion"]


@dataclass(frozen=True)
class Stillness:
    """Where a log moves.

    Attributes
    ----------
    n : int
        Samples in the log.
    block : int
        Samples per block.
    moving : ndarray of bool, shape (B,)
        Whether each block moves.
    spans : ndarray of int, shape (K, 2)
        ``start, stop`` sample indices of each motion, padded by one block each side.
    """

    n: int
    block: int
    moving: np.ndarray
    spans: np.ndarray

    @property
    def still(self) -> bool:
        """True when no motion was found."""
        return len(self.spans) == 0

    @property
    def still_runs(self) -> np.ndarray:
        """``(R, 2)`` start/stop sample indices of the stretches between motions."""
        edges = np.concatenate(([0], self.spans.ravel(), [self.n])).reshape(-1, 2)
        return edges[edges[:, 1] > edges[:, 0]]

    def longest_still(self) -> tuple[int, int]:
        """``(start, stop)`` of the longest still stretch (``(0, 0)`` when there is none)."""
        runs = self.still_runs
        if not len(runs):
            return 0, 0
        i = int(np.argmax(runs[:, 1] - runs[:, 0]))
        return int(runs[i, 0]), int(runs[i, 1])

    def describe(self, sample_rate: float, limit: int = 4) -> str:
        """``"3 motions, at 3.0-9.3 s, 12.3-18.6 s, ..."`` for messages."""
        spans = [f"{a / sample_rate:.1f}-{b / sample_rate:.1f} s" for a, b in self.spans[:limit]]
        more = ", ..." if len(self.spans) > limit else ""
        word = "motion" if len(self.spans) == 1 else "motions"
        return f"{len(self.spans)} {word}, at {', '.join(spans)}{more}"


def _block_stats(x: np.ndarray, block: int) -> tuple[np.ndarray, np.ndarray]:
    nb = len(x) // block
    b = x[: nb * block].reshape(nb, block, x.shape[1])
    mean = b.mean(axis=1)
    spread = np.sqrt(np.maximum(np.einsum("nki,nki->ni", b, b) / block - mean**2, 0.0))
    return mean, spread


def _moving_blocks(x: np.ndarray, block: int, trend: int, nsigma: float, spread_factor: float) -> np.ndarray:
    from scipy.ndimage import median_filter

    mean, spread = _block_stats(x, block)
    dev = mean - median_filter(mean, size=(trend, 1), mode="nearest")
    typical = median(spread, axis=0)
    # The robust spread of the differences, between a block mean's own white noise (the floor, for
    # quantised or very quiet data) and three times it (so a log that mostly moves cannot widen it).
    floor = typical / np.sqrt(block)
    scale = np.clip(MAD_TO_SIGMA * median(np.abs(dev), axis=0), floor, 3.0 * floor)
    scale = np.maximum(scale, 1e-12 * (np.abs(mean).max() + 1e-300))
    off_trend = np.any(np.abs(dev) > nsigma * scale, axis=1)
    # a step between neighbours (a tilt left in place, a bias jump): the median follows it, a
    # drift never moves one block mean by that much
    jump = np.zeros(len(mean), bool)
    jump[1:] = np.any(np.abs(np.diff(mean, axis=0)) > nsigma * np.sqrt(2.0) * scale, axis=1)
    shaky = np.any((spread > spread_factor * typical) & (typical > 0), axis=1)
    return off_trend | jump | shaky


def find_motion(channels, sample_rate: float, *, block_s: float = 1.0, trend_s: float = 300.0,
                nsigma: float = 8.0, spread_factor: float = 4.0) -> Stillness:
    """Find the motions of a log that should be still.

    Parameters
    ----------
    channels : array_like (N, 3), or a sequence of them
        Readings of each sensor [any units], e.g. ``[gyro, accel]``; all of length N.
    sample_rate : float
        Sampling rate [Hz].
    block_s : float
        Block length [s]; at least 10 samples.
    trend_s : float
        Width of the running median that the block means are compared with [s]; motions
        shorter than half of it are found.
    nsigma : float
        Threshold on the block mean's distance from the running median, in robust sigmas.
    spread_factor : float
        Threshold on a block's spread, in multiples of the median block spread.

    Returns
    -------
    Stillness
    """
    chans = [channels] if np.ndim(channels) == 2 else list(channels)
    arrays = [finite_array("readings", c, shape_tail=(3,), ndim=2) for c in chans]
    n = len(arrays[0])
    if any(len(a) != n for a in arrays):
        raise InputError("every channel must have the same number of samples")
    fs = positive("sample_rate", sample_rate)
    block = max(10, int(round(block_s * fs)))
    nb = n // block
    if nb < 3:
        return Stillness(n, block, np.zeros(nb, bool), np.zeros((0, 2), int))
    trend = min(nb, max(3, int(round(trend_s * fs / block)))) | 1
    moving = np.zeros(nb, bool)
    for a in arrays:
        moving |= _moving_blocks(a, block, trend, nsigma, spread_factor)
    padded = moving.copy()
    padded[1:] |= moving[:-1]
    padded[:-1] |= moving[1:]
    edges = np.flatnonzero(np.diff(np.concatenate(([0], padded.view(np.int8), [0]))))
    spans = edges.reshape(-1, 2) * block
    spans[spans[:, 1] == nb * block, 1] = n  # the tail after the last whole block goes with it
    return Stillness(n, block, moving, spans)
