#!/usr/bin/env python3
"""Measure how well the noise intervals and the thermal-bias 1-sigma hold, over seeded simulations.

Prints the figures quoted in docs/flight.md:

* coverage of the 1-sigma intervals of the white-noise density and of the random walk (white
  noise plus a bias random walk, 20 min at 100 Hz, 3 axes x SEEDS logs): the fraction of
  intervals that hold the simulated truth, nominally 0.683;
* RMS of (fit - truth) / reported 1-sigma of the thermal-bias curve (45-min warm-up from -10 to
  50 degC, whole-degree temperature readings) at 7 temperatures, with and without a
  Gauss-Markov bias wander (2e-4 rad/s, 100 s), nominally 1.

Usage::

    python tools/flight_figures.py [--seeds 40]
"""

from __future__ import annotations

import argparse
import math
import time
import warnings

import numpy as np

from gyrocal.flight import fit_thermal_bias
from gyrocal.models import ScaleBias
from gyrocal.noise import characterise
from gyrocal.simulation import BiasDrift, StillProtocol, VirtualGyro, simulate_still

FS = 100.0


def noise_coverage(seeds: int) -> tuple[float, float, int, int]:
    sigma, walk, n = 0.005, 2e-4, int(1200 * FS)
    density_hits, walk_hits = [], []
    for seed in range(seeds):
        rng = np.random.default_rng(seed)
        g = rng.standard_normal((n, 3)) * sigma + np.cumsum(rng.standard_normal((n, 3)) * walk / math.sqrt(FS), 0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = characterise(g, FS)
        d, w = r.gyro.density, r.gyro.random_walk
        truth = sigma / math.sqrt(FS)
        density_hits.extend((d.low[:3] <= truth) & (truth <= d.high[:3]))
        seen = np.isfinite(w.value[:3])
        walk_hits.extend((w.low[:3][seen] <= walk) & (walk <= w.high[:3][seen]))
    return float(np.mean(density_hits)), float(np.mean(walk_hits)), len(density_hits), len(walk_hits)


def thermal_z(seeds: int, bias_instability: float) -> float:
    coefs = np.array([[0.01, 2e-4, -3e-6, 5e-8], [-0.02, -1e-4, 0.0, 0.0], [0.005, 3e-5, 2e-6, 0.0]])
    drift = BiasDrift(coefs, 25.0)
    proto = StillProtocol(duration=2700.0, temp_start=-10.0, temp_end=50.0, temp_tau=600.0, temp_quantum=1.0)
    z = []
    for seed in range(seeds):
        gyro = VirtualGyro(ScaleBias(np.ones(3), np.zeros(3)), noise_std=0.005, bias_instability=bias_instability,
                           bias_tau=100.0, thermal=drift)
        rec, _ = simulate_still(gyro, proto, sample_rate=FS, rng=np.random.default_rng(seed))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            tb = fit_thermal_bias(rec.gyro, rec.temp, FS)
        temps = np.linspace(tb.tmin, tb.tmax, 7)
        z.append((tb.bias_at(temps) - drift.bias(temps)) / tb.std_at(temps))
    return float(np.sqrt(np.mean(np.square(z))))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=40)
    args = parser.parse_args()
    start = time.perf_counter()
    cov_d, cov_w, n_d, n_w = noise_coverage(args.seeds)
    print(f"noise density: {cov_d:.3f} of {n_d} 1-sigma intervals hold the truth (nominal 0.683)")
    print(f"random walk:   {cov_w:.3f} of {n_w} 1-sigma intervals hold the truth (nominal 0.683)")
    for bi in (0.0, 2e-4):
        print(f"thermal bias, Gauss-Markov wander {bi:g} rad/s: RMS (fit - truth) / sigma = "
              f"{thermal_z(args.seeds, bi):.2f} over {args.seeds} logs x 3 axes x 7 temperatures (nominal 1)")
    print(f"{time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
