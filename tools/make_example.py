#!/usr/bin/env python3
"""Regenerate the bundled example recordings in ``src/gyrocal/data/``.

The gyro is the MPU9250 of the servo method of Wang et al., Table III (k = 1.0069, 0.9960, 0.9955;
b = 0.0442, -0.0089, 0.0076 rad/s) with the paper's simulated white noise
(0.035 rad/s per sample), read at 200 Hz and quantised to the MPU9250's
+-250 deg/s range (131 LSB per deg/s). The motion is that paper's protocol (Fig. 1):
360 deg clockwise and counter-clockwise about x, y and z at 60 deg/s, 3 s apart,
with 0.3 s speed ramps, 5 % servo vibration and a 5 deg mounting misalignment.

A second pair is the paper's testing period (its Figs. 9-10, Tables IV-V): the same gyro
repeats the same movements (``example_servo_repeat.csv``) while a reference gyro on the same
board records them (``example_servo_reference.csv``): an ADIS16465-class sensor (white noise
0.0025 deg/s/sqrt(Hz)) read at 100 Hz by its own logger, whose clock runs 35 ppm slow of the
test gyro's and was started 1.83 s after it, mounted 3 deg off the test gyro's axes.
``gyrocal verify cal.json --example -o verify/`` checks a calibration on this pair.

Usage::

    python tools/make_example.py            # writes the CSVs and their truth sidecars
    python tools/make_example.py --check    # regenerates in memory and compares

The sidecars ``example_servo.truth.json`` and ``example_servo_repeat.truth.json`` (format
``gyrocal.simulation-truth``, the same as ``gyrocal simulate`` writes) hold the true
parameters, the mounting rotation and the true windows; the second also the reference's
clock offset and drift, mounting rotation and noise. The runs are seeded, so the output is
reproducible.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from pathlib import Path

import numpy as np

from gyrocal import ScaleBias
from gyrocal.simulation import VirtualGyro
from gyrocal.simulation.reference import ADIS16465_NOISE_DENSITY, simulate_reference
from gyrocal.simulation.servo import ServoProtocol, simulate_servo
from gyrocal.simulation.truth import SimulationTruth, servo_facts

SEED = 20260522
REPEAT_SEED = 20260523  # the testing period: the same movements, recorded again
REF_RATE = 100.0  # Hz, the reference's logger
REF_OFFSET_S = -1.83  # t_test = t_ref * (1 + drift) + offset: the reference logger started 1.83 s later
REF_DRIFT_PPM = 35.0
REF_MOUNTING_DEG = 3.0
SAMPLE_RATE = 200.0  # Hz
K = (1.0069, 0.9960, 0.9955)  # the servo method of Wang et al., Table III, MPU9250
B = (0.0442, -0.0089, 0.0076)  # rad/s, same table
NOISE_STD = 0.035  # rad/s per sample, that paper's simulation setting
LSB_PER_DPS = 131.0  # MPU9250 at +-250 deg/s
FULL_SCALE_DPS = 250.0
DATA = Path(__file__).resolve().parents[1] / "src" / "gyrocal" / "data"


def example_setup() -> tuple[VirtualGyro, ServoProtocol, float]:
    """The gyro, the protocol and the sample rate [Hz] of the bundled example."""
    gyro = VirtualGyro(
        model=ScaleBias(k=K, b=B),
        noise_std=NOISE_STD,
        quantum=math.radians(1.0 / LSB_PER_DPS),
        full_scale=math.radians(FULL_SCALE_DPS),
    )
    protocol = ServoProtocol(speed=math.radians(60.0), wait=3.0, ramp=0.3, vibration=0.05, misalignment_deg=5.0)
    return gyro, protocol, SAMPLE_RATE


def csv_text(rec) -> str:
    """The recording as CSV text in deg/s (5 decimals: far below the 2 deg/s noise)."""
    g = np.degrees(rec.gyro)
    rows = "\n".join(f"{t:.3f},{x:.5f},{y:.5f},{z:.5f}" for t, (x, y, z) in zip(rec.t, g))
    return "t,gx,gy,gz\n" + rows + "\n"


def truth_doc(truth, protocol: ServoProtocol, seed: int = SEED, reference: dict | None = None) -> dict:
    """The truth sidecar, in the one format of simulated truth (gyrocal.simulation.truth)."""
    settings = {
        "seed": seed, "sample_rate": SAMPLE_RATE, "units": "deg/s", "noise_std": NOISE_STD,
        "quantum_deg_s": 1.0 / LSB_PER_DPS, "full_scale_deg_s": FULL_SCALE_DPS, "speed_deg_s": 60.0,
        "turns": list(protocol.turns), "wait_s": protocol.wait, "ramp_s": protocol.ramp,
        "vibration": protocol.vibration, "misalignment_deg": protocol.misalignment_deg,
    }
    facts = servo_facts(truth)
    if reference is not None:
        facts["reference"] = reference
    doc = SimulationTruth(
        protocol="servo", model=truth.model, settings=settings, facts=facts,
        description="Simulated MPU9250 (the servo method of Wang et al., Table III) on its servo protocol; "
                    "regenerate with tools/make_example.py",
    ).to_document()
    doc["created_by"] = "tools/make_example.py"  # not the version: --check must not fail on a release
    return doc


def reference_csv_text(rec) -> str:
    """The reference log as CSV text in deg/s (times on its own clock, 6 decimals below its noise)."""
    g = np.degrees(rec.gyro)
    rows = "\n".join(f"{t:.3f},{x:.6f},{y:.6f},{z:.6f}" for t, (x, y, z) in zip(rec.t, g))
    return "t,gx,gy,gz\n" + rows + "\n"


def testing_period():
    """The paper's testing period: the repeated session, its truth, the reference log and its truth."""
    gyro, protocol, fs = example_setup()
    rng = np.random.default_rng(REPEAT_SEED)
    repeat, repeat_truth = simulate_servo(gyro, protocol, sample_rate=fs, rng=rng)
    ref_gyro = VirtualGyro(model=ScaleBias(k=(1.0, 1.0, 1.0), b=(0.0, 0.0, 0.0)),
                           noise_std=ADIS16465_NOISE_DENSITY * math.sqrt(REF_RATE))
    ref, ref_truth = simulate_reference(repeat.t, repeat_truth.rates, ref_gyro, sample_rate=REF_RATE,
                                        time_offset_s=REF_OFFSET_S, clock_drift_ppm=REF_DRIFT_PPM,
                                        mounting_deg=REF_MOUNTING_DEG, rng=rng)
    return repeat, repeat_truth, ref, ref_truth


