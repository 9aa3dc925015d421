"""What the self-checks cost: one calibration of a 1-million-sample recording with and without them.

Run by hand:  python bench/bench_selfcheck.py [--samples 1000000] [--repeat 5] [--stamps sensor|receive]

Simulates a long servo session at 1 kHz (the servo method of Wang et al.: six turns at 60 deg/s,
repeated; MPU9250 errors of Table III; ramps, vibration, 5 % speed ripple, 5 deg misalignment),
optionally with receive-time stamps, then times in the same process, alternating:

* the calibration without its self-checks, ``calibrate(rec, ..., checks=False)``: segmentation,
  window means on the stamps, the speed ripple regressed out of each plateau and long-run
  (Newey-West) variances of the window means, the fit and its covariance;
* the same with the self-checks (the default, ``checks=True``): the time base read from the
  stamps (rate, gaps, late deliveries, the sensor clock rebuilt), turns across gaps screened,
  goodness of fit with Birge scaling, plausibility of k, the ``fit`` and ``observed`` sections;
* the plain estimate, ``checks=False, long_run=False``: white-noise covariance, plain means, as
  before the self-checks existed (to show the cost of everything together).

Prints the best CPU time of `repeat` runs of each, for the speed and the angle reference, and what
the checks add, against the calibration alone and against reading the CSV plus calibrating (what
``gyrocal calibrate`` does; target: the checks cost under 10 % of a calibration).
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path

import numpy as np


def cpu_time(fn) -> float:
    """CPU time of one call [s]: this process's own, so other programs on a shared machine count less."""
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def session(samples: int, rate: float, stamps: str, seed: int):
    from gyrocal.models import ScaleBias
    from gyrocal.simulation import VirtualGyro
    from gyrocal.simulation.servo import PAPER_TURNS, ServoProtocol, simulate_servo
    from gyrocal.simulation.timestamps import ReceiveClock, with_time_defects

    one = ServoProtocol()
    per_protocol = (one.lead_in + 6 * (one.turn_angle / one.speed + one.ramp) + 5 * 3.0) * rate
    protocol = ServoProtocol(turns=PAPER_TURNS * math.ceil(samples / per_protocol), misalignment_deg=5.0,
                             ripple=0.05)
    gyro = VirtualGyro(ScaleBias(k=[1.0069, 0.9960, 0.9955], b=[0.0442, -0.0089, 0.0076]), noise_std=0.035)
    rng = np.random.default_rng(seed)
    rec, _ = simulate_servo(gyro, protocol, sample_rate=rate, rng=rng)
    if stamps == "receive":
        rec, _ = with_time_defects(rec, rng, clock=ReceiveClock(read_time=0.0003, jitter=0.0002))
    return rec


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1_000_000)
    parser.add_argument("--rate", type=float, default=1000.0)
    parser.add_argument("--repeat", type=int, default=9)
    parser.add_argument("--stamps", choices=("sensor", "receive"), default="sensor")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    from gyrocal.io import read_recording, write_recording
    from gyrocal.pipeline import calibrate

    rec = session(args.samples, args.rate, args.stamps, args.seed)
    print(f"recording: {len(rec):,} samples at {rec.sample_rate:.6g} Hz ({args.stamps} stamps); best CPU time of "
          f"{args.repeat} alternating runs each")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "session.csv"
        write_recording(path, rec, units="deg/s")
        read = min(cpu_time(lambda: read_recording(path, units="deg/s")) for _ in range(args.repeat))
    print(f"reading the CSV (read_recording): {read:.3f} s")
    for name, ref in (("speed 60 deg/s", {"speed": math.radians(60)}), ("angle 360 deg", {"angle": 2 * math.pi})):
        run = calibrate(rec, **ref)
        plain, estimate, checked = math.inf, math.inf, math.inf
        for _ in range(args.repeat):  # alternate, so that the machine's load hits all alike
            plain = min(plain, cpu_time(lambda ref=ref: calibrate(rec, checks=False, long_run=False, **ref)))
            estimate = min(estimate, cpu_time(lambda ref=ref: calibrate(rec, checks=False, **ref)))
            checked = min(checked, cpu_time(lambda ref=ref: calibrate(rec, **ref)))
        extra = checked - estimate
        print(f"{name} ({len(run.observations)} windows): calibrate {estimate:.3f} s without the self-checks, "
              f"{checked:.3f} s with them: the self-checks cost {100 * extra / estimate:.1f} % of the calibration "
              f"(target < 10 %), {100 * extra / (estimate + read):.1f} % of reading + calibrating. Everything added "
              f"to the plain estimate (self-checks, ripple and long-run variances: {checked:.3f} s against the plain "
              f"estimate's {plain:.3f} s): {100 * (checked / plain - 1):.1f} % of the calibration, "
              f"{100 * (checked - plain) / (plain + read):.1f} % of reading + calibrating")


if __name__ == "__main__":
    main()
