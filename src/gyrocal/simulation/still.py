"""A board lying still: a static noise log, or a warming board for a thermal-bias fit.

The flight stacks' thermal calibration (PX4, ArduPilot) records a board that was cooled,
then powered and left still while it warms. Here the sensor temperature follows an
exponential warm-up, ``T(t) = T_end - (T_end - T_start) exp(-t / tau)``, the bias is a
polynomial of temperature, and the temperature readings carry noise and are quantised
(many IMUs report whole degrees). With ``T_start == T_end`` it is a plain static log, the
input of a noise analysis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import at_least, finite_array, positive, temperature
from ..errors import InputError
from ..recording import Recording
from ..units import STANDARD_GRAVITY
from .gyro import VirtualGyro

__all__ = ["BiasDrift", "StillAccelerometer", "StillProtocol", "simulate_still"]


@dataclass(frozen=True)
class BiasDrift:
    """Thermal errors of a gyro whose bias alone depends on temperature.

    Call it as ``drift(temp) -> (K, B)`` (see :class:`~.gyro.ThermalErrors`):
    ``B(T) = sum_n coefs[:, n] (T - ref_temp)^n`` [rad/s], ``K`` the identity.

    Parameters
    ----------
    coefs : array_like, shape (3, k)
        Bias polynomial per axis, lowest power first [rad/s/degC^n].
    ref_temp : float
        Reference temperature of the polynomial [degC].
    """

    coefs: tuple | np.ndarray
    ref_temp: float = 25.0

    def __post_init__(self):
        c = finite_array("coefs", self.coefs, ndim=2)
        if c.shape[0] != 3 or c.shape[1] < 1:
            raise InputError(f"coefs must have shape (3, k), got {c.shape}")
        object.__setattr__(self, "coefs", c)

    def bias(self, temp) -> np.ndarray:
        """True bias (N, 3) [rad/s] at temperatures (N,) [degC]."""
        d = np.atleast_1d(np.asarray(temp, dtype=float)) - self.ref_temp
        return np.vander(d, self.coefs.shape[1], increasing=True) @ self.coefs.T

    def __call__(self, temp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        B = self.bias(temp)
        return np.broadcast_to(np.eye(3), (len(B), 3, 3)), B


@dataclass(frozen=True)
class StillProtocol:
    """A still log: its length and its temperature course.

    Parameters
    ----------
    duration : float
        Length [s].
    temp_start, temp_end : float
        Temperature at power-on and the one it settles to [degC]; equal for a static log.
    temp_tau : float
        Warm-up time constant [s].
    temp_noise : float
        Standard deviation of each temperature reading [degC].
    temp_quantum : float, optional
        Resolution of the temperature readings [degC], e.g. 1 for whole degrees.
    """

    duration: float = 2700.0
    temp_start: float = 25.0
    temp_end: float = 25.0
    temp_tau: float = 600.0
    temp_noise: float = 0.0
    temp_quantum: float | None = None

    def __post_init__(self):
        positive("duration", self.duration)
        positive("temp_tau", self.temp_tau)
        for name in ("temp_start", "temp_end"):
            temperature(name, getattr(self, name))
        at_least("temp_noise", self.temp_noise, 0.0, " degC")
        if self.temp_quantum is not None:
            positive("temp_quantum", self.temp_quantum)

    def temperature(self, t) -> np.ndarray:
        """True sensor temperature [degC] at times `t` [s]."""
        t = np.asarray(t, dtype=float)
        return self.temp_end - (self.temp_end - self.temp_start) * np.exp(-t / self.temp_tau)


@dataclass(frozen=True)
class StillAccelerometer:
    """An accelerometer lying flat: gravity on +z, white noise and a random-walk bias.

    Parameters
    ----------
    noise_density : float
        White-noise density [m/s^2/sqrt(Hz)] (velocity random walk).
    random_walk : float
        Bias random walk [m/s^3/sqrt(Hz)] (Kalibr's ``accelerometer_random_walk``).
    """

    noise_density: float = 0.0
    random_walk: float = 0.0

    def __post_init__(self):
        # named as the flags of 'gyrocal simulate --protocol static' that set them
        at_least("accel_noise_density", self.noise_density, 0.0)
        at_least("accel_random_walk", self.random_walk, 0.0)

    def measure(self, n: int, sample_rate: float, rng: np.random.Generator) -> np.ndarray:
        """Readings (n, 3) [m/s^2]."""
        a = np.zeros((n, 3))
        a[:, 2] = STANDARD_GRAVITY
        a += rng.standard_normal((n, 3)) * self.noise_density * math.sqrt(sample_rate)
        if self.random_walk > 0:
            a += np.cumsum(rng.standard_normal((n, 3)) * self.random_walk / math.sqrt(sample_rate), axis=0)
        return a


def simulate_still(gyro: VirtualGyro, protocol: StillProtocol, *, sample_rate: float, rng: np.random.Generator,
                   accel: StillAccelerometer | None = None) -> tuple[Recording, np.ndarray]:
    """Record `gyro` (and `accel`, when given) lying still through `protocol`.

    Returns
    -------
    recording : Recording
        Readings [rad/s], time [s] and the temperature readings [degC].
    true_temp : ndarray, shape (N,)
        The true sensor temperature [degC] behind the readings.
    """
    fs = positive("sample_rate", sample_rate)
    n = int(round(protocol.duration * fs))
    if n < 2:
        raise InputError(f"duration={protocol.duration} s at {fs} Hz gives {n} sample(s); need at least 2")
    t = np.arange(n) / fs
    true_temp = protocol.temperature(t)
    m = gyro.measure(np.zeros((n, 3)), fs, rng, temp=true_temp if gyro.thermal is not None else None)
    reading = true_temp + rng.standard_normal(n) * protocol.temp_noise
    if protocol.temp_quantum is not None:
        reading = np.round(reading / protocol.temp_quantum) * protocol.temp_quantum
    fields = {} if accel is None else {"accel": accel.measure(n, fs, rng), "accel_units": "m/s^2",
                                       "accel_source_units": "m/s^2"}
    return Recording(t=t, gyro=m, sample_rate=fs, temp=reading, **fields), true_temp
