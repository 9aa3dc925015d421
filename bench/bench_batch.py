"""Batch speed of the six-observation estimators (target >= 1,000,000 calibrations/s, README's measured figures).

Run by hand:  .venv/bin/python bench/bench_batch.py [--batch 1000000] [--repeat 3]

Window means are drawn directly from their distribution (noise-free means of the
paper's protocol plus Gaussian noise of sd sigma / sqrt(n)); the estimators see only
window reductions, so this is what a production line or a Monte Carlo study feeds them.
Each timing is the best of --repeat runs. The baseline is a per-gyro loop of
scipy.optimize.least_squares on the same first-moment equations, timed on a subset in
the same process and extrapolated per gyro.
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numpy as np

from gyrocal.estimators import algorithm1_batch, first_moment_batch, paper_lm_batch
from gyrocal.observations import ObservationSet
from gyrocal.simulation.windows import PAPER_AXES, axis_vector

SPEED, FS, SIGMA = math.pi / 3, 200.0, 0.035


def window_means(B: int, rng: np.random.Generator) -> tuple[ObservationSet, np.ndarray]:
    k, b = rng.uniform(0.8, 1.2, (B, 3)), rng.uniform(-0.1, 0.1, (B, 3))
    n = round(2 * math.pi / SPEED * FS)
    axes = np.array([axis_vector(a) for a in PAPER_AXES])
    tilt = rng.normal(0, 0.05, (B, 6, 3))
    g = SPEED * (axes + tilt - np.einsum("bwi,wi->bw", tilt, axes)[..., None] * axes)
    g *= SPEED / np.linalg.norm(g, axis=-1, keepdims=True)
    mean = g / k[:, None] - b[:, None] + rng.standard_normal((B, 6, 3)) * (SIGMA / math.sqrt(n))
    var = np.full((B, 6, 3), SIGMA**2)
    count = np.full(6, float(n))
    obs = ObservationSet(mean, mean**2 + var, var, np.full((B, 6), SPEED), count, count / FS, np.zeros(6, bool))
    return obs, np.concatenate([k, b], axis=1)


def best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def scipy_loop(obs: ObservationSet, count: int) -> float:
    """Seconds per gyro for a plain per-gyro least_squares loop (the naive baseline)."""
    from scipy.optimize import least_squares

    def fun(p, mean, rate, w):
        return (np.linalg.norm(p[:3] * (mean + p[3:]), axis=1) - rate) * w

    w = np.sqrt(obs.count)
    t = time.perf_counter()
    for i in range(count):
        least_squares(fun, np.r_[np.ones(3), np.zeros(3)], args=(obs.mean[i], obs.rate[i], w))
    return (time.perf_counter() - t) / count


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--batch", type=int, default=1_000_000)
    parser.add_argument("--lm-batch", type=int, default=100_000, help="batch for the LM-based paths")
    parser.add_argument("--baseline", type=int, default=300, help="gyros in the scipy loop")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    obs, truth = window_means(args.batch, rng)
    small = obs.take(np.arange(min(args.lm_batch, args.batch)))
    base = scipy_loop(obs, args.baseline)
    print(f"cpus: {os.cpu_count()}, batch: {args.batch:,}, best of {args.repeat}")
    print(f"baseline scipy.optimize.least_squares loop: {1 / base:,.0f} calibrations/s ({args.baseline} gyros)")
    rows = [
        ("first-moment, closed form (default)", obs, lambda o: first_moment_batch(o)),
        ("Algorithm 1 (paper)", obs, lambda o: algorithm1_batch(o)),
        ("first-moment, batched LM", small, lambda o: first_moment_batch(o, closed_form=False)),
        ("LM on the paper model", small, lambda o: paper_lm_batch(o)),
    ]
    for name, o, fn in rows:
        t = best(lambda fn=fn, o=o: fn(o), args.repeat)
        rate = o.batch_size / t
        print(f"{name:38s} {o.batch_size:>9,} in {t:7.3f} s = {rate:>12,.0f} /s  ({rate * base:,.0f}x baseline)")
    fit = first_moment_batch(obs)
    z = (fit.params - truth) / fit.std
    print(f"check: first-moment |error| / predicted sd: rms {np.sqrt((z**2).mean()):.3f} (expect ~1)")


if __name__ == "__main__":
    main()
