"""Frozen results returned by every estimator."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import readonly
from ..choices import Method
from ..models import ScaleBias

__all__ = ["BatchFit", "FitResult", "Method"]



def _frozen(value, dtype=float) -> np.ndarray:
    """A read-only view of `value`: no copy of large batch arrays that already have `dtype`."""
    return readonly(value, dtype, copy=False)


@dataclass(frozen=True)
class BatchFit:
    """Estimates for a batch of ``B`` gyros (arrays lead with the batch axis).

    Attributes
    ----------
    k, b : ndarray, shape (B, 3)
        Scale factors and biases of the servo method of Wang et al. [b in reading units].
    iterations : ndarray of int, shape (B,)
    converged : ndarray of bool, shape (B,)
    residuals : ndarray, shape (B, m)
        Final residual of each equation, in the method's own residual units.
    covariance : ndarray, shape (B, 6, 6), or None
        Parameter covariance in ``(k, b)`` order, where the method defines one.
    noise_std : ndarray, shape (B, 3), or None
        Per-sample noise standard deviation the covariance assumed [reading units].
    history : ndarray, shape (B, iterations_max + 1, 6)
        ``(k, b)`` after each iteration (index 0 is the initial estimate); rows past an
        item's own iteration count repeat its final value. For the first-moment closed
        form, index 0 is the ``beta0 = 0`` estimate and each row a Newton step on ``beta0``.

    Large arrays may be read-only views of batch-last storage rather than C-contiguous.
    """

    method: Method
    k: np.ndarray
    b: np.ndarray
    iterations: np.ndarray
    converged: np.ndarray
    residuals: np.ndarray
    covariance: np.ndarray | None
    noise_std: np.ndarray | None
    history: np.ndarray

    def __post_init__(self):
        B = np.shape(self.k)[0]
        for name in ("k", "b"):
            if np.shape(getattr(self, name)) != (B, 3):
                raise ValueError(f"{name} must have shape ({B}, 3)")
            object.__setattr__(self, name, _frozen(getattr(self, name)))
        if self.covariance is not None:
            if np.shape(self.covariance) != (B, 6, 6):
                raise ValueError(f"covariance must have shape ({B}, 6, 6)")
            object.__setattr__(self, "covariance", _frozen(self.covariance))
        for name in ("residuals", "history") + (("noise_std",) if self.noise_std is not None else ()):
            object.__setattr__(self, name, _frozen(getattr(self, name)))
        object.__setattr__(self, "iterations", _frozen(self.iterations, int))
        object.__setattr__(self, "converged", _frozen(self.converged, bool))

    def __len__(self) -> int:
        return self.k.shape[0]

    @property
    def params(self) -> np.ndarray:
        """(B, 6) array ``[kx, ky, kz, bx, by, bz]``."""
        return np.concatenate([self.k, self.b], axis=1)

    @property
    def std(self) -> np.ndarray | None:
        """(B, 6) standard deviations, or None without a covariance."""
        if self.covariance is None:
            return None
        return np.sqrt(np.diagonal(self.covariance, axis1=1, axis2=2))

    def item(self, i: int) -> FitResult:
        """The single-gyro result at batch index `i`."""
        n = int(self.iterations[i])
        return FitResult(
            model=ScaleBias(k=self.k[i], b=self.b[i]),
            method=self.method,
            iterations=n,
            converged=bool(self.converged[i]),
            residuals=self.residuals[i],
            covariance=None if self.covariance is None else self.covariance[i],
            noise_std=None if self.noise_std is None else self.noise_std[i],
            history=self.history[i, : n + 1],
        )


@dataclass(frozen=True)
class FitResult:
    """One gyro's calibration estimate.

    Attributes
    ----------
    model : ScaleBias
        The estimated model.
    method : {"first-moment", "algorithm1", "lm"}
    iterations : int
        Iterations after the initial estimate.
    converged : bool
    residuals : ndarray
        Final residuals, in the method's residual units.
    covariance : ndarray, shape (6, 6), or None
        Covariance of ``(k, b)``; None where the method defines none.
    noise_std : ndarray, shape (3,), or None
        Per-sample noise standard deviation behind the covariance [reading units].
    history : ndarray, shape (iterations + 1, 6)
        ``(k, b)`` after each iteration, initial estimate first.
    """

    model: ScaleBias
    method: Method
    iterations: int
    converged: bool
    residuals: np.ndarray
    covariance: np.ndarray | None
    noise_std: np.ndarray | None
    history: np.ndarray

    def __post_init__(self):
        for name in ("residuals", "covariance", "noise_std", "history"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, _frozen(getattr(self, name)))

    @property
    def std(self) -> np.ndarray | None:
        """Standard deviations of ``(k, b)``, or None without a covariance."""
        return None if self.covariance is None else np.sqrt(np.diag(self.covariance))
