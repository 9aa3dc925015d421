"""A second log of the same motion: a reference gyro on its own clock, mount and rate.

The servo method of Wang et al. validates a calibration against a pre-calibrated
high-grade gyro (an ADIS16465) mounted beside the one under test. This module simulates
that second sensor for any simulated test log:

* the motion is the test log's true body rate, linearly interpolated between its samples
  on the test clock (the continuous motion the reference samples);
* the reference's clock runs ``t_test = t_ref * (1 + clock_drift_ppm * 1e-6) + time_offset_s``
  and samples every ``1 / sample_rate`` of its own seconds, covering the test log's span;
* its frame is turned by ``mounting_rotation`` (reference frame to test frame:
  ``w_test = mounting_rotation @ w_ref``);
* it reads through its own :class:`~gyrocal.simulation.VirtualGyro` (noise, residual
  errors, quantisation).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .._validation import finite_array, positive
from ..errors import InputError
from ..recording import Recording
from .gyro import VirtualGyro
from .servo import _random_rotation

__all__ = ["ADIS16465_NOISE_DENSITY", "ReferenceTruth", "simulate_reference"]

#: White-noise density of an ADIS16465, the reference of the servo method of Wang et al.:
#: an angle random walk of 0.15 deg/sqrt(h) is 0.0025 deg/s/sqrt(Hz) [rad/s/sqrt(Hz)].
ADIS16465_NOISE_DENSITY = math.radians(0.0025)


@dataclass(frozen=True)
class ReferenceTruth:
    """What the simulated reference log really is.

    Attributes
    ----------
    time_offset_s : float
        ``t_test = t_ref * (1 + clock_drift_ppm * 1e-6) + time_offset_s`` [s].
    clock_drift_ppm : float
        [ppm].
    mounting_rotation : ndarray, shape (3, 3)
        Reference frame to test frame.
    sample_rate : float
        The reference's rate on its own clock [Hz].
    gyro : VirtualGyro
        The reference sensor.
    """

    time_offset_s: float
    clock_drift_ppm: float
    mounting_rotation: np.ndarray
    sample_rate: float
    gyro: VirtualGyro

    @property
    def mounting_rotation_deg(self) -> float:
        """Angle of the mounting rotation [deg]."""
        return math.degrees(float(np.linalg.norm(Rotation.from_matrix(self.mounting_rotation).as_rotvec())))

    def to_dict(self) -> dict:
        """JSON-ready truth (rates and noise in rad/s)."""
        aff = self.gyro.model.to_affine()
        return {
            "time_offset_s": self.time_offset_s, "clock_drift_ppm": self.clock_drift_ppm,
            "clock": "t_test = t_ref * (1 + clock_drift_ppm * 1e-6) + time_offset_s",
            "mounting_rotation": self.mounting_rotation.tolist(),
            "mounting_rotation_deg": self.mounting_rotation_deg,
            "mounting": "w_test = mounting_rotation @ w_ref",
            "sample_rate": self.sample_rate,
            "noise_std": np.broadcast_to(np.asarray(self.gyro.noise_std, float), (3,)).tolist(),
            "K": aff.K.tolist(), "B": aff.B.tolist(),
        }


def simulate_reference(
    t_test,
    rates,
    gyro: VirtualGyro,
    *,
    sample_rate: float = 100.0,
    time_offset_s: float = 0.0,
    clock_drift_ppm: float = 0.0,
    mounting_rotation=None,
    mounting_deg: float = 0.0,
    rng: np.random.Generator,
) -> tuple[Recording, ReferenceTruth]:
    """Record the motion of a simulated test log with a second, reference gyro.

    Parameters
    ----------
    t_test : array_like, shape (N,)
        Test sample times on the test clock [s].
    rates : array_like, shape (N, 3)
        True body rates of the test sensor at those times [rad/s].
    gyro : VirtualGyro
        The reference sensor (noise, residual errors) [rad/s].
    sample_rate : float
        Reference rate on its own clock [Hz].
    time_offset_s, clock_drift_ppm : float
        Clock relation, see the module docstring [s], [ppm]; |drift| < 1e5 ppm.
    mounting_rotation : array_like, shape (3, 3), optional
        Reference frame to test frame; default: a rotation of `mounting_deg` about an axis
        drawn from `rng`.
    mounting_deg : float
        Angle of the drawn rotation [deg], used when `mounting_rotation` is not given.
    rng : numpy.random.Generator

    Returns
    -------
    recording : Recording
        The reference log [rad/s], its times on its own clock [s].
    truth : ReferenceTruth
    """
    t = finite_array("t_test", t_test, ndim=1)
    w = finite_array("rates", rates, shape_tail=(3,), ndim=2)
    if len(t) != len(w) or len(t) < 2:
        raise InputError(f"t_test and rates must have one row per sample (>= 2), got {len(t)} and {len(w)}")
    fs = positive("sample_rate", sample_rate)
    if not math.isfinite(time_offset_s):
        raise InputError(f"{{param}} must be a finite time [s], got {time_offset_s!r}", param="time_offset_s")
    if not (math.isfinite(clock_drift_ppm) and abs(clock_drift_ppm) < 1e5):
        raise InputError(f"{{param}} must be finite and below 1e5 ppm in size, got {clock_drift_ppm!r}",
                         param="clock_drift_ppm")
    rot = _mounting(mounting_rotation, mounting_deg, rng)
    scale = 1.0 + clock_drift_ppm * 1e-6
    first = math.ceil((t[0] - time_offset_s) / scale * fs)
    last = math.floor((t[-1] - time_offset_s) / scale * fs)
    if last - first < 1:
        raise InputError(f"a reference at {fs:g} Hz gets fewer than 2 samples within the test log's span",
                         param="sample_rate")
    t_ref = np.arange(first, last + 1) / fs
    t_on_test = np.clip(t_ref * scale + time_offset_s, t[0], t[-1])  # rounding at the ends
    body = np.stack([np.interp(t_on_test, t, w[:, j]) for j in range(3)], axis=1)
    readings = gyro.measure(body @ rot, fs, rng)  # w_ref = R^T w_test, row-wise
    rec = Recording(t=t_ref, gyro=readings, units="rad/s", source_units="rad/s", sample_rate=fs)
    rot.setflags(write=False)
    return rec, ReferenceTruth(float(time_offset_s), float(clock_drift_ppm), rot, fs, gyro)


def _mounting(mounting_rotation, mounting_deg: float, rng: np.random.Generator) -> np.ndarray:
    if mounting_rotation is None:
        if not 0 <= mounting_deg <= 180:
            raise InputError(f"{{param}} must be in [0, 180] deg, got {mounting_deg!r}", param="mounting_deg")
        return np.array(_random_rotation(float(mounting_deg), rng))
    rot = finite_array("mounting_rotation", mounting_rotation, shape_tail=(3, 3), ndim=2)
    if not (np.allclose(rot @ rot.T, np.eye(3), atol=1e-9) and np.linalg.det(rot) > 0):
        raise InputError("{param} must be a proper rotation matrix (orthonormal, determinant +1)",
                         param="mounting_rotation")
    return rot.copy()
