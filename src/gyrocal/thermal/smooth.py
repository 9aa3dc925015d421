"""A smooth alternative to Lagrange: one polynomial in temperature per Kg element.

Each of the 12 coefficients gets its own order, chosen by leave-one-temperature-out
(LOTO) error: fit on all nodes but one, predict the one left out, and keep the order
with the smallest RMS prediction error. Because that RMS is itself uncertain by about
``1/sqrt(2n)`` (relative), the lowest order within that margin of the best is kept
(the "one standard error" rule of cross-validation). Temperatures
are centred and scaled, ``u = (T - centre) / scale``, to keep the fits well
conditioned; the coefficients are stored in ``u``, highest power last.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import readonly
from .._validation import finite_array
from ..errors import InputError

__all__ = ["SmoothModel", "fit_smooth", "loto_errors", "weighted_coefficients"]


def _vander(u: np.ndarray, order: int) -> np.ndarray:
    return np.vander(u, order + 1, increasing=True)


def _loto(u: np.ndarray, y: np.ndarray, order: int) -> np.ndarray:
    """Leave-one-out prediction errors (n, m) of a polynomial of `order` fitted to columns of y (n, m)."""
    n = len(u)
    err = np.empty_like(y)
    for k in range(n):
        keep = np.arange(n) != k
        coef, *_ = np.linalg.lstsq(_vander(u[keep], order), y[keep], rcond=None)
        err[k] = _vander(u[k:k + 1], order) @ coef - y[k]
    return err


def loto_errors(temps, values, max_order: int) -> np.ndarray:
    """RMS leave-one-temperature-out error of each order 0..max_order for each column.

    Returns an array (max_order + 1, m) in the units of `values`.
    """
    t = finite_array("temps", temps, ndim=1)
    y = finite_array("values", values, ndim=2)
    u = (t - t.mean()) / max(np.ptp(t) / 2, 1e-12)
    return np.stack([np.sqrt(np.mean(_loto(u, y, p) ** 2, axis=0)) for p in range(max_order + 1)])


@dataclass(frozen=True)
class SmoothModel:
    """Per-element polynomials ``v(T) = sum_p c_p u^p`` with ``u = (T - centre) / scale``.

    Attributes
    ----------
    centre, scale : float
        Temperature normalisation [degC].
    orders : ndarray of int, shape (m,)
        Chosen order of each element.
    coefs : ndarray, shape (m, max_order + 1)
        Coefficients, lowest power first, zero above each element's order.
    loto_rms : ndarray, shape (max_order + 1, m)
        LOTO RMS error of every candidate order (element units).
    """

    centre: float
    scale: float
    orders: np.ndarray
    coefs: np.ndarray
    loto_rms: np.ndarray

    def __post_init__(self):
        coefs = finite_array("coefs", self.coefs, ndim=2)
        orders = np.asarray(self.orders, dtype=int)
        if orders.shape != (coefs.shape[0],) or np.any(orders < 0) or np.any(orders >= coefs.shape[1]):
            raise InputError(f"orders must be {coefs.shape[0]} values in 0..{coefs.shape[1] - 1}, got {orders.tolist()}")
        if not self.scale > 0:
            raise InputError(f"scale must be > 0 degC, got {self.scale!r}")
        for name, arr in (("coefs", coefs), ("orders", orders), ("loto_rms", self.loto_rms)):
            object.__setattr__(self, name, readonly(arr, None if name == "orders" else float, copy=True))

    def __call__(self, temp) -> np.ndarray:
        """Values (N, m) at temperatures (N,) [degC]."""
        u = (np.atleast_1d(np.asarray(temp, dtype=float)) - self.centre) / self.scale
        return _vander(u, self.coefs.shape[1] - 1) @ self.coefs.T

    def to_dict(self) -> dict:
        return {"centre": self.centre, "scale": self.scale, "orders": self.orders.tolist(),
                "coefs": self.coefs.tolist(), "loto_rms": self.loto_rms.tolist(),
                "equation": "v(T) = sum_p coefs[p] * ((T - centre) / scale)**p"}


def fit_smooth(temps, values, max_order: int = 3) -> SmoothModel:
    """Fit one polynomial per column of `values` (n, m), order chosen by LOTO error.

    Parameters
    ----------
    temps : array_like, shape (n,)
        Node temperatures [degC], n >= 3.
    values : array_like, shape (n, m)
        Node values (for example Kg, shape (n, 12)).
    max_order : int
        Highest order tried; capped at ``n - 2`` so each LOTO fit stays determined.
    """
    t = finite_array("temps", temps, ndim=1)
    y = finite_array("values", values, ndim=2)
    if len(t) < 3 or y.shape[0] != len(t):
        raise InputError(f"a smooth model needs >= 3 temperature points with one row of values each, got {len(t)} "
                         f"temperatures and {y.shape[0]} rows")
    if int(max_order) < 0:
        raise InputError(f"{{param}} must be >= 0, got {max_order!r}", param="max_order")
    top = min(int(max_order), len(t) - 2)
    centre, scale = float(t.mean()), float(max(np.ptp(t) / 2, 1e-12))
    u = (t - centre) / scale
    rms = loto_errors(t, y, top)
    # one-standard-error rule: the lowest order whose LOTO RMS is within the RMS's own
    # relative uncertainty, about 1/sqrt(2n), of the best; noise alone cannot buy extra orders
    best = rms.min(axis=0)
    orders = np.argmax(rms <= best * (1 + 1 / np.sqrt(2 * len(t))) + 1e-300, axis=0)
    coefs = np.zeros((y.shape[1], top + 1))
    for j, p in enumerate(orders):
        coefs[j, : p + 1] = np.linalg.lstsq(_vander(u, int(p)), y[:, j], rcond=None)[0]
    return SmoothModel(centre=centre, scale=scale, orders=orders, coefs=coefs, loto_rms=rms)


def weighted_coefficients(model: SmoothModel, temps, values, covariances) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Refit `model`'s polynomials (its orders kept) weighted by each point's 1-sigma, with their covariance.

    Each column ``j`` of `values` gets ``c_j = (V^T W_j V)^-1 V^T W_j y_j`` with ``W_j`` the inverse
    variances of that column at the points; the coefficients are linear in all values, so the
    points' full covariances (correlations between the columns at one point included; points
    independent of one another) carry through exactly.

    Parameters
    ----------
    model : SmoothModel
        Gives the orders and the temperature normalisation.
    temps : array_like, shape (n,)
        Point temperatures [degC].
    values : array_like, shape (n, m)
    covariances : array_like, shape (n, m, m)
        Of each point's values.

    Returns
    -------
    coefs : ndarray, shape (m, P + 1)
        As :attr:`SmoothModel.coefs`, zero above each column's order.
    covariance : ndarray, shape (m * (P + 1), m * (P + 1))
        Of ``coefs.ravel()``.
    chi2 : ndarray, shape (m,)
        Weighted residual sum of squares of each column (``n - order - 1`` degrees of freedom).
    """
    t = finite_array("temps", temps, ndim=1)
    y = finite_array("values", values, ndim=2)
    cov = finite_array("covariances", covariances, ndim=3)
    n, m = y.shape
    if cov.shape != (n, m, m) or len(t) != n:
        raise InputError(f"need {n} temperatures and covariances of shape ({n}, {m}, {m}), got {len(t)} and "
                         f"{cov.shape}")
    sigma = np.sqrt(np.einsum("nii->ni", cov))
    if np.any(sigma <= 0):
        raise InputError("every point's values need a 1-sigma > 0 to weight the smooth fit")
    u = (t - model.centre) / model.scale
    width = model.coefs.shape[1]
    gain = np.zeros((m * width, n * m))  # coefs.ravel() = gain @ values.ravel()
    chi2 = np.empty(m)
    for j, p in enumerate(model.orders):
        v = _vander(u, int(p)) / sigma[:, j:j + 1]
        g = np.linalg.pinv(v) / sigma[:, j]
        gain[j * width:j * width + int(p) + 1, j::m] = g
        chi2[j] = float(np.sum(((y[:, j] - _vander(u, int(p)) @ (g @ y[:, j])) / sigma[:, j]) ** 2))
    block = np.zeros((n * m, n * m))
    for k in range(n):
        block[k * m:(k + 1) * m, k * m:(k + 1) * m] = cov[k]
    return (gain @ y.ravel()).reshape(m, width), gain @ block @ gain.T, chi2
