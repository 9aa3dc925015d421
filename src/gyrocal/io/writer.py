"""Atomic CSV output: columns, and whole recordings (``apply``, ``simulate``)."""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path

import numpy as np

from .._atomic import atomic_path
from ..errors import InputError
from ..units import unit_factor

__all__ = ["check_csv_name", "recording_columns", "write_csv", "write_recording"]

#: Suffixes that name another format than the plain comma-separated text gyrocal writes; gyrocal's own
#: readers go by them, so a CSV under such a name could not even be read back.
_OTHER_FORMATS = {
    ".parquet": "Parquet", ".pq": "Parquet", ".gz": "gzip", ".bz2": "bz2", ".xz": "xz", ".zst": "zstd",
    ".lz4": "lz4", ".br": "brotli", ".zip": "zip", ".json": "JSON", ".bag": "a ROS bag", ".mcap": "MCAP",
    ".db3": "a ROS 2 bag", ".ulg": "a PX4 ULog", ".bin": "a DataFlash log", ".png": "an image", ".pdf": "PDF",
}


def check_csv_name(path: str | os.PathLike) -> None:
    """Refuse an output name whose suffix says another format than CSV (``rec.parquet``, ``rec.csv.gz``)."""
    suffix = Path(path).suffix.lower()
    if suffix in _OTHER_FORMATS:
        raise InputError(f"{path}: gyrocal writes recordings as plain comma-separated text, not "
                         f"{_OTHER_FORMATS[suffix]}; give the file a .csv name")


def _columns(columns: dict) -> dict[str, np.ndarray]:
    if not columns:
        raise InputError("write_csv needs at least one column")
    arrays = {str(k): np.asarray(v) for k, v in columns.items()}
    lengths = {k: len(v) if v.ndim == 1 else -1 for k, v in arrays.items()}
    if any(n < 0 for n in lengths.values()) or len(set(lengths.values())) != 1:
        raise InputError(f"write_csv columns must be 1-D and of equal length, got lengths {lengths}")
    return arrays


#: Rows formatted at a time: memory stays bounded whatever the length of the file.
CHUNK_ROWS = 1 << 18
_NEEDS_QUOTES = r'[,"\r\n]'


def _text(arr: np.ndarray) -> list[str]:
    """Cells of one chunk without pyarrow: floats as their shortest round-trip text."""
    if arr.dtype.kind == "f":
        return [repr(x) for x in arr.tolist()]
    if arr.dtype.kind == "b":
        return ["1" if x else "0" for x in arr.tolist()]
    return ["" if x is None else str(x) for x in arr.tolist()]


def write_csv(path: str | os.PathLike, columns: dict, *, header_comment: str | None = None, progress=None) -> None:
    """Write columns to a comma-separated file, atomically, a chunk of rows at a time.

    Parameters
    ----------
    path : path-like
        Output file; replaced only once the whole file is written.
    columns : dict of str to array_like
        Column name -> 1-D values, written in the dict's order. Floats are written
        with the shortest text that reads back to the same value, booleans as 1 and 0,
        other values as text (quoted only when a cell holds a comma, a quote or a newline).
    header_comment : str, optional
        Written first, each line prefixed with ``# ``; :func:`read_recording` skips it.
    progress : callable, optional
        Called with the number of rows written after each chunk (a progress bar).
    """
    _write(path, _columns(columns), {}, header_comment, progress)


def _write(path, arrays: dict[str, np.ndarray], divisors: dict[str, float], header_comment: str | None,
           progress) -> None:
    """:func:`write_csv` of checked columns, those in `divisors` divided by theirs a chunk at a time."""
    check_csv_name(path)
    n = len(next(iter(arrays.values())))
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="") as f:
            _comment(f, header_comment)
            f.write(",".join(_quote(k) for k in arrays) + "\n")
        write_chunk = _arrow_chunk_writer()
        with open(tmp, "ab") as f:
            for start in range(0, n, CHUNK_ROWS):
                chunk = {k: v[start:start + CHUNK_ROWS] for k, v in arrays.items()}
                write_chunk(f, {k: (v / divisors[k] if k in divisors else v) for k, v in chunk.items()})
                if progress is not None:
                    progress(min(CHUNK_ROWS, n - start))


