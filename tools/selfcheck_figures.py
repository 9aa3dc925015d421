"""Print the figures docs/selfcheck.md quotes: each defect of real recordings, simulated, with and without the checks.

Run by hand:  python tools/selfcheck_figures.py [--draws 100]

Every figure is a seeded Monte Carlo against the simulator's truth (MPU9250 errors of the servo method
of Wang et al., Table III). ``z`` is error / reported 1-sigma of the three scale factors; its RMS is 1
when the 1-sigma is right (sd of the RMS over M draws: 1 / sqrt(6 M)).
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from gyrocal.errors import SegmentationError
from gyrocal.models import ScaleBias
from gyrocal.pipeline import calibrate
from gyrocal.recording import Recording
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.servo import ServoProtocol, simulate_servo
from gyrocal.simulation.timestamps import ReceiveClock, with_time_defects

K = np.array([1.0069, 0.9960, 0.9955])
B = np.array([0.0442, -0.0089, 0.0076])


def _z(run):
    return (run.fit.model.k - K) / run.fit.std[:3]


def _rms(z) -> float:
    return float(np.sqrt(np.mean(np.square(z))))


def ripple(draws: int) -> None:
    """5 % speed ripple at 2.5 Hz, 120 deg/s, 200 Hz, 0.01 rad/s noise, with --speed."""
    gyro = VirtualGyro(ScaleBias(K, B), noise_std=0.01)
    z_on, z_off, ratio = [], [], []
    for seed in range(draws):
        p = ServoProtocol(speed=math.radians(120), ripple=0.05, ripple_freq=2.5, vibration=0, misalignment_deg=3)
        rec, _ = simulate_servo(gyro, p, rng=np.random.default_rng(seed))
        on = calibrate(rec, speed=math.radians(120))
        off = calibrate(rec, speed=math.radians(120), checks=False, long_run=False)
        z_on.append(_z(on))
        z_off.append(_z(off))
        ratio.append(on.fit.std[:3] / off.fit.std[:3])
    print(f"ripple 5 % at 2.5 Hz, 120 deg/s, {draws} sessions: RMS z {_rms(z_on):.2f} (max |z| "
          f"{np.abs(z_on).max():.1f}), sigma {np.mean(ratio):.2f}x (at most {np.max(ratio):.2f}x) the white-noise one; "
          f"without the checks RMS z {_rms(z_off):.2f} (max {np.abs(z_off).max():.1f})")


def bursty(draws: int) -> None:
    """Receive-time stamps (3/17 ms bursts, 6 late packets a minute) at 100 Hz, --angle 360."""
    gyro = VirtualGyro(ScaleBias(K, B), noise_std=0.01)
    clock = ReceiveClock(packet=2, read_time=0.0035, jitter=0.003, late_per_minute=6, late_delay=0.08)
    err_on, err_off, z_on, z_off = [], [], [], []
    for seed in range(draws):
        rng = np.random.default_rng(seed)
        rec, _ = simulate_servo(gyro, ServoProtocol(misalignment_deg=3), sample_rate=100, rng=rng)
        stamped, _ = with_time_defects(rec, rng, clock=clock)
        on = calibrate(stamped, angle=2 * math.pi)
        off = calibrate(stamped, angle=2 * math.pi, checks=False, long_run=False)
        err_on.append(on.fit.model.k / K - 1)
        err_off.append(off.fit.model.k / K - 1)
        z_on.append(_z(on))
        z_off.append(_z(off))
    print(f"bursty receive stamps, {draws} sessions: max |k error| {np.abs(err_on).max():.1e} (RMS z "
          f"{_rms(z_on):.2f}) with the sensor clock rebuilt; {np.abs(err_off).max():.1e} (RMS z {_rms(z_off):.2f}) "
          "integrating on the stamps as they are (the nominal rate is the mean one either way)")


def gaps(draws: int) -> None:
    """Six 169 ms packet gaps in a 100 Hz log with receive stamps, --angle 360."""
    gyro = VirtualGyro(ScaleBias(K, B), noise_std=0.01)
    clock = ReceiveClock(packet=2, read_time=0.0035, jitter=0.003, late_per_minute=6, late_delay=0.08)
    z, found, kept, dropped, refused = [], 0, 0, 0, 0
    for seed in range(draws):
        rng = np.random.default_rng(seed)
        rec, _ = simulate_servo(gyro, ServoProtocol(misalignment_deg=3), sample_rate=100, rng=rng)
        gappy, truth = with_time_defects(rec, rng, clock=clock, gaps=6, gap_length=0.169)
        try:
            run = calibrate(gappy, angle=2 * math.pi)
        except SegmentationError:
            refused += 1
            continue
        found += [(g.lost) for g in run.time_base.gaps] == [17] * 6
        dropped += sum(r.startswith("gap") for _, r in run.segmentation.ignored)
        kept += sum(bool(run.time_base.gaps_in(w.start, w.stop)) for w in run.segmentation.rotations)
        z.append(_z(run))
    print(f"six 169 ms gaps, {draws} sessions: all 6 found with 17 samples each in {found} of {draws - refused}; "
          f"turns kept with a bounded angle {kept}, left out {dropped}; {refused} sessions refused (both turns "
          f"about an axis hit); RMS z {_rms(z):.2f}")


def sample_rate() -> None:
    """A 20 Hz log declared 25 Hz (no time column), --angle 360."""
    gyro = VirtualGyro(ScaleBias(K, B), noise_std=0.035)
    rec, _ = simulate_servo(gyro, ServoProtocol(speed=math.radians(25)), sample_rate=20, rng=np.random.default_rng(1))
    run = calibrate(Recording.from_rate(rec.gyro, 25.0), angle=2 * math.pi)
    print(f"20 Hz declared 25 Hz: k {np.round(run.fit.model.k, 3).tolist()}; warning: {run.warnings[0]}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--draws", type=int, default=100)
    args = parser.parse_args()
    ripple(args.draws)
    bursty(args.draws)
    gaps(args.draws)
    sample_rate()


if __name__ == "__main__":
    main()
