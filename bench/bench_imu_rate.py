"""``gyrocal imu`` CPU against the sample rate, and the gyro fit's Jacobian against a finite difference.

Run by hand:  python bench/bench_imu_rate.py [--rates 200,1000,2000] [--repeat 3] [--previous-src DIR]

* Whole command: ``gyrocal simulate --protocol multi-position --sample-rate R -o s.csv --seed 1`` once per
  rate, then ``gyrocal imu s.csv --units deg/s --accel-units m/s^2 -o i.json`` in fresh processes; the
  CPU (user + system) of each, median of --repeat, interleaved across rates. Baseline: the 1 kHz run
  (issue 25: 2 kHz at most 2.3x the CPU of 1 kHz). With ``--previous-src``, the same commands of an
  earlier gyrocal (``git worktree add /tmp/old 2db7693``, then ``--previous-src /tmp/old/src``),
  interleaved, and previous / now.
* The fit alone, in this process, on a simulated 24-pose session at the highest rate: ``calibrate_imu``
  with the analytic Jacobian and with a central difference in its place (two integrations of the
  attitudes per parameter, for every Jacobian; its baseline), process CPU time.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _cpu_of(cmd: list[str], src: str | None = None) -> float:
    env = None if src is None else dict(os.environ, PYTHONPATH=src)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, capture_output=True, env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def whole_command(rates: list[int], repeat: int, folder: Path, previous: str | None) -> None:
    gyrocal = [sys.executable, "-m", "gyrocal"]
    for r in rates:
        subprocess.run(gyrocal + ["simulate", "--protocol", "multi-position", "--sample-rate", str(r), "--seed", "1",
                                  "-o", str(folder / f"s{r}.csv"), "--force"], check=True, capture_output=True)
    cpu = {(r, src): [] for r in rates for src in ([None, previous] if previous else [None])}
    for _ in range(repeat):
        for r, src in cpu:
            cpu[r, src].append(_cpu_of(gyrocal + ["imu", str(folder / f"s{r}.csv"), "--units", "deg/s",
                                                  "--accel-units", "m/s^2", "-o", str(folder / f"i{r}.json"),
                                                  "--force"], src))
    med = {k: statistics.median(v) for k, v in cpu.items()}
    for r in rates:
        ratio = f"; / 1 kHz {med[r, None] / med[1000, None]:.2f}x" if 1000 in rates else ""
        if previous:
            ratio += (f"; previous {med[r, previous]:.2f} s (/ 1 kHz {med[r, previous] / med[1000, previous]:.2f}x), "
                      f"previous / now {med[r, previous] / med[r, None]:.2f}x" if 1000 in rates else "")
        print(f"gyrocal imu at {r:>5} Hz: CPU {med[r, None]:.2f} s (median of {repeat}){ratio}")


def fit_alone(rate: int, repeat: int) -> None:
    import numpy as np

    import gyrocal.imu._gyro_solve as solve_mod
    from gyrocal.imu import calibrate_imu
    from gyrocal.models import Affine
    from gyrocal.simulation.gyro import VirtualGyro
    from gyrocal.simulation.multiposition import MultiPositionProtocol, VirtualImu, simulate_multi_position

    rng = np.random.default_rng(1)
    k = np.eye(3) * rng.uniform(0.97, 1.03, 3) + rng.normal(0, 0.005, (3, 3))
    gyro = VirtualGyro(Affine(k, np.radians(rng.normal(0, 0.5, 3))), noise_std=np.radians(0.1))
    imu = VirtualImu(gyro, accel_matrix=np.eye(3), accel_offset=rng.normal(0, 0.1, 3), accel_noise_std=0.02)
    s = simulate_multi_position(imu, MultiPositionProtocol(poses=24, sample_rate=float(rate)), rng=rng)
    analytic = solve_mod.residuals_jacobian

    def numeric(prob, model, with_g, p, directions, directions_std):
        return solve_mod.jacobian(lambda q: solve_mod.residuals(prob, model, with_g, q, directions, directions_std), p)

    times = {"analytic": [], "finite difference": []}
    for _ in range(repeat):
        for name, fn in (("analytic", analytic), ("finite difference", numeric)):
            solve_mod.residuals_jacobian = fn
            t0 = time.process_time()
            calibrate_imu(s.t, s.gyro, s.accel)
            times[name].append(time.process_time() - t0)
    solve_mod.residuals_jacobian = analytic
    a, f = (statistics.median(times[k]) for k in ("analytic", "finite difference"))
    print(f"calibrate_imu at {rate} Hz ({len(s.t)} samples): analytic Jacobian {a:.2f} s CPU, central difference "
          f"{f:.2f} s; difference / analytic {f / a:.2f}x")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rates", default="200,1000,2000")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--previous-src", help="src folder of an earlier gyrocal, run as the baseline")
    args = parser.parse_args()
    rates = [int(r) for r in args.rates.split(",")]
    os.environ.setdefault("PYTHONPATH", str(Path(__file__).resolve().parents[1] / "src"))
    with tempfile.TemporaryDirectory() as tmp:
        whole_command(rates, args.repeat, Path(tmp), args.previous_src)
    fit_alone(max(rates), args.repeat)


if __name__ == "__main__":
    main()
