"""A simulated chamber session of a whole IMU, shared by the thermal tests of ``gyrocal imu``.

Reference: an independent generator written here. At each set point the accelerometer's scale
drifts 0.02 %/degC with a cubic part and its offsets by 0.1 g over -25..+60 degC (cubic); the
gyro's scale drifts and its bias jumps from one plateau to the next (turn-on bias). Each plateau
is a multi-position session of its own (:func:`~gyrocal.simulation.multiposition.simulate_multi_position`
with that temperature's sensors), and the log jumps in time between plateaus (the soak is not
recorded). The truth's accelerometer correction is lower triangular, so the frame the fit writes
in (corrected x along the sensor's x, y in its xy plane) is the truth's own.
"""

import numpy as np

from gyrocal.models import Affine
from gyrocal.simulation.gyro import VirtualGyro
from gyrocal.simulation.multiposition import MultiPositionProtocol, VirtualImu, simulate_multi_position

__all__ = ["BETWEEN", "TEMPS", "Truth", "chamber"]

TEMPS = (-25.0, -5.0, 20.0, 40.0, 60.0)
BETWEEN = (-15.0, 7.5, 30.0, 50.0)
_LOWER = np.tril(np.ones((3, 3), bool))


def _x(temp):
    return (temp - 17.5) / 42.5


class Truth:
    """Accelerometer (canonical ``f = A (u - o)``) and gyro of one seeded board, as functions of temperature."""

    def __init__(self, rng):
        self.a0 = np.tril(np.eye(3) * rng.uniform(0.98, 1.02, 3) + rng.normal(0, 0.004, (3, 3)))
        self.o0 = rng.normal(0, 0.2, 3)
        self.drift = rng.choice([-1.0, 1.0], 3) * rng.uniform(0.7, 1.0, 3)
        self.sens = rng.uniform(0.8, 1.2, 3)
        self.k0 = np.eye(3) * rng.uniform(0.97, 1.03, 3) + rng.normal(0, 0.005, (3, 3))
        self.b0 = np.radians(rng.normal(0, 0.5, 3))

    def accel(self, temp):
        x = _x(temp)
        s = 1 + self.sens * 2e-4 * (temp - 20) + 1e-3 * x**3  # sensitivity: reading per m/s^2
        a = self.a0.copy()
        a[np.diag_indices(3)] /= s
        offset = self.o0 + 9.80665 * 0.1 * self.drift * (0.35 * x + 0.1 * x**2 + 0.05 * x**3)
        return a, offset

    def params(self, temp):
        a, o = self.accel(temp)
        return np.concatenate([a[_LOWER], o])


def chamber(seed, poses=14):
    """The log of one board: a session per plateau, 600 s unrecorded between plateaus."""
    rng = np.random.default_rng(seed)
    truth = Truth(rng)
    parts, gyro_truth, t0 = [], [], 0.0
    for temp in TEMPS:
        a, o = truth.accel(temp)
        k = truth.k0 * (1 + 1e-4 * (temp - 20))
        bias = truth.b0 + np.radians(0.002) * (temp - 20) + np.radians(rng.normal(0, 0.05, 3))
        imu = VirtualImu(VirtualGyro(Affine(k, bias), noise_std=np.radians(0.1)), accel_matrix=a, accel_offset=o,
                         accel_noise_std=0.02)
        s = simulate_multi_position(imu, MultiPositionProtocol(poses=poses, static_duration=(1.5, 2.5)), rng=rng)
        parts.append((s.t + t0, s.gyro, s.accel, temp + rng.normal(0, 0.05, len(s.t))))
        gyro_truth.append(np.concatenate([s.truth["gyro_matrix"].ravel(), s.truth["gyro_offset"]]))
        t0 += s.t[-1] + 600.0
    t, gyro, accel, temp = (np.concatenate(c) for c in zip(*parts))
    breaks = np.cumsum([len(p[0]) for p in parts])[:-1]
    return truth, np.array(gyro_truth), t, gyro, accel, temp, breaks
