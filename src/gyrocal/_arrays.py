"""The one way gyrocal makes arrays read-only, small fixed matrices applied to long arrays of rows, and
the order statistics numpy's own would import numpy.ma for (14 ms, a twentieth of a command's start)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["distinct", "median", "percentile", "readonly", "rows_times"]


def readonly(value, dtype=float, *, copy: bool) -> np.ndarray:
    """A read-only array holding `value`.

    Parameters
    ----------
    value : array_like
    dtype : numpy dtype
        Converted to it when needed (None keeps the input's).
    copy : bool
        True: an array of its own, so nothing the caller holds can change it (small
        parameter arrays). False: a read-only *view*, without a copy when `value` already
        has `dtype` (long sample arrays, where a copy costs more than reading the file);
        the caller's own array stays writable, and the caller must not change it afterwards.
    """
    arr = np.array(value, dtype=dtype) if copy else np.asarray(value, dtype=dtype).view()
    arr.setflags(write=False)
    return arr


def rows_times(rows, matrix) -> np.ndarray:
    """``rows @ matrix.T`` for rows (..., k) and a small (j, k) matrix, a column at a time.

    numpy hands an (N, 3) @ (3, 3) product to BLAS, whose OpenBLAS worker threads start at about
    60 k rows: their start and spinning cost several times the nine multiply-adds per row, and slow
    everything else running. A few whole-column operations need no BLAS.
    """
    v = np.asarray(rows)
    a = np.asarray(matrix)
    out = np.empty(v.shape[:-1] + a.shape[:1], dtype=np.result_type(v, a, float))
    tmp = np.empty(v.shape[:-1], dtype=out.dtype)
    for i in range(a.shape[0]):
        col = out[..., i]
        np.multiply(v[..., 0], a[i, 0], out=col)
        for k in range(1, a.shape[1]):
            np.multiply(v[..., k], a[i, k], out=tmp)
            col += tmp
    return out


def median(values, axis: int | None = None, *, keepdims: bool = False):
    """``np.median(values, axis, keepdims=keepdims)`` bit for bit, without importing numpy.ma.

    numpy's median asks whether its NaN check met a masked array. This is the same computation: one
    partition at the middle one or two places and the last, their mean, and NaN wherever the input
    holds one.
    """
    a = np.asarray(values)
    x, ax = (a.ravel(), 0) if axis is None else (a, axis)
    if x.size == 0 or not np.issubdtype(x.dtype, np.number) or np.iscomplexobj(x):
        return np.median(a, axis=axis, keepdims=keepdims)
    n = x.shape[ax]
    middle = [n // 2 - 1, n // 2] if n % 2 == 0 else [n // 2]
    inexact = np.issubdtype(x.dtype, np.inexact)
    part = np.partition(x, middle + [n - 1] if inexact else middle, axis=ax)
    result = np.take(part, middle, axis=ax).mean(axis=ax)
    if inexact:
        nan = np.isnan(np.take(part, -1, axis=ax))
        if nan.any():
            result = np.where(nan, np.nan, result).astype(result.dtype)[()]
    if keepdims:
        result = np.reshape(result, (1,) * a.ndim) if axis is None else np.expand_dims(result, ax)
    return result


def percentile(values, q: float, axis: int | None = None):
    """``np.percentile(values, q, axis)`` (its linear method) bit for bit, without importing numpy.ma.

    numpy finds the places to partition at with np.unique, which asks whether its input is masked.
    This is the same computation for one `q` and float64 values: the order statistics either side of
    the place ``(n - 1) q / 100``, interpolated from the nearer one as numpy does, NaN where the input
    holds one. Anything else goes to numpy.
    """
    a = np.asarray(values)
    x, ax = (a.ravel(), 0) if axis is None else (a, axis)
    if x.size == 0 or x.dtype != np.float64 or np.ndim(q) or not 0 <= q <= 100:
        return np.percentile(a, q, axis=axis)
    n = x.shape[ax]
    place = (n - 1) * (q / 100)
    below = min(math.floor(place), n - 1)
    above = min(below + 1, n - 1)
    part = np.partition(x, sorted({below, above, n - 1}), axis=ax)
    low, high = np.take(part, below, axis=ax), np.take(part, above, axis=ax)
    weight = place - below if place < n - 1 else float(n)  # numpy's weight at the top, where low == high
    step = high - low
    result = low + step * weight if weight < 0.5 else high - step * (1 - weight)
    nan = np.isnan(np.take(part, -1, axis=ax))
    return np.where(nan, np.nan, result)[()] if nan.any() else result


def distinct(values) -> np.ndarray:
    """``np.unique(values)``: the sorted distinct values (one NaN for all), without importing numpy.ma."""
    s = np.sort(np.ravel(values))
    if not s.size:
        return s
    nans = s.size - np.searchsorted(s, np.nan) if np.issubdtype(s.dtype, np.inexact) else 0  # sorted last
    s = s[: s.size - nans]
    s = s[np.concatenate(([True], s[1:] != s[:-1]))] if s.size else s
    return np.append(s, s.dtype.type(np.nan)) if nans else s
