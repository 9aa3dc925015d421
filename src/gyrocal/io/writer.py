"""Atomic CSV output: columns, and whole recordings (``apply``, ``simulate``)."""

from __future__ import annotations

import csv
import os

import numpy as np

from .._atomic import atomic_path
from ..errors import InputError
from ..units import unit_factor

__all__ = ["recording_columns", "write_csv", "write_recording"]


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


def recording_columns(rec, units: str | None = None) -> dict[str, np.ndarray]:
    """The columns of a recording as gyrocal writes it, in order.

    ``t`` [s] (only when the time came from the data), ``gx gy gz`` in `units`
    (default ``rec.source_units``; raw counts stay counts), ``temp`` [degC], ``table_rate``
    in the gyro's unit (deg/s beside raw counts), ``axis``, ``ax ay az`` [m/s^2] (raw
    counts stay counts), then every other column unchanged.
    """
    if rec.units == "counts":
        if units not in (None, "counts"):
            raise InputError(f"the recording holds raw counts; it cannot be written in {units}", param="units")
        gyro_factor, table_unit = 1.0, "deg/s"
    else:
        table_unit = units or rec.source_units
        if table_unit == "counts":
            raise InputError("the recording holds rates converted to rad/s; write them in rad/s or deg/s",
                             param="units")
        gyro_factor = unit_factor(table_unit)
    cols: dict[str, np.ndarray] = {}
    if rec.has_time:
        cols["t"] = np.asarray(rec.t)
    for i, name in enumerate(("gx", "gy", "gz")):
        cols[name] = rec.gyro[:, i] / gyro_factor if gyro_factor != 1.0 else rec.gyro[:, i]
    if rec.temp is not None:
        cols["temp"] = rec.temp
    if rec.table_rate is not None:
        cols["table_rate"] = rec.table_rate / unit_factor(table_unit)
    if rec.axis is not None:
        cols["axis"] = rec.axis
    if rec.accel is not None:
        for i, name in enumerate(("ax", "ay", "az")):
            cols[name] = rec.accel[:, i]
    for name, value in rec.extra.items():
        cols.setdefault(name, value)
    return cols


def write_recording(path: str | os.PathLike, rec, *, units: str | None = None,
                    header_comment: str | None = None) -> None:
    """Write a recording as CSV (:func:`recording_columns`), atomically, with an optional ``#`` comment."""
    write_csv(path, recording_columns(rec, units), header_comment=header_comment)
