"""The one way gyrocal makes arrays read-only, and small fixed matrices applied to long arrays of rows."""

from __future__ import annotations

import numpy as np

__all__ = ["readonly", "rows_times"]


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
