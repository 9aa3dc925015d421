"""Time reading a large CSV recording: pyarrow's parser alone vs ``gyrocal.io.read_recording``.

Run by hand:  python bench/bench_read.py [--samples 10000000] [--repeat 3]

Writes a servo-like recording (t, gx, gy, gz in deg/s, 1 kHz, six observations per
protocol repeated) to a temporary folder, then times, in the same process:

* baseline: ``pyarrow.csv.read_csv(path)``, the parse alone (it infers the column types);
* for reference, the same parse told the four columns are float64, as gyrocal does;
* gyrocal: ``read_recording(path, units="deg/s")`` (parse, checks, unit conversion);
* when ``gyrocal.pipeline`` exists: read + segment + calibrate with ``--speed``.

Prints the best wall and CPU time of `repeat` rounds of each (they take turns within a
round) and their ratios to the baseline.
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path

import numpy as np


def servo_signal(n: int, rate_hz: float, rng: np.random.Generator) -> dict[str, np.ndarray]:
    """Six 60 deg/s turns (+-x, +-y, +-z) with 3 s rests, repeated, MPU-like noise and quantisation [deg/s]."""
    speed, rest = 60.0, 3.0
    turn = 360.0 / speed
    period = 6 * (turn + rest)
    t = np.arange(n) / rate_hz
    phase = np.mod(t, period)
    slot = np.minimum((phase // (turn + rest)).astype(int), 5)
    turning = phase - slot * (turn + rest) < turn
    w = np.zeros((n, 3))
    w[np.arange(n), slot // 2] = np.where(turning, speed * np.where(slot % 2 == 0, 1.0, -1.0), 0.0)
    m = 1.01 * w + np.array([0.5, -0.3, 0.2]) + rng.normal(0.0, 0.05, (n, 3))
    m = np.round(m * 16.4) / 16.4  # MPU-9250 at +-2000 deg/s: 16.4 LSB per deg/s
    return {"t": np.round(t, 6), "gx": m[:, 0], "gy": m[:, 1], "gz": m[:, 2]}


def best_times(fns: dict, repeat: int) -> dict[str, tuple[float, float]]:
    """Shortest wall time and shortest CPU time (all threads) of each function over `repeat` rounds [s].

    The functions take turns within each round, so a busy machine slows them alike; CPU
    time is the steadier figure on a shared machine. Each result is dropped before the next call.
    """
    best = {name: (math.inf, math.inf) for name in fns}
    for _ in range(repeat):
        for name, fn in fns.items():
            w0, c0 = time.perf_counter(), time.process_time()
            fn()
            wall, cpu = time.perf_counter() - w0, time.process_time() - c0
            best[name] = (min(best[name][0], wall), min(best[name][1], cpu))
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=10_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    import pyarrow as pa
    import pyarrow.csv as pcsv

    from gyrocal.io import read_recording, write_csv

    rng = np.random.default_rng(1)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "servo.csv"
        t0 = time.perf_counter()
        write_csv(path, servo_signal(args.samples, 1000.0, rng))
        print(f"wrote {args.samples:,} samples, {path.stat().st_size / 1e6:.0f} MB, in {time.perf_counter() - t0:.1f} s")

        typed = pcsv.ConvertOptions(column_types=dict.fromkeys(["t", "gx", "gy", "gz"], pa.float64()))
        fns = {
            "pyarrow.csv.read_csv alone": lambda: pcsv.read_csv(path),
            "  same, types declared": lambda: pcsv.read_csv(path, convert_options=typed),
            "gyrocal read_recording": lambda: read_recording(path, units="deg/s"),
        }
        try:
            from gyrocal.pipeline import calibrate

            fns["read + segment + calibrate"] = lambda: calibrate(read_recording(path, units="deg/s"), speed=math.radians(60.0))
        except ImportError:
            print("gyrocal.pipeline not available: read + segment + calibrate not timed")
        from gyrocal.errors import GyrocalError

        try:
            best = best_times(fns, args.repeat)
        except GyrocalError as exc:
            print(f"read + segment + calibrate failed: {exc}")
            del fns["read + segment + calibrate"]
            best = best_times(fns, args.repeat)
        base_wall, base_cpu = best["pyarrow.csv.read_csv alone"]
        print(f"{'':28s}  {'wall [s]':>8s} {'ratio':>6s}   {'CPU [s]':>8s} {'ratio':>6s}")
        for name, (wall, cpu) in best.items():
            print(f"{name:28s}: {wall:8.3f} {wall / base_wall:6.2f}   {cpu:8.3f} {cpu / base_cpu:6.2f}")


if __name__ == "__main__":
    main()
