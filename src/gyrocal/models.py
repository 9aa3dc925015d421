"""Calibration models and their one canonical correction.

Both papers' models are affine maps from a reading ``m`` to the true rate; gyrocal
stores each in the canonical form

    w_true = A (m - o)

and keeps each paper's own parameters, converting exactly in both directions:

* :class:`ScaleBias` (the servo method of Wang et al., eq. 1): ``g = diag(k) (m + b)``, so ``A = diag(k)``, ``o = -b``.
* :class:`Affine` (the full-temperature-range method, eq. 12): ``w = K w~ + B``, so ``A = K^-1``, ``o = B``.

Models are unit-agnostic numbers: ``o`` is in the units of the readings and ``A``
maps reading units to output units. The package keeps both in rad/s inside; files
record units explicitly (see :mod:`gyrocal.results.calibration`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ._arrays import readonly, rows_times
from ._validation import finite_array, vector3
from .errors import InputError, NonPhysicalEstimateError

__all__ = ["KG_INDEX", "KG_NAMES", "Affine", "CalibrationModel", "ScaleBias", "correct", "kb_to_kg", "kg_to_kb"]

#: The full-temperature-range method, eq. 14: element order of the 12-vector Kg.
KG_NAMES: tuple[str, ...] = ("Kxx", "Kyy", "Kzz", "Kyx", "Kzx", "Kxy", "Kzy", "Kxz", "Kyz", "Bx", "By", "Bz")
#: Position in K (eq. 11) of each of the first nine Kg elements.
#: K = [[Kxx, Kyx, Kzx], [Kxy, Kyy, Kzy], [Kxz, Kyz, Kzz]], so row = output axis, column = input axis.
KG_INDEX: tuple[tuple[int, int], ...] = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1))
_KG_ROWS = np.array([r for r, _ in KG_INDEX])
_KG_COLS = np.array([c for _, c in KG_INDEX])


def kg_to_kb(kg) -> tuple[np.ndarray, np.ndarray]:
    """``K`` (..., 3, 3) and ``B`` (..., 3) from Kg vectors (..., 12): the one Kg -> K mapping (eq. 11, 14).

    The C library's ``gyrocal_thermal_correct`` unpacks Kg the same way; a test ties the two.
    """
    kg = np.asarray(kg, dtype=float)
    K = np.zeros(kg.shape[:-1] + (3, 3))
    K[..., _KG_ROWS, _KG_COLS] = kg[..., :9]
    return K, kg[..., 9:].copy()


def kb_to_kg(K, B) -> np.ndarray:
    """Kg vectors (..., 12) from ``K`` (..., 3, 3) and ``B`` (..., 3): the inverse of :func:`kg_to_kb`."""
    K = np.asarray(K, dtype=float)
    return np.concatenate([K[..., _KG_ROWS, _KG_COLS], np.asarray(B, dtype=float)], axis=-1)


def correct(matrix: np.ndarray, offset: np.ndarray, readings) -> np.ndarray:
    """Apply ``w_true = matrix @ (m - offset)`` to readings of shape (..., 3) [reading units]."""
    m = finite_array("readings", readings, shape_tail=(3,))
    if m.ndim != 2 or len(m) <= _CHUNK_ROWS:
        return rows_times(m - offset, matrix)
    out = np.empty(m.shape)
    for s in range(0, len(m), _CHUNK_ROWS):  # bounded temporaries: a long log is not held twice more
        out[s:s + _CHUNK_ROWS] = rows_times(m[s:s + _CHUNK_ROWS] - offset, matrix)
    return out


#: Rows corrected at a time by :func:`correct`.
_CHUNK_ROWS = 1 << 16


@dataclass(frozen=True)
class ScaleBias:
    """Per-axis scale and bias, the servo method of Wang et al., eq. 1: ``g = diag(k) (m + b)``.

    Parameters
    ----------
    k : array_like, shape (3,)
        Scale factors [output units per reading unit], all > 0.
    b : array_like, shape (3,)
        Additive biases [reading units]. Note the sign: ``b`` is added to the
        reading, so it is minus the usual zero-rate offset.
    """

    k: np.ndarray
    b: np.ndarray
    kind: ClassVar[str] = "scale-bias"
    param_names: ClassVar[tuple[str, ...]] = ("kx", "ky", "kz", "bx", "by", "bz")

    def __post_init__(self):
        k = vector3("k", self.k)
        if np.any(k <= 0):
            raise NonPhysicalEstimateError(f"scale factors k must be > 0, got {k.tolist()}")
        object.__setattr__(self, "k", readonly(k, copy=True))
        object.__setattr__(self, "b", readonly(vector3("b", self.b), copy=True))

    @property
    def matrix(self) -> np.ndarray:
        """Canonical ``A = diag(k)``."""
        return np.diag(self.k)

    @property
    def offset(self) -> np.ndarray:
        """Canonical ``o = -b`` [reading units]."""
        return -self.b

    @property
    def params(self) -> np.ndarray:
        """Parameter vector in :attr:`param_names` order."""
        return np.concatenate([self.k, self.b])

    @classmethod
    def from_params(cls, params) -> ScaleBias:
        p = finite_array("params", params, shape_tail=(6,), ndim=1)
        return cls(k=p[:3], b=p[3:])

    @classmethod
    def from_canonical(cls, matrix, offset) -> ScaleBias:
        """Exact inverse of (:attr:`matrix`, :attr:`offset`); `matrix` must be diagonal."""
        a = finite_array("matrix", matrix, shape_tail=(3, 3), ndim=2)
        if np.any(a[~np.eye(3, dtype=bool)] != 0):
            raise InputError("matrix has off-diagonal terms; a scale-bias model needs a diagonal matrix (use Affine)")
        return cls(k=np.diag(a).copy(), b=-vector3("offset", offset))

    def correct(self, readings) -> np.ndarray:
        """True rates from readings of shape (..., 3): ``diag(k) (m + b)``."""
        return correct(self.matrix, self.offset, readings)

    def distort(self, true_rates) -> np.ndarray:
        """Readings a gyro with this model would give for `true_rates` (noise-free inverse)."""
        w = finite_array("true_rates", true_rates, shape_tail=(3,))
        return w / self.k - self.b

    def to_affine(self) -> Affine:
        """The same map as an :class:`Affine` model (``K = diag(1/k)``, ``B = -b``)."""
        return Affine.from_canonical(self.matrix, self.offset)

    def to_dict(self) -> dict:
        """The servo method's parameters (Wang et al., eq. 1), as plain lists."""
        return {"k": self.k.tolist(), "b": self.b.tolist()}


