"""A simulated multi-position hand session as a board with a gyro and an accelerometer streams it.

A person follows the guide of :mod:`gyrocal.capture.pose_guide`: rests the board in each asked
orientation (off by a few degrees, at any heading) and turns it by hand to the next. The motion
and both sensors come from the project's simulator (:mod:`gyrocal.simulation.multiposition`: a
gyro mounted a few degrees off a 9-parameter accelerometer, the Earth's rotation, lever-arm
accelerations); this module turns the readings into MPU-6050 counts with the device's
microsecond stamps.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .. import quaternion as quat
from .._validation import positive
from ..imu.poses import UP
from ..models import ScaleBias
from ..segmentation.windows import Window
from ..simulation import VirtualGyro
from ..simulation.multiposition import (
    MultiPositionProtocol,
    VirtualImu,
    mounted_gyro,
    random_accelerometer,
    simulate_multi_position,
)
from ..units import STANDARD_GRAVITY
from .simulated import MPU6050_ACCEL_SENSITIVITY, MPU6050_SENSITIVITY, DeviceSession, _temperature, counts

__all__ = ["orientation_up", "simulate_device_imu_session", "z_scores"]

#: MPU-6050 noise densities: gyro 0.005 deg/s/sqrt(Hz), accelerometer 400 ug/sqrt(Hz).
GYRO_DENSITY = math.radians(0.005)
ACCEL_DENSITY = 400e-6 * STANDARD_GRAVITY


def orientation_up(up, heading: float = 0.0) -> np.ndarray:
    """The body orientation (body to world quaternion) in which the sensor direction `up` points up,
    turned by `heading` [rad] about the vertical."""
    u = np.asarray(up, float) / np.linalg.norm(up)
    axis = np.cross(u, UP)
    s = np.linalg.norm(axis)
    if s < 1e-9:
        tilt = np.zeros(3) if u @ UP > 0 else np.array([math.pi, 0.0, 0.0])
    else:
        tilt = axis / s * math.atan2(s, float(u @ UP))
    return quat.multiply(quat.from_rotvec(UP * heading), quat.from_rotvec(tilt))


def _shorten(arrays: list[np.ndarray], still: np.ndarray, short: dict[int, float], fs: float):
    """Cut the still time of poses `short` (index -> seconds left) out of the middle of their stillness."""
    cut = np.zeros(len(arrays[0]), bool)
    for k, keep in short.items():
        a, b = still[k]
        cut[a + 1: b - int(round(keep * fs))] = True
    shift = np.concatenate([[0], np.cumsum(cut)])
    spans = np.array([[a - shift[a], b - shift[b]] for a, b in still])
    return [x[~cut] for x in arrays], spans


def simulate_device_imu_session(directions: Sequence, *, rng: np.random.Generator, sample_rate: float = 100.0,
                                model: ScaleBias | None = None, misalignment_deg: float = 3.0,
                                aim_deg: float = 3.0, still: tuple[float, float] = (2.5, 3.5),
                                short: dict[int, float] | None = None, sensitivity: float = MPU6050_SENSITIVITY,
                                accel_sensitivity: int = MPU6050_ACCEL_SENSITIVITY,
                                temp: float | None = 25.0) -> DeviceSession:
    """A multi-position hand session through the poses whose gravity directions are `directions` (k, 3).

    Parameters
    ----------
    directions : array_like, shape (k, 3)
        Sensor direction pointing up in each pose (:func:`gyrocal.capture.pose_guide.guided_directions`
        for a person who follows the guide).
    rng : numpy.random.Generator
        All randomness: the sensors' errors and noise, the headings, the aim and the moves.
    model : ScaleBias, optional
        The gyro's scale and bias [rad/s] before it is mounted `misalignment_deg` off the accelerometer.
    aim_deg : float
        How far off each asked direction the person rests the board (1-sigma per axis) [deg].
    still : (float, float)
        Range of the still time in each pose [s] (the first pose rests 3 s).
    short : dict of int to float, optional
        Poses (by index) held only this long [s]: the rest of their stillness is cut out.
    """
    fs = positive("sample_rate", sample_rate)
    model = model or ScaleBias(k=np.array([1.02, 0.985, 1.01]), b=np.radians([1.5, -2.0, 0.8]))
    gyro = mounted_gyro(model, misalignment_deg, rng)
    a, o = random_accelerometer(rng)
    imu = VirtualImu(VirtualGyro(gyro, noise_std=GYRO_DENSITY * math.sqrt(fs)), accel_matrix=a, accel_offset=o,
                     accel_noise_std=ACCEL_DENSITY * math.sqrt(fs))
    ups = np.asarray(directions, float)
    ups = ups + rng.normal(0.0, math.radians(aim_deg), ups.shape)
    q = np.array([orientation_up(u, rng.uniform(-math.pi, math.pi)) for u in ups])
    proto = MultiPositionProtocol(orientations=q, static_duration=still, first_static=3.0, sample_rate=fs)
    s = simulate_multi_position(imu, proto, rng=rng)
    (gyro_r, accel_r), spans = _shorten([s.gyro, s.accel], s.still, short or {}, fs)
    n = len(gyro_r)
    g = s.truth["gravity"]
    t_us = np.round(np.arange(n) * (1e6 / fs)).astype(np.int64) + 1_000_000
    windows = tuple(Window(int(lo), int(hi), "static", label=f"pose {i + 1}") for i, (lo, hi) in enumerate(spans))
    return DeviceSession(counts(np.degrees(gyro_r) * sensitivity), t_us, _temperature(temp, n), fs, sensitivity,
                         gyro, windows, accel=counts(accel_r / g * accel_sensitivity),
                         accel_sensitivity=int(accel_sensitivity), truth=dict(s.truth))


def z_scores(result, truth: dict) -> np.ndarray:
    """``(estimate - truth) / reported 1-sigma`` of a whole-IMU calibration (:class:`~gyrocal.imu.session.
    ImuCalibrationResult`, internal units) of a simulated session: the accelerometer's parameters in its
    model's order (``param_names``), then the gyro's correction matrix (row-major) and offset."""
    a, g = result.accel, result.gyro
    xyz = "xyz".index

    def entry(m, o, name):
        return m[xyz(name[2]), xyz(name[3])] if name[0] == "A" else o[xyz(name[2])]

    za = [(entry(a.matrix, a.offset, n) - entry(truth["accel_matrix"], truth["accel_offset"], n)) / sd
          for n, sd in zip(a.param_names, a.std)]
    n = g.matrix.size
    zg = (np.r_[g.matrix.ravel(), g.offset] - np.r_[truth["gyro_matrix"].ravel(), truth["gyro_offset"]]) / g.std[:n + 3]
    return np.r_[za, zg]