def generate() -> dict[str, str]:
    """File name -> content of every bundled example file."""
    gyro, protocol, fs = example_setup()
    rec, truth = simulate_servo(gyro, protocol, sample_rate=fs, rng=np.random.default_rng(SEED))
    repeat, repeat_truth, ref, ref_truth = testing_period()
    reference = {"path": "example_servo_reference.csv", "units": "deg/s", **ref_truth.to_dict()}
    return {
        "example_servo.csv": csv_text(rec),
        "example_servo.truth.json": json.dumps(truth_doc(truth, protocol), indent=2) + "\n",
        "example_servo_repeat.csv": csv_text(repeat),
        "example_servo_repeat.truth.json": json.dumps(
            truth_doc(repeat_truth, protocol, REPEAT_SEED, reference), indent=2) + "\n",
        "example_servo_reference.csv": reference_csv_text(ref),
    }


_NUMBER = re.compile(r"-?\d+(?:\.(\d*))?(?:[eE][-+]?\d+)?")


def same_numbers(bundled: str, generated: str, rtol: float = 1e-12, fixed_point: bool = False) -> bool:
    """The texts agree apart from numbers, and each number agrees to ``rtol`` (in ``fixed_point`` text, a
    CSV written with fixed decimals, also to one unit of its last digit).

    A BLAS kernel other than the one that wrote the files changes the last bits of a float, which
    can flip the last printed digit; a real change of the example moves numbers far more than that.
    """
    a, b = _NUMBER.split(bundled), _NUMBER.split(generated)
    if len(a) != len(b):
        return False
    # split() interleaves text, the decimals group, and text: compare text exactly, numbers by value
    if a[::2] != b[::2]:
        return False
    for x, y in zip(_NUMBER.finditer(bundled), _NUMBER.finditer(generated)):
        # one unit of the last digit only for fixed-point columns (both written with the same decimals)
        fixed = fixed_point and x.group(1) and len(x.group(1)) == len(y.group(1) or "") and "e" not in x.group(0).lower()
        unit = 1.000001 * 10.0 ** -len(x.group(1)) if fixed else 0.0
        u, v = float(x.group(0)), float(y.group(0))
        if abs(u - v) > max(rtol * max(abs(u), abs(v)), unit):
            return False
    return True


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare with the bundled files instead of writing")
    args = parser.parse_args(argv)
    files = generate()
    if args.check:
        same = all((DATA / name).is_file()
                   and same_numbers((DATA / name).read_text(), text, fixed_point=name.endswith(".csv"))
                   for name, text in files.items())
        print("bundled example is up to date" if same else "bundled example differs; rerun without --check")
        return 0 if same else 1
    for name, text in files.items():
        path = DATA / name
        path.write_text(text)
        print(f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
