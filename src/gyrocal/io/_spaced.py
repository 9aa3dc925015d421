"""Whitespace-separated text tables (imu_tk's and mikoff's ``time x y z``) through pyarrow's compiled kernels.

pyarrow's CSV parser takes one delimiter and does not collapse runs of them. Where every line has
the same spacing (imu_tk writes two spaces before each field), the parser reads the file with that
one character as its delimiter, on every core, the empty cells between fields as columns that must
stay empty (:func:`regular_table`). Otherwise the lines are trimmed, split on runs of spaces and
tabs and cast to numbers by pyarrow's compute kernels on every core: a plain UTF-8 file of numbers a
MiB at a time into arrays made once (:func:`spaced_numbers`), anything else as pieces from lines read
whole, as the one column of a table delimited by a control character no text log holds
(:func:`spaced_pieces`). All are the same parse of the same cells as the CSV reader's, without a
Python string per cell.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pcsv

from ..errors import InputError
from ._arrow import from_numpy, numeric_to_numpy, text_to_numpy
from ._blocks import in_order, line_blocks, lines_of
from ._layout import Layout
from ._source import arrow_input

__all__ = ["regular_table", "spaced_numbers", "spaced_pieces"]

_LINE_DELIMITER = "\x1f"  # ASCII unit separator: never in a text log, so a whole line is one cell


def _spacing(lines: list[str], width: int) -> tuple[str, int, list[int]] | None:
    """The one separator character, the cells per line and the places of the `width` fields that every
    sampled line shares; None when the spacing varies (columns aligned by padding, tabs and spaces mixed)."""
    for sep in (" ", "\t"):
        shapes = {(len(cells), tuple(i for i, c in enumerate(cells) if c))
                  for line in lines if line and (cells := line.split(sep))}
        if len(shapes) == 1:
            count, fields = shapes.pop()
            if len(fields) == width and all(len(line.split()) == width for line in lines if line):
                return sep, count, list(fields)
    return None


def regular_table(path: Path, packed: str | None, layout: Layout, lines: list[str], encoding: str):
    """The table's columns as float64 (a pyarrow table, named as `layout`), read by the multithreaded
    CSV parser when the sampled data `lines` share one spacing; None otherwise, and wherever a later
    line departs from it (a cell between fields not empty, or a field empty), which the caller then
    reads by :func:`spaced_pieces`."""
    spacing = _spacing(lines, len(layout.names))
    if spacing is None:
        return None
    sep, count, fields = spacing
    names = [f"_{i}" for i in range(count)]  # every cell; the empty ones between fields typed null
    for i, name in zip(fields, layout.names):
        names[i] = name
    types = {n: pa.float64() if i in fields else pa.null() for i, n in enumerate(names)}
    options = {
        "read_options": pcsv.ReadOptions(skip_rows=layout.data, column_names=names,
                                         encoding="utf8" if encoding == "utf-8-sig" else encoding),
        "parse_options": pcsv.ParseOptions(delimiter=sep, quote_char=False, ignore_empty_lines=True),
        # only an empty cell is null: a gap holding "nan" is a field too many, a field reading "NA" no number here
        "convert_options": pcsv.ConvertOptions(column_types=types, null_values=[""], strings_can_be_null=False),
    }
    try:
        with arrow_input(path, packed) as source:
            table = pcsv.read_csv(source, **options).select(layout.names)
    except pa.ArrowInvalid:  # a line of other spacing, or a cell that is not a number
        return None
    return None if any(column.null_count for column in table.columns) else table


def _lines(path: Path, packed: str | None, layout: Layout, encoding: str) -> list:
    """The data lines, as pyarrow string chunks (empty lines dropped), read on every core (the streaming
    reader, on one, holds as much memory ahead of the blocks it has given)."""
    options = {
        "read_options": pcsv.ReadOptions(skip_rows=layout.data, column_names=["line"], encoding=encoding),
        "parse_options": pcsv.ParseOptions(delimiter=_LINE_DELIMITER, quote_char=False, ignore_empty_lines=True),
        "convert_options": pcsv.ConvertOptions(column_types={"line": pa.string()}, strings_can_be_null=False),
    }
    with arrow_input(path, packed) as source:
        return pcsv.read_csv(source, **options).column(0).chunks


def _cells(chunk, width: int) -> tuple[pa.Array, int, tuple[int, int] | None]:
    """The cells of a chunk of lines, row after row, how many rows it holds (blank lines are no rows),
    and the first row of another width than `width` (its index in the chunk and its fields), if any."""
    chunk = pc.ascii_trim_whitespace(chunk)
    if pc.any(pc.equal(pc.binary_length(chunk), 0)).as_py():
        chunk = pc.filter(chunk, pc.greater(pc.binary_length(chunk), 0))  # lines of spaces only
    split = pc.ascii_split_whitespace(chunk)
    counts = numeric_to_numpy(pc.list_value_length(split), copy=False)
    if len(counts) and (bad := np.flatnonzero(counts != width)).size:
        return split, len(chunk), (int(bad[0]), int(counts[bad[0]]))
    return pc.list_flatten(split), len(chunk), None


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
        return _pieces(_lines(path, packed, layout, encoding), path.name, layout.names, set(numeric), axis)
    except pa.ArrowInvalid as exc:
        if "invalid UTF8" not in str(exc) or encoding != "utf8":
            return None
    # text from an older logger: every byte is a character
    return _pieces(_lines(path, packed, layout, "latin-1"), path.name, layout.names, set(numeric), axis)


def _pieces(chunks: list, source: str, names: list[str], numeric: set[str], axis: str | None) -> dict[str, list]:
    """The chunks of lines split and cast on every core, collected in order (so a bad row is named by its
    number in the file); each chunk of lines goes once its numbers are out."""

    def columns(chunk):
        cells, rows, bad = _cells(chunk, len(names))
        return ({} if bad or not rows else _columns(cells, rows, names, numeric, axis)), rows, bad

    pieces: dict[str, list] = {n: [] for n in names}
    row = 0

    def collect(result) -> None:
        nonlocal row
        cols, rows, bad = result
        _refuse(source, row, bad, len(names))
        row += rows
        for n, piece in cols.items():
            pieces[n].append(piece)

    in_order(_drained(chunks), columns, collect)
    return pieces


def _drained(chunks: list):
    """The items of `chunks` in order, each out of the list as it is given (so it can be freed)."""
    chunks.reverse()
    while chunks:
        yield chunks.pop()


def _refuse(source: str, row: int, bad: tuple[int, int] | None, width: int) -> None:
    if bad:
        raise InputError(f"{source}: data row {row + bad[0] + 1} has {bad[1]} fields, the header has {width}")


def spaced_numbers(path: Path, layout: Layout, rates: list[str]) -> dict[str, np.ndarray] | None:
    """The columns of a plain UTF-8 whitespace table of numbers only, split and cast on every core a MiB
    at a time straight into arrays sized from the first blocks (the rates in one (3, N) block): the
    numbers held about once, not as pieces and then joined. None where this cannot read the file (other
    bytes, a line ending in a bare CR, a cell that is no number), for :func:`spaced_pieces`."""
    names = layout.names
    size = path.stat().st_size
    order = rates + [n for n in names if n not in rates]  # the rates first: their rows are the (3, N) block
    where = [names.index(n) for n in order]
    out = [np.empty((3, 0)), np.empty((len(order) - 3, 0))]  # the rates; the other columns
    row = seen = 0

    def numbers(block):
        cells, rows, bad = _cells(lines_of(block), len(names))
        values = numeric_to_numpy(pc.cast(cells, pa.float64()), copy=False) if rows and not bad else None
        return values, rows, bad, len(block)

    def store(result) -> None:
        nonlocal row, seen, out
        values, rows, bad, length = result
        _refuse(path.name, row, bad, len(names))
        seen += length
        if row + rows > out[0].shape[1]:  # rows per byte so far, over the whole file, and a little more
            wide = int((row + rows) * size / seen * 1.02) + 1024
            out = [np.concatenate((part[:, :row], np.empty((len(part), wide - row))), axis=1) for part in out]
        if rows:
            table = values.reshape(rows, len(names))[:, where].T
            out[0][:, row:row + rows], out[1][:, row:row + rows] = table[:3], table[3:]
            row += rows

    try:
        in_order(line_blocks(path, layout.data), numbers, store)
    except InputError:  # a row of another width, named by its number: final
        raise
    except (ValueError, pa.ArrowInvalid):  # a bare CR, bytes that are not UTF-8, a cell that is no number
        return None
    block = out[0] if row == out[0].shape[1] else out[0][:, :row].copy()  # one (3, N) block of its own
    others = {n: out[1][j, :row] for j, n in enumerate(order[3:])}
    del out
    return {n: block[rates.index(n)] if n in rates else others[n] for n in names}
