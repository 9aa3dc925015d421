"""numpy <-> pyarrow through buffers.

pyarrow's own conversions (``pa.array(ndarray)``, ``Array.to_numpy``) import pandas whenever it is
installed, about a second per process; these helpers read and build the arrays' buffers
directly instead. Text columns are dictionary-encoded on the way out of pyarrow, so a column of a
few distinct labels (``axis``) costs an index per row rather than a Python string per row.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa

__all__ = ["from_numpy", "numeric_to_numpy", "text_to_numpy"]

#: Distinct values, as a fraction of the rows, up to which a text column is read through its dictionary.
_DICTIONARY_SHARE = 0.1


def _chunks(column) -> list:
    return list(column.chunks) if isinstance(column, pa.ChunkedArray) else [column]


def _plain(chunk) -> np.ndarray | None:
    """A null-free primitive chunk as a read-only numpy view of its data buffer; None otherwise."""
    typ = chunk.type
    if chunk.null_count or not (pa.types.is_floating(typ) or pa.types.is_integer(typ)):
        return None
    dtype = np.dtype(typ.to_pandas_dtype())
    return np.frombuffer(chunk.buffers()[1], dtype=dtype, count=len(chunk), offset=chunk.offset * dtype.itemsize)


def numeric_to_numpy(column, out: np.ndarray | None = None, copy: bool = True) -> np.ndarray:
    """A numeric column as one numpy array (copied into `out` when given); nulls become NaN.

    With ``copy=False`` a single null-free chunk comes back as a read-only view of pyarrow's buffer.
    """
    parts = []
    for chunk in _chunks(column):
        view = _plain(chunk)
        if view is None:
            import pyarrow.compute as pc  # only for columns with nulls or not float: its import is 0.1 s

            view = np.asarray(pc.fill_null(pc.cast(chunk, pa.float64()), np.nan).to_pylist(), dtype=float)
        parts.append(view)
    if out is None:
        return np.concatenate(parts) if len(parts) != 1 else (parts[0].copy() if copy else parts[0])
    pos = 0
    for part in parts:
        out[pos:pos + len(part)] = part
        pos += len(part)
    return out


def text_to_numpy(column, dtype=object) -> np.ndarray:
    """A text column as a numpy array of `dtype` (object: Python strings, None for a missing cell)."""
    import pyarrow.compute as pc  # lazily: numeric logs never need it, and its import is 0.1 s

    n = len(column)
    encoded = pc.dictionary_encode(column)
    chunks = _chunks(encoded)
    distinct = sum(len(c.dictionary) for c in chunks)
    if column.null_count or distinct > max(1000, _DICTIONARY_SHARE * n):
        return np.array(column.to_pylist(), dtype=dtype)
    out = np.empty(n, dtype=dtype if dtype is not str else np.dtype(f"U{_width(chunks)}"))
    pos = 0
    for chunk in chunks:
        labels = np.array(chunk.dictionary.to_pylist(), dtype=out.dtype)
        index = chunk.indices
        codes = np.frombuffer(index.buffers()[1], dtype=np.dtype(index.type.to_pandas_dtype()), count=len(index),
                              offset=index.offset * index.type.bit_width // 8)
        out[pos:pos + len(chunk)] = labels[codes] if len(labels) else labels
        pos += len(chunk)
    return out


def _width(chunks) -> int:
    return max([1] + [len(s) for c in chunks for s in c.dictionary.to_pylist()])


def from_numpy(a: np.ndarray):
    """A pyarrow array of a 1-D numpy array: numbers as they are, booleans as 0/1, anything else as text."""
    if a.dtype.kind == "b":
        a = a.astype(np.uint8)
    if a.dtype.kind in "fiu":
        data = np.ascontiguousarray(a, dtype=a.dtype.newbyteorder("="))
        return pa.Array.from_buffers(pa.from_numpy_dtype(data.dtype), len(data), [None, pa.py_buffer(data)])
    text = np.asarray([("" if v is None else str(v)) for v in a.tolist()] if a.dtype.kind == "O" else a, dtype=str)
    codes = text.view(np.uint32).reshape(len(text), max(text.dtype.itemsize // 4, 1))
    if codes.size and codes.max() < 128:  # ASCII (axis labels, most logs): each character is its code's byte
        filled = codes != 0  # numpy pads its fixed-width strings with NUL at the end
        lengths, data = filled.sum(axis=1), codes[filled].astype(np.uint8)
    else:
        raw = np.char.encode(text, "utf-8").astype(f"S{max(text.dtype.itemsize // 4, 1) * 4}")
        lengths = np.char.str_len(raw)
        body = raw.view(np.uint8).reshape(len(raw), raw.dtype.itemsize)
        data = np.ascontiguousarray(body[np.arange(raw.dtype.itemsize) < lengths[:, None]])
    offsets = np.zeros(len(text) + 1, dtype=np.int64)
    np.cumsum(lengths, out=offsets[1:])
    return pa.Array.from_buffers(pa.large_string(), len(text), [None, pa.py_buffer(offsets), pa.py_buffer(data)])
