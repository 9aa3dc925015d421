"""Whitespace-separated text tables (imu_tk's and mikoff's ``time x y z``) through pyarrow's compiled kernels.

pyarrow's CSV parser takes one delimiter and does not collapse runs of them, so each line is read
whole (as the one column of a table delimited by a control character no text log holds), then
trimmed, split on runs of spaces and tabs, and cast to numbers by pyarrow's compute kernels: the
same parse of the same cells as the CSV reader's, without a Python string per cell.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pcsv

from ..errors import InputError
from ._arrow import from_numpy, numeric_to_numpy, text_to_numpy
from ._layout import Layout
from ._source import arrow_input

__all__ = ["spaced_pieces"]

_LINE_DELIMITER = "\x1f"  # ASCII unit separator: never in a text log, so a whole line is one cell


def _lines(path: Path, packed: str | None, layout: Layout, encoding: str) -> list:
    """The data lines, as pyarrow string chunks (empty lines dropped)."""
    options = {
        "read_options": pcsv.ReadOptions(skip_rows=layout.data, column_names=["line"], encoding=encoding),
        "parse_options": pcsv.ParseOptions(delimiter=_LINE_DELIMITER, quote_char=False, ignore_empty_lines=True),
        "convert_options": pcsv.ConvertOptions(column_types={"line": pa.string()}, strings_can_be_null=False),
    }
    with arrow_input(path, packed) as source:
        return pcsv.read_csv(source, **options).column(0).chunks


def _cells(chunk, width: int, row0: int, source: str) -> tuple[pa.Array, int]:
    """The cells of a chunk of lines, row after row, and how many rows it holds; blank lines are no rows."""
    chunk = pc.ascii_trim_whitespace(chunk)
    if pc.any(pc.equal(pc.binary_length(chunk), 0)).as_py():
        chunk = pc.filter(chunk, pc.greater(pc.binary_length(chunk), 0))  # lines of spaces only
    split = pc.ascii_split_whitespace(chunk)
    counts = numeric_to_numpy(pc.list_value_length(split), copy=False)
    if len(counts) and (bad := np.flatnonzero(counts != width)).size:
        i = int(bad[0])
        raise InputError(f"{source}: data row {row0 + i + 1} has {int(counts[i])} fields, the header has {width}")
    return pc.list_flatten(split), len(chunk)


def _columns(cells: pa.Array, rows: int, names: list[str], numeric: set[str], axis: str | None) -> dict:
    """Numpy pieces of each column of `rows` rows of `cells` (row-major): numbers as float64 where they
    all parse, text otherwise (the caller's cell parser then names the bad cell)."""
    width = len(names)
    if set(names) <= numeric:
        try:
            block = numeric_to_numpy(pc.cast(cells, pa.float64()), copy=False).reshape(rows, width)
            return {n: block[:, j] for j, n in enumerate(names)}
        except pa.ArrowInvalid:
            pass
    out = {}
    for j, n in enumerate(names):
        column = pc.take(cells, from_numpy(np.arange(j, rows * width, width)))
        if n in numeric:
            try:
                out[n] = numeric_to_numpy(pc.cast(column, pa.float64()), copy=False)
                continue
            except pa.ArrowInvalid:
                pass
        out[n] = text_to_numpy(column, dtype=str if n == axis else object)
    return out


def spaced_pieces(path: Path, packed: str | None, layout: Layout, numeric: list[str], axis: str | None,
                  encoding: str) -> dict[str, list] | None:
    """Pieces of each column of a whitespace-separated table, chunk by chunk; None where pyarrow cannot
    read the lines at all (the caller's pure-Python reader then does, with its own messages)."""
    # pyarrow reads UTF-8 (its BOM included) natively and transcodes anything else
    encoding = "utf8" if encoding == "utf-8-sig" else encoding
    try:
        chunks = _lines(path, packed, layout, encoding)
    except pa.ArrowInvalid as exc:
        if "invalid UTF8" not in str(exc) or encoding != "utf8":
            return None
        chunks = _lines(path, packed, layout, "latin-1")  # text from an older logger: every byte is a character
    names = layout.names
    pieces: dict[str, list] = {n: [] for n in names}
    row = 0
    for i in range(len(chunks)):
        chunk, chunks[i] = chunks[i], None  # each chunk of lines goes once its numbers are out
        cells, rows = _cells(chunk, len(names), row, path.name)
        row += rows
        if rows:
            for n, piece in _columns(cells, rows, names, set(numeric), axis).items():
                pieces[n].append(piece)
    return pieces
