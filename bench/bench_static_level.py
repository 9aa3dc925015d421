"""Peak memory and time of the standstill level on a long recording, against a whole pairwise matrix.

Run by hand:  python bench/bench_static_level.py [--samples 1000000] [--rate 200]

``segmentation._motion.static_level`` clusters the quiet 0.25 s blocks of a recording by their
mean. The naive way (and this module's way before) compares every pair of up to ~4,000 blocks
in one ``q x q`` distance matrix; now the quiet blocks at the noise floor nearest zero, at most
800, are compared 256 rows at a time. Both run here on the same simulated servo session (the servo method of Wang et al.:
six turns, repeated), with the peak memory traced (``tracemalloc``) and the best time of 3.
"""

from __future__ import annotations

import argparse
import math
import time
import tracemalloc

import numpy as np


def naive_static_level(gyro: np.ndarray, block: int, cap: int = 2000):
    """The former clustering: a floor-division cap (up to 2 x `cap` - 1 blocks) and a whole q x q matrix."""
    n = len(gyro) // block
    step = max(1, n // (250_000 // block + 1))
    b = gyro[: n * block].reshape(n, block, 3)[::step]
    mean = b.sum(axis=1) / block
    std = np.sqrt(np.maximum(np.einsum("nki,nki->ni", b, b) / block - mean**2, 0.0))
    q = np.linalg.norm(std, axis=1)
    quiet = np.flatnonzero(q <= 2.0 * np.percentile(q, 10) + 1e-300)
    quiet = quiet[:: max(1, len(quiet) // cap)]
    m, s = mean[quiet], std[quiet]
    radius = 6.0 * float(np.linalg.norm(np.median(s, axis=0))) / np.sqrt(block)
    sq = np.einsum("ij,ij->i", m, m)
    d2 = sq[:, None] + sq[None, :] - 2.0 * m @ m.T
    count = (d2 < radius**2).sum(axis=1)
    dense = np.flatnonzero(count >= max(2, 0.05 * count.max()))
    members = d2[dense[np.argmin(sq[dense])]] < radius**2
    return np.median(m[members], axis=0), len(quiet)


def measure(fn, repeat: int = 3) -> tuple[float, float]:
    """Best time [s] and peak traced memory [MiB] of `fn`."""
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    tracemalloc.start()
    fn()
    peak = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    return best, peak


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1_000_000)
    parser.add_argument("--rate", type=float, default=200.0)
    args = parser.parse_args()

    from gyrocal.models import ScaleBias
    from gyrocal.segmentation._motion import static_level
    from gyrocal.simulation import VirtualGyro
    from gyrocal.simulation.servo import PAPER_TURNS, ServoProtocol, simulate_servo

    one = ServoProtocol()
    per = (one.lead_in + 6 * (one.turn_angle / one.speed + one.ramp) + 5 * 3.0) * args.rate
    protocol = ServoProtocol(turns=PAPER_TURNS * math.ceil(args.samples / per), wait=9.0)
    gyro = VirtualGyro(ScaleBias(k=[1.0069, 0.9960, 0.9955], b=[0.0442, -0.0089, 0.0076]), noise_std=0.035)
    rec, _ = simulate_servo(gyro, protocol, sample_rate=args.rate, rng=np.random.default_rng(0))
    g = np.ascontiguousarray(rec.gyro[: args.samples])
    block = max(8, int(round(0.25 * args.rate)))
    (base_naive, q), new = naive_static_level(g, block), static_level(g, block)[0]
    t_naive, m_naive = measure(lambda: naive_static_level(g, block))
    t_new, m_new = measure(lambda: static_level(g, block))
    print(f"{len(g):,} samples at {args.rate:g} Hz, blocks of {block}: the naive way compares {q} blocks")
    print(f"naive q x q matrix: {t_naive * 1e3:.1f} ms, peak {m_naive:.1f} MiB")
    print(f"static_level:       {t_new * 1e3:.1f} ms, peak {m_new:.1f} MiB "
          f"({m_new / m_naive:.2f}x the memory, {t_new / t_naive:.2f}x the time)")
    print(f"standstill levels agree within {np.max(np.abs(new - base_naive)):.2e} rad/s")


if __name__ == "__main__":
    main()
