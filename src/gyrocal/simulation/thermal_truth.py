"""A temperature-dependent true gyro shaped like the full-temperature-range method's Figures 4-6.

* scale factors (Kxx, Kyy, Kzz) linear in temperature (Figure 4);
* misalignment (off-diagonal K) constant (Figure 5);
* biases a smooth nonlinear (cubic) function of temperature (Figure 6);
* at the reference temperature, exactly the full-temperature-range method's eq. 23 vector (biases in deg/s there).

The default slopes and bias curves are our choice of plausible magnitudes (the
paper's figures give shapes, not numbers).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import finite_array
from ..errors import InputError

__all__ = ["EQ23_KG", "ThermalTruth", "eq23_kg"]

#: The full-temperature-range method, eq. 23: Kg at 25 degC in eq. 14 order; the last three (biases) in deg/s.
EQ23_KG: tuple[float, ...] = (1.0005, 1.0005, 1.0017, -0.0188, 0.0012, 0.0187,
                              5.2027e-4, -0.0011, -7.5133e-4, -0.0303, -0.0435, -0.0261)


def eq23_kg() -> np.ndarray:
    """Eq. 23 in internal units (biases converted to rad/s)."""
    kg = np.array(EQ23_KG)
    kg[9:] *= math.pi / 180.0
    return kg


@dataclass(frozen=True)
class ThermalTruth:
    """True ``K(T)``, ``B(T)`` of a simulated gyro; call it as ``truth(temp) -> (K, B)``.

    Parameters
    ----------
    kg_ref : array_like, shape (12,)
        Kg at `ref_temp` in internal units (default eq. 23).
    ref_temp : float
        Reference temperature [degC].
    scale_slope : array_like, shape (3,)
        d(Kxx, Kyy, Kzz)/dT [1/degC].
    bias_poly : array_like, shape (3, 3)
        Bias change [deg/s] per axis (rows) as coefficients of ``u, u^2, u^3`` with
        ``u = (T - ref_temp) / 50``.
    """

    kg_ref: tuple[float, ...] | np.ndarray = tuple(eq23_kg())
    ref_temp: float = 25.0
    scale_slope: tuple[float, float, float] = (2.0e-5, -1.5e-5, 1.8e-5)
    bias_poly: tuple = ((0.06, 0.08, 0.05), (-0.05, 0.06, -0.04), (0.04, -0.07, 0.03))

    def __post_init__(self):
        finite_array("kg_ref", self.kg_ref, shape_tail=(12,), ndim=1)
        finite_array("scale_slope", self.scale_slope, shape_tail=(3,), ndim=1)
        finite_array("bias_poly", self.bias_poly, shape_tail=(3, 3), ndim=2)
        if not math.isfinite(self.ref_temp):
            raise InputError(f"ref_temp must be finite [degC], got {self.ref_temp!r}")

    def kg(self, temp) -> np.ndarray:
        """True Kg (N, 12) at temperatures (N,) [degC], internal units."""
        t = np.atleast_1d(np.asarray(temp, dtype=float))
        kg = np.broadcast_to(np.asarray(self.kg_ref, float), t.shape + (12,)).copy()
        kg[:, :3] += np.outer(t - self.ref_temp, self.scale_slope)  # Figure 4: linear scale
        u = (t - self.ref_temp) / 50.0
        powers = np.stack([u, u * u, u ** 3], axis=1)
        kg[:, 9:] += powers @ np.asarray(self.bias_poly, float).T * (math.pi / 180.0)  # Figure 6: smooth bias
        return kg

    def gyro(self, noise_std: float = 0.0, **options):
        """A :class:`VirtualGyro` with these thermal errors and `noise_std` [rad/s] (other options passed on)."""
        from ..models import Affine
        from .gyro import VirtualGyro

        return VirtualGyro(model=Affine.from_kg(self.kg_ref), noise_std=noise_std, thermal=self, **options)

    def __call__(self, temp) -> tuple[np.ndarray, np.ndarray]:
        """``(K (N, 3, 3), B (N, 3) [rad/s])`` at temperatures (N,) [degC], for ``VirtualGyro(thermal=...)``."""
        from ..models import kg_to_kb

        return kg_to_kb(self.kg(temp))

    def to_dict(self) -> dict:
        """The truth's settings as plain JSON values (for a truth document)."""
        return {"ref_temp": self.ref_temp, "kg_ref": [float(v) for v in self.kg_ref],
                "scale_slope": [float(v) for v in self.scale_slope],
                "bias_poly_deg_s": [[float(v) for v in row] for row in self.bias_poly]}
