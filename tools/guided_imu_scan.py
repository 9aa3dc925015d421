"""Guided multi-position sessions over many seeds: does the guide finish, and do the uncertainties hold?

Each seed simulates a person who follows ``gyrocal capture --guide multi-position`` (the project's
hand-session simulator: a gyro mounted a few degrees off a 9-parameter accelerometer, MPU-6050 noise
and counts, poses within a few degrees of the asked ones at any heading), feeds the samples to the
guide a chunk at a time as a capture does, calibrates with the accepted poses, and compares with the
simulator's truth in units of the reported 1-sigma. Over many seeds the z-scores should have an RMS
near 1 (below 1: the uncertainty is too cautious; above: too optimistic).

Usage: .venv/bin/python tools/guided_imu_scan.py [--seeds 40] [--poses 12]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from gyrocal.capture.pose_guide import PoseGuide, guided_directions
from gyrocal.capture.simulated_imu import simulate_device_imu_session, z_scores
from gyrocal.imu.run import calibrate_recording


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--poses", type=int, default=12)
    args = ap.parse_args()
    rows, unfinished, refusals = [], 0, 0
    t0 = time.perf_counter()
    for seed in range(args.seeds):
        s = simulate_device_imu_session(guided_directions(args.poses), rng=np.random.default_rng(seed))
        guide = PoseGuide(poses=args.poses)
        events = guide.start()
        for n in range(25, len(s) + 25, 25):
            start = guide.keep_from
            events += guide.update(s.recording(start, min(n, len(s))), offset=start)
            if guide.complete:
                break
        refusals += sum(e.kind == "refused" for e in events)
        if not guide.complete:
            unfinished += 1
            continue
        run = calibrate_recording(s.recording(), windows=guide.windows())
        if run.result.accel.model == "triangular" and run.result.gyro.model == "affine":
            rows.append(z_scores(run.result, s.truth))
    z = np.array(rows)
    print(f"{args.seeds} seeds in {time.perf_counter() - t0:.1f} s: {unfinished} unfinished, {refusals} refusals of a "
          f"pose the simulated person held correctly, {len(z)} calibrated with the full models")
    print("z-score RMS per parameter (accelerometer A_xx A_yx A_yy A_zx A_zy A_zz o_x o_y o_z, gyro matrix row-major, "
          "gyro offset):")
    print(" ".join(f"{v:.2f}" for v in np.sqrt((z**2).mean(axis=0))))
    print(f"overall RMS {np.sqrt((z**2).mean()):.3f}; largest |z| {np.abs(z).max():.1f}")


if __name__ == "__main__":
    main()
