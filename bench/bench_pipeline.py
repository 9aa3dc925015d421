"""Time read + segment + calibrate of a 10-million-sample CSV against pyarrow's parse alone.

Run by hand:  python bench/bench_pipeline.py [--samples 10000000] [--repeat 3]

Simulates a long servo session (the servo method's six turns at 60 deg/s, ramps, vibration,
5 deg misalignment, MPU9250 errors of Table III, repeated) at 1 kHz, writes it as a
CSV ``t, gx, gy, gz`` in deg/s to a temporary folder, then times in the same process:

* baseline: ``pyarrow.csv.read_csv(path)``, the parse alone;
* gyrocal: ``read_recording`` + ``calibrate(--speed 60)`` (which segments), with the
  segmentation also timed on its own, and the calibration also with the straightforward
  implementations its fast paths replaced (``tests/naive_selfcheck.py``).

Baseline and pipeline runs alternate; prints the best of `repeat` runs of each, the ratio
to the baseline (target <= 1.5), and each run's ratio to the parse just before it.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import naive_selfcheck  # noqa: E402  (the straightforward calibration, for the before/after line)


def best_time(fn, repeat: int) -> tuple[float, object]:
    """Shortest wall time of `repeat` calls [s], and the last result."""
    best, out = math.inf, None
    for _ in range(repeat):
        out = None
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def write_session(path: Path, samples: int, rate: float, seed: int) -> None:
    import pyarrow as pa
    import pyarrow.csv as pacsv

    from gyrocal.models import ScaleBias
    from gyrocal.simulation import VirtualGyro
    from gyrocal.simulation.servo import PAPER_TURNS, ServoProtocol, simulate_servo

    one = ServoProtocol(misalignment_deg=5.0)
    per_protocol = (one.lead_in + 6 * (one.turn_angle / one.speed + one.ramp) + 5 * 3.0) * rate
    repeats = math.ceil(samples / per_protocol)
    protocol = ServoProtocol(turns=PAPER_TURNS * repeats, misalignment_deg=5.0, lead_out=0.0)
    gyro = VirtualGyro(ScaleBias(k=[1.0069, 0.9960, 0.9955], b=[0.0442, -0.0089, 0.0076]), noise_std=0.035)
    rec, _ = simulate_servo(gyro, protocol, sample_rate=rate, rng=np.random.default_rng(seed))
    n = min(samples, len(rec))
    deg = np.degrees(rec.gyro[:n])
    table = pa.table({"t": np.round(rec.t[:n], 6), "gx": deg[:, 0], "gy": deg[:, 1], "gz": deg[:, 2]})
    pacsv.write_csv(table, path, pacsv.WriteOptions(include_header=True))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=10_000_000)
    parser.add_argument("--rate", type=float, default=1000.0, help="sample rate [Hz]")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    import pyarrow.csv as pacsv

    from gyrocal.io import read_recording
    from gyrocal.pipeline import calibrate
    from gyrocal.segmentation import segment

    speed = math.radians(60.0)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "session.csv"
        t0 = time.perf_counter()
        write_session(path, args.samples, args.rate, seed=1)
        print(f"wrote {args.samples:,} samples ({path.stat().st_size / 1e6:.0f} MB) in {time.perf_counter() - t0:.1f} s")

        # Baseline and pipeline alternate, so a busy machine slows both alike; best of each is reported.
        parse, full, pairs = math.inf, math.inf, []
        for _ in range(args.repeat):
            tp, _ = best_time(lambda: pacsv.read_csv(path), 1)
            tf, run = best_time(lambda: calibrate(read_recording(path, units="deg/s"), speed=speed), 1)
            parse, full = min(parse, tp), min(full, tf)
            pairs.append(tf / tp)
        t_read, rec = best_time(lambda: read_recording(path, units="deg/s"), args.repeat)
        t_seg, seg = best_time(lambda: segment(rec, reference="speed", speed=speed), args.repeat)
        t_cal, _ = best_time(lambda: calibrate(rec, speed=speed), args.repeat)
        with naive_selfcheck.installed():  # the straightforward implementations the fast paths replaced
            t_naive, _ = best_time(lambda: calibrate(rec, speed=speed), args.repeat)

    print(f"pyarrow.csv.read_csv alone      {parse:7.3f} s   (baseline)")
    print(f"read_recording                  {t_read:7.3f} s   {t_read / parse:5.2f}x")
    print(f"segment (speed reference)       {t_seg:7.3f} s   {t_seg / parse:5.2f}x")
    print(f"calibrate (segment + fit)       {t_cal:7.3f} s   {t_cal / parse:5.2f}x")
    print(f"  the same, straightforward     {t_naive:7.3f} s   {t_naive / parse:5.2f}x   (tests/naive_selfcheck.py: "
          f"{t_naive / t_cal:.1f}x the time)")
    print(f"read + segment + calibrate      {full:7.3f} s   {full / parse:5.2f}x   (target <= 1.5)")
    print("paired ratios (each run against the parse just before it): " + ", ".join(f"{r:.2f}" for r in pairs))
    print(f"{len(seg.rotations)} rotations, {len(seg.statics)} static windows; k = "
          + ", ".join(f"{v:.5f}" for v in run.fit.model.k))


if __name__ == "__main__":
    main()
