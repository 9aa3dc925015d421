"""Atomic CSV output for ``apply`` and ``simulate``."""

from __future__ import annotations

import csv
import os

import numpy as np

from .._atomic import atomic_path
from ..errors import InputError

__all__ = ["write_csv"]


def _columns(columns: dict) -> dict[str, np.ndarray]:
    if not columns:
        raise InputError("write_csv needs at least one column")
    arrays = {str(k): np.asarray(v) for k, v in columns.items()}
    lengths = {k: len(v) if v.ndim == 1 else -1 for k, v in arrays.items()}
    if any(n < 0 for n in lengths.values()) or len(set(lengths.values())) != 1:
        raise InputError(f"write_csv columns must be 1-D and of equal length, got lengths {lengths}")
    return arrays


def _text(arr: np.ndarray) -> list[str]:
    if arr.dtype.kind == "f":
        return [repr(float(x)) for x in arr]  # shortest text that reads back to the same float
    if arr.dtype.kind == "b":
        return ["1" if x else "0" for x in arr]
    return ["" if x is None else str(x) for x in arr.tolist()]


def write_csv(path: str | os.PathLike, columns: dict, *, header_comment: str | None = None) -> None:
    """Write columns to a comma-separated file, atomically.

    Parameters
    ----------
    path : path-like
        Output file; replaced only once the whole file is written.
    columns : dict of str to array_like
        Column name -> 1-D values, written in the dict's order. Floats are written
        with the shortest text that reads back to the same value; other values as text.
    header_comment : str, optional
        Written first, each line prefixed with ``# ``; :func:`read_recording` skips it.
    """
    arrays = _columns(columns)
    with atomic_path(path) as tmp:
        if _write_arrow(tmp, arrays, header_comment):
            return
        with open(tmp, "w", encoding="utf-8", newline="") as f:
            _comment(f, header_comment)
            writer = csv.writer(f, lineterminator="\n")
            writer.writerow(list(arrays))
            writer.writerows(zip(*(_text(a) for a in arrays.values())))


def _comment(f, header_comment: str | None) -> None:
    if header_comment:
        for line in header_comment.splitlines():
            f.write(f"# {line}\n")


def _write_arrow(tmp, arrays: dict[str, np.ndarray], header_comment: str | None) -> bool:
    """Fast path for numeric columns; False when pyarrow is missing or a column is not numeric."""
    if not all(a.dtype.kind in "fiu" for a in arrays.values()):
        return False
    try:
        import pyarrow as pa
        import pyarrow.csv as pcsv
    except ImportError:
        return False
    table = pa.table({k: pa.array(v) for k, v in arrays.items()})
    with open(tmp, "w", encoding="utf-8", newline="") as f:
        _comment(f, header_comment)
        f.write(",".join(_quote(k) for k in arrays) + "\n")
    with open(tmp, "ab") as f:
        pcsv.write_csv(table, f, pcsv.WriteOptions(include_header=False))
    return True


def _quote(name: str) -> str:
    return f'"{name}"' if any(c in name for c in ',"\n') else name
