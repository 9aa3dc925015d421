"""A chamber session of a whole IMU: a multi-position session at each temperature point, with the truth.

The board's 24 parameters follow cubics in temperature (:class:`ImuThermalTruth`): the
accelerometer's 12 (its correction matrix ``A`` row-major, then its offset ``o``; ``f = A (u - o)``)
and the gyro's 12 (its correction matrix ``M`` row-major, then its offset ``b``; ``w = M (m - b)``),
each ``p(T) = sum_k c_k x^k`` with ``x = (T - ref_temp) / scale``. ``A`` is lower triangular at every
temperature, so the frame ``gyrocal imu`` writes in (corrected x along the sensor's x, y in its xy
plane) is the truth's own. A point reached while cooling (colder than the point before it) sits on
the cooling branch: its accelerometer offsets are moved by the hysteresis.

At each point the chamber soaks (not recorded: the log jumps in time by the soak) and a full pose
sequence is taken (:func:`~gyrocal.simulation.multiposition.simulate_multi_position` with that
temperature's sensors); the temperature column reads the point plus white noise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import at_least, finite_array
from ..errors import InputError
from ..units import STANDARD_GRAVITY
from .multiposition import MultiPositionProtocol, VirtualImu, mounted_gyro, simulate_multi_position

__all__ = ["ImuThermalTruth", "chamber_session", "random_thermal_imu"]

_DIAG = np.array([0, 4, 8])
_LOWER = np.array([3, 6, 7])


@dataclass(frozen=True)
class ImuThermalTruth:
    """True parameters of both sensors as cubics in temperature.

    Parameters
    ----------
    accel_coefs : array_like, shape (12, 4)
        Coefficients of ``x^0..x^3`` of ``A`` (row-major, lower triangular) and ``o`` [m/s^2].
    gyro_coefs : array_like, shape (12, 4)
        Of ``M`` (row-major) and ``b`` [rad/s].
    ref_temp, scale : float
        ``x = (T - ref_temp) / scale`` [degC].
    hysteresis : array_like, shape (3,)
        Added to the accelerometer's offsets on the cooling branch [m/s^2].
    """

    accel_coefs: np.ndarray
    gyro_coefs: np.ndarray
    ref_temp: float = 25.0
    scale: float = 50.0
    hysteresis: tuple[float, float, float] | np.ndarray = (0.0, 0.0, 0.0)

    def __post_init__(self):
        for name, shape in (("accel_coefs", (12, 4)), ("gyro_coefs", (12, 4)), ("hysteresis", (3,))):
            object.__setattr__(self, name, finite_array(name, getattr(self, name), shape_tail=shape,
                                                        ndim=len(shape)))
        if np.any(self.accel_coefs[[1, 2, 5], :] != 0):
            raise InputError("accel_coefs: A must be lower triangular (rows x, y have no entry right of the diagonal)")

    def params(self, temp, cooling: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """The accelerometer's and the gyro's 12 parameters at `temp` [degC] on the heating or cooling branch."""
        powers = ((float(temp) - self.ref_temp) / self.scale) ** np.arange(4)
        accel, gyro = self.accel_coefs @ powers, self.gyro_coefs @ powers
        if cooling:
            accel[9:] += self.hysteresis
        return accel, gyro

    def imu(self, temp, cooling: bool, accel_noise_std: float, gyro_kw: dict) -> VirtualImu:
        """The :class:`VirtualImu` at `temp` [degC] (gyro options `gyro_kw` of :class:`VirtualGyro`)."""
        from ..models import Affine
        from .gyro import VirtualGyro

        accel, gyro = self.params(temp, cooling)
        readings = Affine(K=np.linalg.inv(gyro[:9].reshape(3, 3)), B=gyro[9:])
        return VirtualImu(VirtualGyro(readings, **gyro_kw), accel_matrix=accel[:9].reshape(3, 3),
                          accel_offset=accel[9:], accel_noise_std=accel_noise_std)

    def to_dict(self) -> dict:
        """The truth as plain JSON values (for the truth file)."""
        return {"ref_temp_degC": self.ref_temp, "scale_degC": self.scale,
                "equation": "p(T) = sum_k coefs[:, k] * ((T - ref_temp_degC) / scale_degC)**k",
                "accelerometer": {"names": [f"A_{r}{c}" for r in "xyz" for c in "xyz"] + ["o_x", "o_y", "o_z"],
                                  "coefs": self.accel_coefs.tolist(), "units": "m/s^2",
                                  "equation": "a_true = A @ (raw - o)"},
                "gyro": {"names": [f"M_{r}{c}" for r in "xyz" for c in "xyz"] + ["b_x", "b_y", "b_z"],
                         "coefs": self.gyro_coefs.tolist(), "units": "rad/s", "equation": "w_true = M @ (raw - b)"},
                "hysteresis": {"accel_offset": self.hysteresis.tolist(), "units": "m/s^2",
                               "equation": "cooling branch: o(T) + accel_offset"}}


def random_thermal_imu(gyro_model, rng: np.random.Generator, *, misalignment_deg: float = 5.0,
                       hysteresis: float = 0.0) -> ImuThermalTruth:
    """A plausible board: accelerometer sensitivity drifting about 0.02 %/degC and offsets about 0.1 g over
    -25..+60 degC (cubics), the gyro (`gyro_model` mounted `misalignment_deg` off) drifting 1e-4/degC in scale
    and about 0.002 deg/s/degC in bias; `hysteresis` [m/s^2] on each accelerometer offset, sign drawn."""
    a = np.zeros((12, 4))
    a[_DIAG, 0] = rng.uniform(0.98, 1.02, 3)
    a[_LOWER, 0] = rng.normal(0.0, np.radians(0.5), 3)
    a[_DIAG, 1] = rng.choice([-1.0, 1.0], 3) * rng.uniform(0.7, 1.0, 3) * 1e-2
    a[_DIAG, 2:] = rng.normal(0.0, 1e-3, (3, 2))
    a[_LOWER, 1] = rng.normal(0.0, 2e-4, 3)
    sign = rng.choice([-1.0, 1.0], 3)
    a[9:, 0] = rng.normal(0.0, 0.1, 3)
    a[9:, 1:] = sign[:, None] * 0.1 * STANDARD_GRAVITY * np.array([0.4, 0.15, 0.1]) * rng.uniform(0.7, 1.0, (3, 1))
    aff = mounted_gyro(gyro_model, misalignment_deg, rng)
    g = np.zeros((12, 4))
    g[:9, 0] = np.linalg.inv(aff.K).ravel()
    g[9:, 0] = aff.B
    g[_DIAG, 1] = rng.normal(0.0, 5e-3, 3)
    g[_DIAG, 3] = rng.normal(0.0, 1e-3, 3)
    g[9:, 1] = rng.normal(0.0, np.radians(0.1), 3)
    g[9:, 2:] = rng.normal(0.0, np.radians(0.03), (3, 2))
    return ImuThermalTruth(a, g, hysteresis=rng.choice([-1.0, 1.0], 3) * hysteresis)


def chamber_session(truth: ImuThermalTruth, temps, *, gyro_kw: dict, poses: int = 24, tilt_deg: float = 90.0,
                    still: float = 3.0, soak: float = 600.0, accel_noise_std: float = 0.02, temp_noise: float = 0.0,
                    sample_rate: float = 100.0, rng: np.random.Generator):
    """A pose sequence at each of `temps` [degC], `soak` s unrecorded before each but the first.

    Returns
    -------
    (Recording, dict)
        The log (gyro rad/s, accelerometer m/s^2, temp degC) and the points' truth: temperature, branch,
        samples, and both sensors' parameters there.
    """
    from ..recording import Recording

    temps = [float(x) for x in finite_array("temps", temps, ndim=1)]
    if len(temps) < 1:
        raise InputError("give at least one temperature point [degC]")
    at_least("soak", soak, 0.0, " s")
    at_least("temp_noise", temp_noise, 0.0, " degC")
    proto = MultiPositionProtocol(poses=poses, turn_deg=tilt_deg, static_duration=(0.75 * still, 1.25 * still),
                                  sample_rate=sample_rate)
    parts, points, t0, n0 = [], [], 0.0, 0
    for k, temp in enumerate(temps):
        cooling = k > 0 and temp < temps[k - 1]
        s = simulate_multi_position(truth.imu(temp, cooling, accel_noise_std, gyro_kw), proto, rng=rng)
        parts.append((s.t + t0, s.gyro, s.accel, temp + temp_noise * rng.standard_normal(len(s.t))))
        accel, gyro = truth.params(temp, cooling)
        points.append({"temperature_degC": temp, "branch": "cooling" if cooling else "heating",
                       "samples": [n0, n0 + len(s.t)], "accelerometer": accel.tolist(), "gyro": gyro.tolist()})
        t0, n0 = t0 + s.t[-1] + 1.0 / sample_rate + soak, n0 + len(s.t)
    t, gyro, accel, temp = (np.concatenate(c) for c in zip(*parts))
    rec = Recording(t=t, gyro=gyro, temp=temp, accel=accel, accel_units="m/s^2", accel_source_units="m/s^2")
    return rec, points
