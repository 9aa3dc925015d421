"""Whole-IMU calibration (gyrocal imu): speed, and whether the reported 1-sigma holds (README's figures).

Run by hand:  .venv/bin/python bench/bench_imu.py [--poses 24] [--seeds 40] [--repeat 3]

* imucal's example Ferraris session: gyrocal's whole-IMU fit against imucal's, run here.

* Speed: one calibration of a simulated 24-pose hand session at 100 Hz (detection, accelerometer,
  gyro with its generalised least squares), best of --repeat. The gyro's inner cost is integrating
  the attitude between poses for every trial of the parameters; its baseline is the same
  integration with one quaternion product per sample in a Python loop (what a direct port of
  imu_tk's integrator does), timed in the same process on the same intervals.
* Honesty of the 1-sigma: over --seeds simulated sessions (random poses, misalignment, noise,
  uneven steps, the Earth's rotation), the RMS of the actual errors of each group of parameters
  divided by the RMS of the reported 1-sigma (1 = the uncertainty holds; above 1 = optimistic).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from gyrocal import quaternion as quat
from gyrocal.imu import calibrate_imu
from gyrocal.models import Affine
from gyrocal.simulation.gyro import VirtualGyro
from gyrocal.simulation.multiposition import MultiPositionProtocol, VirtualImu, simulate_multi_position


def session(seed: int, poses: int):
    rng = np.random.default_rng(seed)
    k = np.eye(3) * rng.uniform(0.97, 1.03, 3) + rng.normal(0, 0.005, (3, 3))
    gyro = VirtualGyro(Affine(k, np.radians(rng.normal(0, 0.5, 3))), noise_std=np.radians(0.1))
    a = np.tril(np.eye(3) * rng.uniform(0.97, 1.03, 3) + rng.normal(0, 0.005, (3, 3)))
    imu = VirtualImu(gyro, accel_matrix=a, accel_offset=rng.normal(0, 0.2, 3), accel_noise_std=0.02)
    proto = MultiPositionProtocol(poses=poses, static_duration=(1.5, 2.5), uneven_steps=0.03)
    return simulate_multi_position(imu, proto, rng=rng)


def naive_integration(t, omega, bounds) -> np.ndarray:
    """One quaternion product per step, in a Python loop (the baseline)."""
    out = []
    phi = quat.step_rotvecs(t, omega)
    for a, b in bounds:
        q = np.array([1.0, 0.0, 0.0, 0.0])
        for p in phi[a:b]:
            q = quat.multiply(q, quat.from_rotvec(p))
        out.append(q)
    return np.array(out)


def speed(poses: int, repeat: int) -> None:
    s = session(0, poses)
    best = min(_timed(lambda: calibrate_imu(s.t, s.gyro, s.accel)) for _ in range(repeat))
    still = s.still
    bounds = np.stack([still[:-1, 1] - 1, still[1:, 0]], axis=1)
    fast = min(_timed(lambda: quat.attitude_change(s.t, s.gyro, bounds)) for _ in range(repeat))
    slow = _timed(lambda: naive_integration(s.t, s.gyro, bounds))
    steps = int((bounds[:, 1] - bounds[:, 0]).sum())
    print(f"calibrate_imu, {poses} poses, {len(s.t)} samples: {best:.2f} s")
    print(f"attitude integration of {len(bounds)} moves ({steps} steps): {1e3 * fast:.2f} ms; per-sample loop "
          f"{1e3 * slow:.1f} ms; ratio {slow / fast:.0f}x")


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def honesty(poses: int, seeds: int) -> None:
    err_a, std_a, err_g, std_g = [], [], [], []
    for seed in range(seeds):
        s = session(1000 + seed, poses)
        r = calibrate_imu(s.t, s.gyro, s.accel)
        tr = s.truth
        if r.accel.model == "triangular":
            mask = np.tril(np.ones((3, 3), dtype=bool))
            err_a.append(r.accel.params - np.concatenate([tr["accel_matrix"][mask], tr["accel_offset"]]))
            std_a.append(r.accel.std)
        err_g.append(r.gyro.params[:12] - np.concatenate([tr["gyro_matrix"].ravel(), tr["gyro_offset"]]))
        std_g.append(r.gyro.std[:12])
    groups = {"accelerometer matrix": (err_a, std_a, slice(0, 6)), "accelerometer offset": (err_a, std_a, slice(6, 9)),
              "gyro matrix": (err_g, std_g, slice(0, 9)), "gyro bias": (err_g, std_g, slice(9, 12))}
    print(f"actual RMS error / reported RMS 1-sigma over {seeds} sessions of {poses} poses:")
    for name, (err, std, sl) in groups.items():
        e, s = np.array(err)[:, sl], np.array(std)[:, sl]
        print(f"  {name}: {np.sqrt(np.mean(e**2)) / np.sqrt(np.mean(s**2)):.2f} "
              f"(RMS z {np.sqrt(np.mean((e / s) ** 2)):.2f})")


def ferraris() -> None:
    """imucal's example session: gyrocal's Ferraris fit against imucal's (imucal run here)."""
    import json
    from importlib import resources
    from pathlib import Path

    import pandas as pd
    from imucal import FerrarisCalibration, ferraris_regions_from_section_list

    from gyrocal.io import read_windows

    data = Path(str(resources.files("gyrocal") / "data" / "imucal_ferraris"))
    df = pd.read_csv(data / "example_ferraris_session.csv")
    sections = data / "example_ferraris_session_list.json"
    fs, g = 102.4, 9.81
    info = FerrarisCalibration(grav=g).compute(
        ferraris_regions_from_section_list(df, pd.DataFrame(json.loads(sections.read_text())).T),
        sampling_rate_hz=fs, from_acc_unit="m/s^2", from_gyr_unit="deg/s")
    r = calibrate_imu(np.arange(len(df)) / fs, np.radians(df[["gyr_x", "gyr_y", "gyr_z"]].to_numpy()),
                      df[["acc_x", "acc_y", "acc_z"]].to_numpy(), gravity=g,
                      windows=read_windows(sections, sample_rate=fs))
    acc = np.linalg.inv(info.R_a) @ np.linalg.inv(info.K_a)
    gyr = np.linalg.inv(info.R_g) @ np.linalg.inv(info.K_g)
    rows = [("accelerometer matrix", r.accel.matrix.ravel() - acc.ravel(), r.accel.std[:9], ""),
            ("accelerometer offset", r.accel.offset - info.b_a, r.accel.std[9:], " m/s^2"),
            ("gyro matrix", r.gyro.matrix.ravel() - gyr.ravel(), r.gyro.std[:9], ""),
            ("gyro bias", np.degrees(r.gyro.offset) - info.b_g, np.degrees(r.gyro.std[9:12]), " deg/s")]
    print("imucal's Ferraris session, gyrocal imu against imucal (largest difference, and in gyrocal's 1-sigma):")
    for name, diff, std, unit in rows:
        print(f"  {name}: {np.abs(diff).max():.2g}{unit}, {np.abs(diff / std).max():.2f} sigma")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=24)
    parser.add_argument("--seeds", type=int, default=40)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    speed(args.poses, args.repeat)
    ferraris()
    honesty(args.poses, args.seeds)


if __name__ == "__main__":
    main()
