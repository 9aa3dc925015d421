"""Parquet recordings (needs the ``arrow`` extra)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import InputError, MissingDependencyError
from ._cells import to_float
from ._columns import NUMERIC, resolve, time_scale

__all__ = ["read_parquet_columns"]


def _as_float(column, name: str, source: str) -> np.ndarray:
    import pyarrow as pa
    import pyarrow.compute as pc

    if pa.types.is_timestamp(column.type):
        ns = pc.cast(column, pa.timestamp("ns")).cast(pa.int64()).to_numpy(zero_copy_only=False)
        return ns * 1e-9
    if pa.types.is_integer(column.type) or pa.types.is_floating(column.type) or pa.types.is_boolean(column.type):
        return pc.cast(column, pa.float64()).to_numpy(zero_copy_only=False)
    if pa.types.is_string(column.type) or pa.types.is_large_string(column.type):
        return to_float(column.to_numpy(zero_copy_only=False), name, source)
    raise InputError(f"{source}: column {name!r} has type {column.type}, not numbers", param="columns",
                     hint="map another column with {param}")


def read_parquet_columns(path: str | os.PathLike, columns=None, *, accel: bool = False):
    """Read a Parquet file: ``(data, extra)`` as for :func:`gyrocal.io.csvfile.read_csv_columns`.

    A timestamp-typed time column becomes seconds since the epoch; a numeric one named
    with a unit (``time_ms``, ``t [us]``, ``stamp_ns``) is scaled to seconds.
    """
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        raise MissingDependencyError("reading Parquet needs pyarrow: pip install 'gyrocal[arrow]'") from None
    path = Path(path)
    try:
        table = pq.read_table(path)
    except Exception as exc:  # pyarrow raises several types for a damaged file
        raise InputError(f"{path.name}: not a readable Parquet file ({str(exc).splitlines()[0]})") from None
    names = list(table.column_names)
    mapping = resolve(names, columns, path.name, accel=accel)
    data = {}
    for canon, name in mapping.items():
        column = table.column(name)
        if canon in NUMERIC:
            data[canon] = _as_float(column, name, path.name)
        else:
            data[canon] = np.asarray(column.to_numpy(zero_copy_only=False), dtype=str)
    if "t" in data and not pa.types.is_timestamp(table.column(mapping["t"]).type):
        data["t"] = data["t"] * time_scale(mapping["t"])
    used = set(mapping.values())
    extra = {n: table.column(n).to_numpy(zero_copy_only=False) for n in names if n not in used}
    return data, extra
