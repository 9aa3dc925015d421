"""A chamber session on a temperature ramp: the cube turned through its poses over and over while the
temperature drifts, with the truth.

The chamber runs from ``low`` to ``high`` [degC] at a constant ``rate`` [degC/min] while the board is
held still in a pose sequence (:func:`~gyrocal.imu.poses.pose_sequence`, a new draw of ``poses`` poses
each cycle) and turned by hand between poses, until the ramp ends. Both sensors' 12 parameters follow
the board's cubics (:class:`~gyrocal.simulation.chamber.ImuThermalTruth`) at each sample's true
temperature; a ramp that cools (``high < low``) is on the cooling branch (the accelerometer's offsets
moved by the hysteresis). The temperature column reads the true temperature plus white noise.
"""

from __future__ import annotations

import numpy as np

from .._validation import at_least, positive
from ..errors import InputError
from .chamber import ImuThermalTruth
from .multiposition import MultiPositionProtocol, session_motion

__all__ = ["DEFAULT_RATE", "ramp_session", "ramp_truth_params"]

#: Ramp rate when none is given [degC/min]: a common chamber's controlled ramp.
DEFAULT_RATE = 1.0


def ramp_truth_params(truth: ImuThermalTruth, temp, cooling: bool) -> tuple[np.ndarray, np.ndarray]:
    """Both sensors' 12 parameters (N, 12) at temperatures `temp` (N,) [degC] on one branch."""
    x = (np.asarray(temp, dtype=float) - truth.ref_temp) / truth.scale
    powers = x[:, None] ** np.arange(4)
    accel, gyro = powers @ truth.accel_coefs.T, powers @ truth.gyro_coefs.T
    if cooling:
        accel[:, 9:] += truth.hysteresis
    return accel, gyro


def _orientations(cycles: int, poses: int, tilt_deg: float, rng) -> np.ndarray:
    from ..imu.poses import pose_sequence

    return np.concatenate([pose_sequence(poses, tilt_deg, rng=rng) for _ in range(cycles)])


def ramp_session(truth: ImuThermalTruth, low: float, high: float, rate: float = DEFAULT_RATE, *, gyro_kw: dict,
                 poses: int = 24, tilt_deg: float = 90.0, still: float = 3.0, accel_noise_std: float = 0.02,
                 temp_noise: float = 0.0, sample_rate: float = 100.0, rng: np.random.Generator):
    """Poses taken while the temperature runs from `low` to `high` [degC] at `rate` [degC/min].

    Returns
    -------
    (Recording, dict)
        The log (gyro rad/s, accelerometer m/s^2, temp degC) and the ramp's truth: its ends, rate,
        duration, branch and the true still spans of the poses.
    """
    from ..recording import Recording
    from .gyro import VirtualGyro

    positive("rate", rate)
    at_least("temp_noise", temp_noise, 0.0, " degC")
    if not abs(high - low) >= 1.0:
        raise InputError(f"a temperature ramp needs its ends 1 degC or more apart, got {low:g}:{high:g}")
    duration = abs(high - low) / rate * 60.0
    proto = MultiPositionProtocol(poses=max(int(poses), 2), turn_deg=tilt_deg, sample_rate=sample_rate,
                                  static_duration=(0.75 * positive("static_duration", still), 1.25 * still))
    cycles = int(np.ceil(duration / (int(poses) * (0.75 * still + 0.5)))) + 1  # more poses than the ramp needs
    t, w, f, spans = session_motion(_orientations(cycles, int(poses), tilt_deg, rng), proto, rng)
    keep = t <= duration
    t, w, f = t[keep], w[keep], f[keep]
    spans = spans[spans[:, 1] <= len(t)]
    cooling = high < low
    true_temp = low + (high - low) * t / duration
    accel_p, gyro_p = ramp_truth_params(truth, true_temp, cooling)
    mats = accel_p[:, :9].reshape(-1, 3, 3)
    accel = np.linalg.solve(mats, f[:, :, None])[:, :, 0] + accel_p[:, 9:]
    accel = accel + accel_noise_std * rng.standard_normal(accel.shape)

    def errors(temp):
        _, g = ramp_truth_params(truth, temp, cooling)
        return np.linalg.inv(g[:, :9].reshape(-1, 3, 3)), g[:, 9:]

    gyro = VirtualGyro(truth.imu(truth.ref_temp, False, accel_noise_std, gyro_kw).gyro.model, thermal=errors,
                       **gyro_kw).measure(w, sample_rate, rng, temp=true_temp)
    temp = true_temp + temp_noise * rng.standard_normal(len(t))
    rec = Recording(t=t, gyro=gyro, temp=temp, accel=accel, accel_units="m/s^2", accel_source_units="m/s^2")
    facts = {"low_degC": float(low), "high_degC": float(high), "rate_degC_per_min": float(rate),
             "duration_s": float(duration), "branch": "cooling" if cooling else "heating",
             "equation": "T(t) = low + (high - low) * t / duration_s", "still": spans.tolist()}
    return rec, facts