def _comment(f, header_comment: str | None) -> None:
    if header_comment:
        for line in header_comment.splitlines():
            f.write(f"# {line}\n")


def _python_chunk(f, chunk: dict[str, np.ndarray]) -> None:
    text = io.StringIO()
    csv.writer(text, lineterminator="\n").writerows(zip(*(_text(a) for a in chunk.values())))
    f.write(text.getvalue().encode("utf-8"))


def _arrow_chunk_writer():
    """A function writing one chunk of columns through pyarrow's CSV writer (the Python one without pyarrow)."""
    try:
        import pyarrow as pa
        import pyarrow.compute as pc
        import pyarrow.csv as pcsv

        from ._arrow import from_numpy
    except ImportError:
        return _python_chunk

    def write(f, chunk: dict[str, np.ndarray]) -> None:
        table = pa.table({k: from_numpy(v) for k, v in chunk.items()})
        text_columns = [table.column(k) for k, v in chunk.items() if v.dtype.kind not in "fiub"]
        quote = any(pc.any(pc.match_substring_regex(c, _NEEDS_QUOTES)).as_py() for c in text_columns)
        pcsv.write_csv(table, f, pcsv.WriteOptions(include_header=False, quoting_style="needed" if quote else "none"))
        pa.default_memory_pool().release_unused()  # the formatted chunk: do not let the allocator keep it

    return write


def _quote(name: str) -> str:
    return f'"{name}"' if any(c in name for c in ',"\n') else name


def recording_columns(rec, units: str | None = None) -> dict[str, np.ndarray]:
    """The columns of a recording as gyrocal writes it, in order.

    ``t`` [s] (only when the time came from the data), ``gx gy gz`` in `units`
    (default ``rec.source_units``; raw counts stay counts), ``temp`` [degC], ``table_rate``
    in the gyro's unit (deg/s beside raw counts), ``axis``, ``ax ay az`` [m/s^2] (raw
    counts stay counts), then every other column unchanged.
    """
    cols, divisors = _recording_columns(rec, units)
    return {k: (v / divisors[k] if k in divisors else v) for k, v in cols.items()}


def _recording_columns(rec, units: str | None) -> tuple[dict[str, np.ndarray], dict[str, float]]:
    """The recording's columns in its own units, and the divisor that takes each to the written unit."""
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
    divisors = dict.fromkeys(("gx", "gy", "gz"), gyro_factor) if gyro_factor != 1.0 else {}
    if rec.has_time:
        cols["t"] = np.asarray(rec.t)
    for i, name in enumerate(("gx", "gy", "gz")):
        cols[name] = rec.gyro[:, i]
    if rec.temp is not None:
        cols["temp"] = rec.temp
    if rec.table_rate is not None:
        cols["table_rate"] = rec.table_rate
        divisors["table_rate"] = unit_factor(table_unit)
    if rec.axis is not None:
        cols["axis"] = rec.axis
    if rec.accel is not None:
        for i, name in enumerate(("ax", "ay", "az")):
            cols[name] = rec.accel[:, i]
    for name, value in rec.extra.items():
        cols.setdefault(name, value)
    return cols, divisors


def write_recording(path: str | os.PathLike, rec, *, units: str | None = None,
                    header_comment: str | None = None, progress=None) -> None:
    """Write a recording as CSV (:func:`recording_columns`), atomically, with an optional ``#`` comment
    (`progress` as for :func:`write_csv`)."""
    cols, divisors = _recording_columns(rec, units)  # converted a chunk at a time: no whole converted copy
    _write(path, _columns(cols), divisors, header_comment, progress)
