"""A virtual triaxial gyroscope: deterministic errors, noise, quantisation, saturation.

Readings follow the full-temperature-range method, eq. 12, ``m = K(T) w + B(T) + noise``, which covers the
the model of the servo method of Wang et al. too (``K = diag(1/k)``, ``B = -b``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np

from .._validation import finite_array
from ..errors import InputError
from ..models import CalibrationModel

__all__ = ["VirtualGyro", "ThermalErrors", "noise_std_from_density"]


class ThermalErrors(Protocol):
    """Temperature-dependent errors: ``errors(temp) -> (K, B)`` with shapes (N, 3, 3) and (N, 3)."""

    def __call__(self, temp: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...


def noise_std_from_density(density: float, sample_rate: float) -> float:
    """Per-sample white-noise standard deviation [rad/s] from a noise density [rad/s/sqrt(Hz)]."""
    return float(density) * float(np.sqrt(sample_rate))


@dataclass(frozen=True)
class VirtualGyro:
    """A simulated gyro.

    Parameters
    ----------
    model : ScaleBias or Affine
        True deterministic errors at the reference temperature; ignored where
        `thermal` is given.
    noise_std : float or array_like of shape (3,)
        Per-sample white noise [rad/s] (the servo method of Wang et al. simulates 0.035 and 0.2).
    bias_instability : float
        Standard deviation of a first-order Gauss–Markov bias [rad/s]; 0 for none.
    bias_tau : float
        Correlation time of that bias [s].
    rate_random_walk : float
        Rate random walk coefficient [rad/s/sqrt(s)]; 0 for none.
    quantum : float, optional
        Output resolution [rad/s]; readings are rounded to multiples of it.
    full_scale : float, optional
        Saturation limit [rad/s]; readings are clipped to +-full_scale.
    thermal : callable, optional
        ``thermal(temp) -> (K, B)`` per sample (see :class:`ThermalErrors`).
    """

    model: CalibrationModel
    noise_std: float | tuple[float, float, float] = 0.0
    bias_instability: float = 0.0
    bias_tau: float = 100.0
    rate_random_walk: float = 0.0
    quantum: float | None = None
    full_scale: float | None = None
    thermal: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None

    def __post_init__(self):
        sd = np.broadcast_to(np.asarray(self.noise_std, dtype=float), (3,))
        if not np.all(np.isfinite(sd)) or np.any(sd < 0):
            raise InputError(f"{{param}} must be >= 0, got {self.noise_std!r}", param="noise_std")
        for name in ("bias_instability", "rate_random_walk"):
            if not getattr(self, name) >= 0:
                raise InputError(f"{{param}} must be >= 0, got {getattr(self, name)!r}", param=name)
        for name in ("quantum", "full_scale"):
            value = getattr(self, name)
            if value is not None and not value > 0:
                raise InputError(f"{{param}} must be > 0 when given, got {value!r}", param=name)

    def errors(self, n: int, temp: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """Deterministic ``(K, B)``, broadcastable against n samples."""
        if self.thermal is None:
            aff = self.model.to_affine()
            return aff.K[None], aff.B[None]
        if temp is None:
            raise InputError("this virtual gyro has thermal errors; give a temperature for every sample")
        return self.thermal(np.broadcast_to(np.asarray(temp, dtype=float), (n,)))

    def ideal(self, true_rates, temp=None) -> np.ndarray:
        """Noise-free readings (N, 3) for true rates (N, 3) [rad/s]."""
        w = finite_array("true_rates", true_rates, shape_tail=(3,), ndim=2)
        K, B = self.errors(len(w), temp)
        return np.einsum("nij,nj->ni", np.broadcast_to(K, (len(w), 3, 3)), w) + B

    def measure(self, true_rates, sample_rate: float, rng: np.random.Generator, temp=None) -> np.ndarray:
        """Readings (N, 3) [rad/s] for true rates (N, 3) sampled at `sample_rate` [Hz]."""
        m = self.ideal(true_rates, temp)
        n, dt = len(m), 1.0 / float(sample_rate)
        m = m + rng.standard_normal((n, 3)) * np.asarray(self.noise_std, dtype=float)
        if self.bias_instability > 0:
            a = np.exp(-dt / self.bias_tau)
            drive = rng.standard_normal((n, 3)) * self.bias_instability * np.sqrt(1 - a * a)
            m = m + _ar1(drive, a, rng.standard_normal(3) * self.bias_instability)
        if self.rate_random_walk > 0:
            m = m + np.cumsum(rng.standard_normal((n, 3)) * self.rate_random_walk * np.sqrt(dt), axis=0)
        if self.quantum is not None:
            m = np.round(m / self.quantum) * self.quantum
        if self.full_scale is not None:
            m = np.clip(m, -self.full_scale, self.full_scale)
        return m


def _ar1(drive: np.ndarray, a: float, x0: np.ndarray) -> np.ndarray:
    """x[i] = a x[i-1] + drive[i], vectorised with a linear filter."""
    from scipy.signal import lfilter

    out, _ = lfilter([1.0], [1.0, -a], drive, axis=0, zi=(a * x0)[None, :])
    return out
