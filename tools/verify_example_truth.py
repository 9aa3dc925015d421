#!/usr/bin/env python3
"""Set a verification of the bundled example beside the truth the simulation knows.

``gyrocal verify CAL --example -o DIR`` compares the calibrated testing period with the
reference log. The simulation also knows the true rates, so the MSE a perfect reference
would measure (the truth-based MSE at the same samples) can be set beside the measured one;
what is left between them is what the reference adds: its noise (the floor) and the servo
vibration faster than its 100 Hz can follow.

Usage::

    gyrocal calibrate --example -o cal.json
    gyrocal verify cal.json --example -o verify/
    python tools/verify_example_truth.py cal.json verify/verify.json
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path

import numpy as np

from gyrocal.results.files import load
from gyrocal.units import unit_factor


def _make_example():
    path = Path(__file__).resolve().parent / "make_example.py"
    spec = importlib.util.spec_from_file_location("make_example", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("calibration", type=Path)
    parser.add_argument("report", type=Path, help="verify.json written by gyrocal verify --example")
    args = parser.parse_args(argv)
    cal, report = load(args.calibration), load(args.report)
    repeat, truth, ref, _ = _make_example().testing_period()
    u = unit_factor(report.units)
    # the samples the report compared: those whose reference time falls inside the reference log
    tau = report.alignment.reference_time(repeat.t)
    keep = (tau >= ref.t[0]) & (tau <= ref.t[-1])
    calibrated = cal.apply(repeat).gyro[keep] / u
    raw = np.asarray(repeat.gyro)[keep] / u
    true = np.asarray(truth.rates)[keep] / u
    v = report.metrics.values
    print(f"MSE [({report.units})^2] at the {keep.sum()} compared samples: measured against the reference | "
          "truth-based | difference")
    for j, ax in enumerate("xyz"):
        before, after = np.mean((raw[:, j] - true[:, j]) ** 2), np.mean((calibrated[:, j] - true[:, j]) ** 2)
        print(f"  {ax}: before {v['mse_before'][j]:.3f} | {before:.3f} | {v['mse_before'][j] - before:+.3f};  "
              f"after {v['mse_after'][j]:.3f} | {after:.3f} | {v['mse_after'][j] - after:+.3f}  "
              f"(reference floor {v['reference_floor'][j]:.4f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
