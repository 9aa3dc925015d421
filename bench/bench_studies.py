"""Time the studies at the paper's full size, and the fast path against the per-sample path.

Run by hand: ``python bench/bench_studies.py [--subset 100]``. Prints

* ``servo-speed`` at full size (28 speeds x 15,000 calibrations x 2 noise levels =
  840,000 calibrations at 200 Hz), figures and tables included;
* the same calibrations by the per-sample path, timed on ``--subset`` calibrations per
  speed (all 28 speeds, one noise level: the cost does not depend on the noise) and
  extrapolated linearly to the full size, and the speed-up;
* ``servo-normal`` at full size (30 gyros x 500 reps x 2 noise levels x 3 estimators).
"""

from __future__ import annotations

import argparse
import tempfile
import time

import numpy as np

from gyrocal.simulation.fast import simulate_observations
from gyrocal.studies import run_study
from gyrocal.studies._common import ServoSettings, draw_truth, fit_errors
from gyrocal.studies.servo_speed import PAPER_SPEEDS


def per_sample_time(subset: int, settings: ServoSettings) -> float:
    """Seconds to simulate and fit `subset` calibrations per speed, per-sample path, one noise level."""
    rng = np.random.default_rng(1)
    k, b = draw_truth("normal", subset, rng)
    start = time.perf_counter()
    for speed in PAPER_SPEEDS:
        obs = simulate_observations(k, b, speed=speed, sample_rate=settings.sample_rate, noise_std=0.035,
                                    jitter=settings.jitter, misalignment=settings.misalignment, rng=rng, fast=False)
        fit_errors("algorithm1", obs, k, b)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--subset", type=int, default=100, help="per-sample calibrations per speed (baseline)")
    args = parser.parse_args()
    settings = ServoSettings()
    full = 30 * 500
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        run_study("servo-speed", f"{tmp}/speed")
        t_speed = time.perf_counter() - t0
        t_slow = per_sample_time(args.subset, settings) * (full / args.subset) * len(settings.noise_levels)
        t0 = time.perf_counter()
        run_study("servo-normal", f"{tmp}/normal")
        t_normal = time.perf_counter() - t0
    n = len(PAPER_SPEEDS) * full * len(settings.noise_levels)
    print(f"servo-speed full size ({n:,} calibrations, fast path, with figures): {t_speed:.2f} s")
    print(f"per-sample path, extrapolated from {args.subset} calibrations per speed: {t_slow:.0f} s")
    print(f"speed-up of the fast path: {t_slow / t_speed:.0f}x")
    print(f"servo-normal full size (30 x 500 x 2 noise levels x 3 estimators, with figures): {t_normal:.2f} s")


if __name__ == "__main__":
    main()
