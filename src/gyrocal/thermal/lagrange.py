"""Three-node Lagrange interpolation in temperature (the full-temperature-range method, eq. 21-22).

The stencil rule is fixed, because the firmware export implements the same in C:
with nodes ``T_0 < ... < T_{n-1}`` and ``i`` the first node ``>= T``, the stencil
starts at ``s = clip(i - 2, 0, n - 3)``. Inside ``(T_{i-1}, T_i)`` with ``i >= 2`` that
is the paper's nodes ``i-2, i-1, i``; the paper is silent on the first interval
``[T_0, T_1]``, which we serve with nodes 0, 1, 2 (the only stencil that stays
inside the table). Readings within :data:`RANGE_MARGIN` of the end nodes are
clamped to them silently: a node's temperature is the mean of noisy or quantised
readings, so a test at the same set point reads a few tenths beyond it. Further
outside ``[T_0, T_{n-1}]`` the caller chooses what happens.
"""

from __future__ import annotations

import warnings

import numpy as np

from .._validation import finite_array
from ..choices import OutOfRange, values
from ..errors import InputError, OutOfRangeError
from ._warn import ThermalRangeWarning

__all__ = ["OutOfRange", "RANGE_MARGIN", "check_nodes", "interpolate", "lagrange_weights", "range_policy", "stencil"]

_POLICIES = values(OutOfRange)

#: Readings this close to the end nodes [degC] count as at them (GYROCAL_THERMAL_MARGIN in C).
RANGE_MARGIN = 0.5


def check_nodes(nodes) -> np.ndarray:
    """Return `nodes` [degC] as a float array, refusing fewer than 3 or non-increasing values."""
    t = finite_array("temperature nodes", nodes, ndim=1)
    if len(t) < 3:
        raise InputError(f"3-node Lagrange interpolation needs at least 3 temperature points, got {len(t)}")
    if np.any(np.diff(t) <= 0):
        raise InputError(f"temperature nodes must be strictly increasing, got {np.round(t, 3).tolist()}")
    return t


def range_policy(nodes: np.ndarray, temp: np.ndarray, out_of_range: OutOfRange) -> np.ndarray:
    if out_of_range not in _POLICIES:
        raise InputError(f"{{param}}={out_of_range!r} is not one of {', '.join(_POLICIES)}", param="out_of_range",
                         value=out_of_range)
    lo, hi = nodes[0], nodes[-1]
    outside = (temp < lo - RANGE_MARGIN) | (temp > hi + RANGE_MARGIN)
    if not outside.any():
        return temp if out_of_range == "extrapolate" else np.clip(temp, lo, hi)
    worst = float(temp[outside][np.argmax(np.abs(temp[outside] - (lo + hi) / 2))])
    where = f"{int(outside.sum())} temperature reading(s) outside the calibrated range [{lo:g}, {hi:g}] degC, e.g. {worst:.2f} degC"
    if out_of_range == "refuse":
        raise OutOfRangeError(where, param="out_of_range", value=out_of_range,
                              hint="set {param} to 'clamp' or 'extrapolate' to accept them")
    warnings.warn(f"{where}; {'clamped to the nearest end' if out_of_range == 'clamp' else 'extrapolated'}",
                  ThermalRangeWarning, stacklevel=3)
    return np.clip(temp, lo, hi) if out_of_range == "clamp" else temp


def stencil(nodes: np.ndarray, temp: np.ndarray) -> np.ndarray:
    """First node of the 3-node stencil for each temperature (see the module rule)."""
    i = np.searchsorted(nodes, temp, side="left")
    return np.clip(i - 2, 0, len(nodes) - 3)


def lagrange_weights(nodes, temp, out_of_range: OutOfRange = "refuse") -> tuple[np.ndarray, np.ndarray]:
    """Stencil indices and weights of the 3-node interpolation.

    Parameters
    ----------
    nodes : array_like, shape (n,)
        Calibrated temperatures [degC], strictly increasing, n >= 3.
    temp : array_like, shape (N,)
        Temperatures to evaluate at [degC].
    out_of_range : {"refuse", "clamp", "extrapolate"}
        What to do outside ``[nodes[0], nodes[-1]]``.

    Returns
    -------
    index : ndarray of int, shape (N, 3)
        Node indices ``s, s+1, s+2``.
    weight : ndarray, shape (N, 3)
        Lagrange basis values at `temp` (the full-temperature-range method, eq. 22); they sum to 1.
    """
    t = check_nodes(nodes)
    x = range_policy(t, finite_array("temp", temp, ndim=1), out_of_range)
    s = stencil(t, x)
    idx = s[:, None] + np.arange(3)
    tn = t[idx]
    w = np.empty_like(tn)
    for j in range(3):  # the full-temperature-range method, eq. 22
        a, b = tn[:, (j + 1) % 3], tn[:, (j + 2) % 3]
        w[:, j] = (x - a) * (x - b) / ((tn[:, j] - a) * (tn[:, j] - b))
    return idx, w


def interpolate(nodes, values, temp, out_of_range: OutOfRange = "refuse") -> np.ndarray:
    """Interpolate node values (n, ...) at temperatures (N,) [degC]; returns (N, ...) (the full-temperature-range method, eq. 21)."""
    v = np.asarray(values, dtype=float)
    idx, w = lagrange_weights(nodes, np.atleast_1d(np.asarray(temp, dtype=float)), out_of_range)
    if v.shape[0] != len(np.asarray(nodes)):
        raise InputError(f"values have {v.shape[0]} rows but there are {len(np.asarray(nodes))} temperature nodes")
    return np.einsum("nk,nk...->n...", w, v[idx])
