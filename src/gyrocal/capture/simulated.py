"""Simulated device sessions: what a gyro (and an accelerometer) on a microcontroller reads during a
servo or hand session, or a multi-position hand session of the whole IMU.

The motion and the sensors come from :mod:`gyrocal.simulation`; this module turns the readings
into what a device sends: raw counts (int16) at a sensitivity, microsecond time stamps of the
device's clock and the temperature in hundredths of a degree.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._validation import positive
from ..models import ScaleBias
from ..recording import Recording
from ..segmentation.windows import Window
from ..simulation import ServoProtocol, VirtualGyro, simulate_servo
from ..units import STANDARD_GRAVITY

__all__ = ["MPU6050_ACCEL_SENSITIVITY", "MPU6050_SENSITIVITY", "DeviceSession", "counts", "simulate_device_session"]

#: LSB per deg/s of an MPU-6050 / MPU-9250 at +-250 deg/s.
MPU6050_SENSITIVITY = 131.0
#: LSB per g of its accelerometer at +-2 g.
MPU6050_ACCEL_SENSITIVITY = 16384


@dataclass(frozen=True)
class DeviceSession:
    """A simulated session as the device sees it.

    Attributes
    ----------
    raw : ndarray of int16, shape (N, 3)
        Readings [counts].
    t_us : ndarray of int64, shape (N,)
        The device clock at each sample [us].
    temp : ndarray, shape (N,), or None
        Temperature [degC], in steps of 0.01.
    sample_rate : float
        Nominal rate [Hz].
    sensitivity : float
        [counts per deg/s].
    model : ScaleBias or Affine
        The true gyro, internal units (rad/s): servo method of Wang et al. eq. 1, or a gyro
        mounted at an angle to the accelerometer (multi-position sessions).
    windows : tuple of Window
        Every true turn and static stretch, in samples of this session.
    accel : ndarray of int16, shape (N, 3), or None
        Accelerometer readings [counts] (multi-position sessions).
    accel_sensitivity : int or None
        [counts per g].
    truth : dict or None
        Multi-position sessions: the simulator's truth (:attr:`gyrocal.simulation.multiposition.ImuSession.truth`,
        internal units: rad/s and m/s^2).
    """

    raw: np.ndarray
    t_us: np.ndarray
    temp: np.ndarray | None
    sample_rate: float
    sensitivity: float
    model: ScaleBias
    windows: tuple[Window, ...]
    accel: np.ndarray | None = None
    accel_sensitivity: int | None = None
    truth: dict | None = None

    def __len__(self) -> int:
        return len(self.raw)

    @property
    def device_k(self) -> np.ndarray:
        """True k as the device computes it [deg/s per count]."""
        return self.model.k / self.sensitivity

    @property
    def device_b(self) -> np.ndarray:
        """True b as the device computes it [counts]."""
        return self.model.b * (180.0 / math.pi) * self.sensitivity

    @property
    def turns(self) -> tuple[Window, ...]:
        return tuple(w for w in self.windows if w.kind == "rotation")

    def recording(self, start: int = 0, stop: int | None = None, gravity: float = STANDARD_GRAVITY) -> Recording:
        """Samples ``start:stop`` as ``gyrocal capture`` reads them: counts at the session's sensitivities, in
        rad/s and m/s^2, the time from the first sample of the session [s]."""
        part = slice(start, len(self) if stop is None else stop)
        kw = {}
        if self.accel is not None:
            kw = dict(accel=self.accel[part] * (gravity / self.accel_sensitivity), accel_units="m/s^2",
                      accel_source_units="counts", accel_sensitivity=self.accel_sensitivity)
        return Recording(t=(self.t_us[part] - self.t_us[0]) * 1e-6, gyro=np.radians(self.raw[part] / self.sensitivity),
                         source_units="counts", sensitivity=self.sensitivity, **kw)


def simulate_device_session(
    protocols: ServoProtocol | Sequence[ServoProtocol],
    *,
    model: ScaleBias,
    noise_std: float,
    rng: np.random.Generator,
    sample_rate: float = 200.0,
    sensitivity: float = MPU6050_SENSITIVITY,
    temp: float | None = 25.0,
    clock_ppm: float = 0.0,
) -> DeviceSession:
    """Simulate a session (one protocol, or several played one after the other).

    Parameters
    ----------
    protocols : ServoProtocol or sequence of ServoProtocol
        The motion; a sequence plays its parts in turn (for example a turn done wrong,
        then done again).
    model : ScaleBias
        The true gyro [rad/s].
    noise_std : float
        Per-sample white noise [rad/s].
    rng : numpy.random.Generator
        All randomness.
    sample_rate : float
        [Hz].
    sensitivity : float
        [counts per deg/s]; readings are rounded to whole counts and clipped to int16.
    temp : float or None
        Temperature [degC], drifting by 0.5 degC over the session; None for a device without one.
    clock_ppm : float
        Error of the device clock that stamps the samples [parts per million].
    """
    fs = positive("sample_rate", sample_rate)
    sens = positive("sensitivity", sensitivity)
    parts = [protocols] if isinstance(protocols, ServoProtocol) else list(protocols)
    gyro = VirtualGyro(model, noise_std=noise_std)
    chunks, windows, offset = [], [], 0
    for p in parts:
        rec, truth = simulate_servo(gyro, p, sample_rate=fs, rng=rng)
        chunks.append(rec.gyro)
        windows += [Window(w.start + offset, w.stop + offset, w.kind, w.axis, w.sign, w.angle, w.rate, w.label)
                    for w in truth.windows]
        offset += len(rec)
    raw = counts(np.concatenate(chunks) * (180.0 / math.pi) * sens)
    n = len(raw)
    t_us = np.round(np.arange(n) * (1e6 / fs) * (1 + 1e-6 * clock_ppm)).astype(np.int64) + 1_000_000
    return DeviceSession(raw, t_us, _temperature(temp, n), fs, sens, model, tuple(windows))


def counts(x) -> np.ndarray:
    """Readings rounded to whole counts and clipped to int16, as a sensor's register holds them."""
    return np.clip(np.round(x), -32768, 32767).astype(np.int16)


def _temperature(temp: float | None, n: int) -> np.ndarray | None:
    """[degC] in steps of 0.01, drifting by 0.5 degC over the session; None for a device without one."""
    return None if temp is None else np.round((temp + 0.5 * np.arange(n) / max(n, 1)) * 100) / 100
