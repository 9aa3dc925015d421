"""The one way gyrocal makes arrays read-only."""

from __future__ import annotations

import numpy as np

__all__ = ["readonly"]


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
