"""Simulated pairs for the verification tests: a test gyro and a reference gyro on one motion.

Every pair is drawn from a seeded generator; the truth (clock offset and drift, mounting
rotation, true rates) comes back with it, so tests compare estimates with the truth that
made the data, never with figures gyrocal itself computed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gyrocal import ScaleBias
from gyrocal.simulation import VirtualGyro, simulate_profile
from gyrocal.simulation.reference import ReferenceTruth, simulate_reference
from gyrocal.simulation.servo import ServoProtocol, simulate_servo

IDEAL = ScaleBias(k=(1.0, 1.0, 1.0), b=(0.0, 0.0, 0.0))


def smooth_motion(rng: np.random.Generator, amplitude: float = 0.4):
    """Rates (t -> (N, 3)) [rad/s]: six sines per axis, 0.05-1 Hz, random phases."""
    f = rng.uniform(0.05, 1.0, (3, 6))
    a = rng.uniform(0.25, 1.0, (3, 6)) * amplitude
    ph = rng.uniform(0, 2 * np.pi, (3, 6))
    return lambda t: np.stack([np.sum(a[j][:, None] * np.sin(2 * np.pi * f[j][:, None] * t + ph[j][:, None]), 0)
                               for j in range(3)], axis=1)


@dataclass
class Pair:
    """A simulated test log, its true rates, the model of the test gyro and the reference log."""

    test: object
    rates: np.ndarray
    model: ScaleBias
    ref: object
    truth: ReferenceTruth


def make_pair(rng: np.random.Generator, *, motion: str = "smooth", duration: float = 60.0, fs_test: float = 200.0,
              fs_ref: float = 100.0, noise_test: float = 0.02, noise_ref: float = 0.002, offset: float = 0.0,
              drift: float = 0.0, mounting_deg: float = 20.0, model: ScaleBias | None = None,
              vibration: float = 0.0) -> Pair:
    """A pair on `motion` ``"smooth"`` (random sines) or ``"servo"`` (the servo method of Wang et al., Fig. 1)."""
    model = model or IDEAL
    gyro = VirtualGyro(model=model, noise_std=noise_test)
    if motion == "servo":
        test, truth = simulate_servo(gyro, ServoProtocol(speed=math.radians(60.0), vibration=vibration),
                                     sample_rate=fs_test, rng=rng)
        rates = np.asarray(truth.rates)
    else:
        test, rates = simulate_profile(gyro, smooth_motion(rng), duration=duration, sample_rate=fs_test, rng=rng)
    ref, truth = simulate_reference(test.t, rates, VirtualGyro(model=IDEAL, noise_std=noise_ref), sample_rate=fs_ref,
                                    time_offset_s=offset, clock_drift_ppm=drift, mounting_deg=mounting_deg, rng=rng)
    return Pair(test, rates, model, ref, truth)
