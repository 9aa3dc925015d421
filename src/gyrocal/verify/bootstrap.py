"""Block bootstrap of means and quantiles of long, serially correlated series.

The errors between two gyros follow the motion (a scale error is large during a turn and
absent at rest), so samples are not independent and the usual ``s / sqrt(n)`` is far too
small. The series is cut into non-overlapping blocks longer than its correlation time
(Carlstein's block bootstrap) and the blocks are resampled with replacement. The block
length comes from the automatic rule of Politis and White (2004, with the correction of
Patton, Politis and White 2009). Means resample exactly through per-block sums; quantiles
through per-block histograms on fine logarithmic bins, so a bootstrap of a
ten-million-sample log costs one pass over the data.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["BlockBootstrap", "optimal_block_length"]

_HIST_BINS = 2000
#: Most blocks: shorter blocks are merged up to ``n / MAX_BLOCKS`` samples, which keeps the
#: histograms small and costs nothing in validity (longer blocks only add correlation).
MAX_BLOCKS = 1000


def _autocovariance(x: np.ndarray, max_lag: int) -> np.ndarray:
    """Biased autocovariance of `x` at lags 0..max_lag, by FFT."""
    n = len(x)
    x = x - x.mean()
    size = 1 << (2 * n - 1).bit_length()
    f = np.fft.rfft(x, size)
    return np.fft.irfft(f * np.conj(f), size)[: max_lag + 1] / n


def optimal_block_length(x: np.ndarray) -> int:
    """Block length [samples] for a circular block bootstrap of the mean of `x` (Politis and White).

    The correlation is read up to the first lag ``m`` after which ``K`` consecutive
    autocorrelations stay inside ``2 sqrt(log10(n) / n)``; a flat-top lag window of width
    ``2 m`` then estimates the two spectral quantities of the optimal length
    ``(2 G**2 / D)**(1/3) n**(1/3)``. White noise gives 1.
    """
    x = np.asarray(x, dtype=float)
    n = len(x)
    if n < 8:
        return 1
    kn = max(5, math.ceil(math.sqrt(math.log10(n))))
    max_lag = min(n - 1, math.ceil(math.sqrt(n)) + kn)
    acov = _autocovariance(x, max_lag)
    if acov[0] <= 0:
        return 1
    inside = np.abs(acov / acov[0]) < 2.0 * math.sqrt(math.log10(n) / n)
    m_hat = max_lag - kn
    for m in range(max_lag - kn):
        if inside[m + 1:m + 1 + kn].all():
            m_hat = m
            break
    big_m = min(2 * m_hat, max_lag)
    if big_m == 0:
        return 1
    k = np.arange(1, big_m + 1)
    s = k / big_m
    lam = np.where(s <= 0.5, 1.0, 2.0 * (1.0 - s))  # flat-top window
    g = 2.0 * float(np.sum(lam * k * acov[1:big_m + 1]))
    g0 = float(acov[0] + 2.0 * np.sum(lam * acov[1:big_m + 1]))
    if g0 <= 0:
        return 1
    d = 4.0 / 3.0 * g0**2  # circular block bootstrap
    b = (2.0 * g * g / d) ** (1.0 / 3.0) * n ** (1.0 / 3.0)
    return int(min(max(round(b), 1), n))


class BlockBootstrap:
    """Resampling of the blocks of one series length, shared by every statistic of it.

    Parameters
    ----------
    n : int
        Length of the series [samples].
    block : int
        Block length [samples]; blocks are consecutive, the last may be shorter. It is
        raised to ``n / MAX_BLOCKS`` when shorter.
    replicates : int
        Number of bootstrap replicates.
    rng : numpy.random.Generator
    """

    def __init__(self, n: int, block: int, replicates: int, rng: np.random.Generator):
        self.n = int(n)
        self.block = int(min(max(block, math.ceil(n / MAX_BLOCKS), 1), n))
        self.starts = np.arange(0, self.n, self.block)
        nb = len(self.starts)
        self.counts = np.diff(np.append(self.starts, self.n)).astype(float)
        self.weights = rng.multinomial(nb, np.full(nb, 1.0 / nb), size=replicates).astype(float)

    @property
    def blocks(self) -> int:
        """Number of blocks."""
        return len(self.starts)

    def means(self, x: np.ndarray) -> np.ndarray:
        """Bootstrap replicates (B, k) of the column means of `x` (n, k)."""
        sums = np.add.reduceat(np.asarray(x, dtype=float), self.starts, axis=0)
        return (self.weights @ sums) / (self.weights @ self.counts)[:, None]

    def quantiles(self, x: np.ndarray, q: float) -> np.ndarray:
        """Bootstrap replicates (B,) of the `q`-quantile (0..1) of the non-negative series `x` (n,)."""
        x = np.asarray(x, dtype=float)
        top = float(x.max())
        if top <= 0:
            return np.zeros(len(self.weights))
        floor = max(float(np.quantile(x, 0.5 * q)), top * 1e-9)  # the q-quantile lies above this
        edges = np.concatenate([[0.0], np.geomspace(floor, top * (1 + 1e-12), _HIST_BINS)])
        bins = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, len(edges) - 2)
        block_of = np.repeat(np.arange(self.blocks), self.counts.astype(int))
        hist = np.bincount(block_of * (len(edges) - 1) + bins, minlength=self.blocks * (len(edges) - 1))
        cum = np.cumsum(self.weights @ hist.reshape(self.blocks, -1), axis=1)
        target = q * cum[:, -1]
        j = np.argmax(cum >= target[:, None], axis=1)  # bin holding the quantile
        below = np.where(j > 0, cum[np.arange(len(j)), j - 1], 0.0)
        inside = cum[np.arange(len(j)), j] - below
        frac = np.where(inside > 0, (target - below) / np.where(inside > 0, inside, 1.0), 0.0)
        return edges[j] + frac * (edges[j + 1] - edges[j])
