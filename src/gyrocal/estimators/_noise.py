"""Per-axis white-noise variance pooled from the windows, with the batch axis last.

Batch-last arrays keep every operation contiguous, which matters for the batched
closed form (:mod:`gyrocal.estimators._exact6`) that calls this chunk by chunk.
"""

from __future__ import annotations

import numpy as np


def pooled_noise_var(mean: np.ndarray, noise_var: np.ndarray, count: np.ndarray, static: np.ndarray) -> np.ndarray:
    """Noise variance (3, b) [reading units^2] from window means and variances (n, 3, b).

    Static windows are used when there are any. Otherwise each rotation window lends
    its two non-rotating axes (all but the largest mean reading), whose first
    differences hold sensor noise but no speed jitter. Windows count by their samples.
    """
    if static.any():
        w = np.broadcast_to((count * static)[:, None, None], mean.shape)
    else:
        a = np.abs(mean)
        top = np.maximum(np.maximum(a[:, 0], a[:, 1]), a[:, 2])
        w = (a < top[:, None]) * count[:, None, None]
    total = w.sum(axis=0)
    pooled = (w * noise_var).sum(axis=0) / np.where(total > 0, total, 1.0)
    # An axis never seen off-rotation borrows the mean of the others.
    fallback = pooled.sum(axis=0) / np.maximum((total > 0).sum(axis=0), 1)
    return np.where(total > 0, pooled, fallback)


def estimate_noise_var(obs) -> np.ndarray:
    """Per-axis per-sample noise variance (B, 3) [reading units^2] of an ObservationSet, from its data.

    Static windows are used when there are any. Otherwise each rotation window lends
    its two non-rotating axes, whose first differences hold sensor noise but no
    speed jitter (:func:`pooled_noise_var`).
    """
    obs = obs.as_batch()
    return pooled_noise_var(obs.mean.transpose(1, 2, 0), obs.noise_var.transpose(1, 2, 0), obs.count, obs.static).T