@dataclass(frozen=True)
class Affine:
    """Full 12-parameter model, the full-temperature-range method, eq. 12: ``w = K w~ + B``.

    Parameters
    ----------
    K : array_like, shape (3, 3)
        Scale, package misalignment and non-orthogonality [reading units per output unit];
        eq. 11 layout, row = gyro axis, column = reference axis. Must be invertible.
    B : array_like, shape (3,)
        Bias [reading units].
    """

    K: np.ndarray
    B: np.ndarray
    kind: ClassVar[str] = "affine"
    param_names: ClassVar[tuple[str, ...]] = KG_NAMES

    def __post_init__(self):
        K = finite_array("K", self.K, shape_tail=(3, 3), ndim=2)
        cond = np.linalg.cond(K)
        if not np.isfinite(cond) or cond > 1e12:
            raise NonPhysicalEstimateError(f"K is singular (condition number {cond:.3g}); it cannot be inverted")
        object.__setattr__(self, "K", readonly(K, copy=True))
        object.__setattr__(self, "B", readonly(vector3("B", self.B), copy=True))

    @property
    def matrix(self) -> np.ndarray:
        """Canonical ``A = K^-1``."""
        return np.linalg.inv(self.K)

    @property
    def offset(self) -> np.ndarray:
        """Canonical ``o = B`` [reading units]."""
        return np.array(self.B)

    @property
    def kg(self) -> np.ndarray:
        """The full-temperature-range method, eq. 14 12-vector ``[Kxx, Kyy, Kzz, Kyx, Kzx, Kxy, Kzy, Kxz, Kyz, Bx, By, Bz]``."""
        return kb_to_kg(self.K, self.B)

    @property
    def params(self) -> np.ndarray:
        """Parameter vector in :attr:`param_names` (Kg) order."""
        return self.kg

    @classmethod
    def from_kg(cls, kg) -> Affine:
        """Build from the full-temperature-range method 12-vector (eq. 14 order)."""
        return cls(*kg_to_kb(finite_array("kg", kg, shape_tail=(12,), ndim=1)))

    from_params = from_kg

    @classmethod
    def from_canonical(cls, matrix, offset) -> Affine:
        """Exact inverse of (:attr:`matrix`, :attr:`offset`)."""
        a = finite_array("matrix", matrix, shape_tail=(3, 3), ndim=2)
        if np.linalg.cond(a) > 1e12:
            raise NonPhysicalEstimateError("correction matrix is singular; it cannot describe a gyro")
        return cls(K=np.linalg.inv(a), B=vector3("offset", offset))

    def correct(self, readings) -> np.ndarray:
        """True rates from readings of shape (..., 3): ``K^-1 (w - B)``."""
        return correct(self.matrix, self.offset, readings)

    def distort(self, true_rates) -> np.ndarray:
        """Readings for `true_rates` (noise-free): ``K w~ + B``."""
        w = finite_array("true_rates", true_rates, shape_tail=(3,))
        return rows_times(w, self.K) + self.B

    def to_affine(self) -> Affine:
        return self

    def to_dict(self) -> dict:
        """The full-temperature-range method's parameters: K, B, and Kg in eq. 14 order with that order."""
        return {"K": self.K.tolist(), "B": self.B.tolist(), "kg": self.kg.tolist(), "kg_order": list(KG_NAMES)}


CalibrationModel = ScaleBias | Affine
