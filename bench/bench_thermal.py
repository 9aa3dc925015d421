"""Benchmark: fit a paper-size session of the full-temperature-range method (10 temperatures x 3 positions x 21 rates).

Run by hand:  python bench/bench_thermal.py [--step-duration 60] [--sample-rate 200]

Prints the time to parse the CSV session (``read_session``), the time to fit it
(``calibrate_thermal``: steps, 10 least-squares fits, smooth model), and the ratio
against a naive baseline measured in the same process: a Python loop over steps
(slicing each step's samples) and eq. 19 solved as written with the 12 x 3n Omega.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from gyrocal.io import read_session, write_csv
from gyrocal.simulation.thermal_truth import ThermalTruth
from gyrocal.simulation.turntable import TurntableProtocol, simulate_turntable
from gyrocal.thermal import calibrate_thermal
from gyrocal.thermal.fit import kg_eq19


def naive_fit(rec, settle: float) -> np.ndarray:
    """Per-step Python loop, then eq. 19 as written at each temperature; returns Kg (p, 12)."""
    rate, axis, t = rec.table_rate, rec.axis, rec.t
    by_temp: dict[float, tuple[list, list]] = {}
    start = 0
    n = len(t)
    for i in range(1, n + 1):
        if i == n or rate[i] != rate[i - 1] or axis[i] != axis[i - 1]:
            k = start
            while t[k] < t[start] + settle:
                k += 1
            seg = rec.gyro[k:i]
            ref = np.zeros(3)
            ref["xyz".index(axis[start])] = rate[start]
            temp = round(float(rec.temp[k:i].mean()), 1)
            refs, means = by_temp.setdefault(temp, ([], []))
            refs.append(ref)
            means.append(seg.mean(axis=0))
            start = i
    return np.array([kg_eq19(np.array(r), np.array(m)) for _, (r, m) in sorted(by_temp.items())])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--step-duration", type=float, default=60.0, help="seconds per rate step (paper: 60)")
    ap.add_argument("--sample-rate", type=float, default=200.0, help="Hz")
    ap.add_argument("--settle", type=float, default=2.0, help="seconds dropped per step")
    args = ap.parse_args()
    truth = ThermalTruth()
    t0 = time.perf_counter()
    rec = simulate_turntable(truth.gyro(np.radians(0.05)), TurntableProtocol(step_duration=args.step_duration),
                             sample_rate=args.sample_rate, rng=np.random.default_rng(1))
    print(f"simulated {len(rec):,} samples in {time.perf_counter() - t0:.1f} s")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "session.csv"
        d = np.degrees(rec.gyro)
        t0 = time.perf_counter()
        write_csv(path, {"t": rec.t, "gx": d[:, 0], "gy": d[:, 1], "gz": d[:, 2], "temp": rec.temp,
                         "table_rate": np.degrees(rec.table_rate), "axis": rec.axis})
        print(f"wrote CSV ({path.stat().st_size / 1e6:.0f} MB) in {time.perf_counter() - t0:.1f} s")
        t0 = time.perf_counter()
        recs, names = read_session(path, units="deg/s", saturation="ignore")
        parse = time.perf_counter() - t0
    print(f"parse (read_session): {parse:.2f} s")
    t0 = time.perf_counter()
    cal, fit = calibrate_thermal(recs, settle=args.settle, full_scale=np.radians(2000.0), names=names)
    fast = time.perf_counter() - t0
    print(f"fit (calibrate_thermal): {fast:.2f} s   [{len(fit.steps)} steps, {len(cal.temps)} temperatures]")
    t0 = time.perf_counter()
    kg_naive = naive_fit(recs[0], args.settle)
    slow = time.perf_counter() - t0
    print(f"naive baseline (per-sample step search + per-step loop + eq. 19 as written): {slow:.2f} s")
    print(f"speed-up of the fit over the baseline: {slow / fast:.1f}x   (parse + fit: {parse + fast:.2f} s)")
    print(f"max |Kg fast - Kg naive| = {np.max(np.abs(kg_naive - fit.kg)):.2e}")
    z = (fit.kg - truth.kg(fit.temps)) / fit.std_noise
    print(f"truth check: max |error| / sigma = {np.max(np.abs(z)):.2f} over {z.size} parameters")


if __name__ == "__main__":
    main()
