"""Delimited text recordings (CSV, TSV, whitespace), read column by column.

A small table of numbers (under a MiB, or any size without pyarrow) goes through numpy's compiled
``loadtxt``, which parses it before pyarrow could be imported. Larger files go through ``pyarrow.csv``
(multithreaded, columnar), whitespace-separated ones through pyarrow's compute kernels (:mod:`._spaced`);
what neither takes (text cells without pyarrow) goes through a pure-Python reader.
"""

from __future__ import annotations

import codecs
import csv
import importlib.util
import io
import lzma
import os
import warnings
import zlib
from pathlib import Path

import numpy as np

from ..errors import InputError
from ._cells import to_float, to_seconds
from ._columns import NUMERIC, resolve, time_scale
from ._layout import WHITESPACE, Layout, find_layout, split
from ._source import arrow_input, compression, open_bytes

__all__ = ["read_csv_columns", "sniff", "WHITESPACE"]

_HEAD_BYTES = 1 << 16
_SMALL = 1 << 20  # below a MiB numpy parses a table of numbers faster than pyarrow imports itself
_DECOMPRESS_ERRORS = (OSError, EOFError, zlib.error, lzma.LZMAError)


def sniff(lines: list[str], source: str = "file") -> tuple[int, str | None]:
    """Index of the header line and the delimiter of a text table (see :func:`find_layout`)."""
    layout = find_layout(lines, source)
    return (layout.data if layout.header is None else layout.header), layout.delimiter


# UTF-32 first: its little-endian BOM starts with UTF-16's
_BOMS = ((codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"),
         (codecs.BOM_UTF16_LE, "utf-16"), (codecs.BOM_UTF16_BE, "utf-16"))


def _head(path: Path, packed: str | None, skip_rows: int | None = None) -> tuple[list[str], str]:
    """The first lines of a text table (64 KiB, and beyond `skip_rows` lines), and its encoding: UTF-8
    unless a UTF-16/32 BOM says otherwise (Excel's "Unicode text" is UTF-16); both readers decode that
    encoding, which drops the BOM."""
    try:
        with open_bytes(path, packed) as f:
            raw = f.read(_HEAD_BYTES)
            while skip_rows and raw.count(b"\n") <= skip_rows + 40 and (more := f.read(_HEAD_BYTES)):
                raw += more
    except _DECOMPRESS_ERRORS as exc:
        raise InputError(f"{path.name}: cannot decompress it as {packed} ({exc})") from None
    encoding = next((enc for bom, enc in _BOMS if raw.startswith(bom)), None)
    if encoding is None and b"\x00" in raw:
        packed_note = f" (after {packed} decompression)" if packed else ""
        raise InputError(
            f"{path.name}: binary data{packed_note}, not a text table; gyrocal reads delimited text (plain, or "
            "gzip/bz2/xz/zstd/lz4/zip-compressed), Parquet and ROS 1/ROS 2/MCAP bags")
    encoding = encoding or "utf-8-sig"
    lines = raw.decode(encoding, errors="replace").splitlines()
    return (lines[:-1] if len(raw) % _HEAD_BYTES == 0 and len(lines) > 1 else lines), encoding  # the last line may be cut


def _headerless(path: Path, lines: list[str], layout: Layout, accel: bool = False) -> InputError:
    """The refusal of a table without a header when no columns are given, with the mapping to type."""
    first = lines[layout.data]
    rows = [split(line, layout.delimiter) for line in lines[layout.data:layout.data + 50] if line.strip()]
    try:
        t = [float(r[0].replace(",", ".") if layout.decimal_comma else r[0]) for r in rows]
        timed = len(layout.names) >= 4 and len(t) > 1 and all(b > a for a, b in zip(t, t[1:]))
    except (ValueError, IndexError):
        timed = False
    numbers = "t=1,gx=2,gy=3,gz=4" if timed else "gx=1,gy=2,gz=3"
    if accel:  # the accelerometer's three columns after the gyro's
        numbers += ",ax=5,ay=6,az=7" if timed else ",ax=4,ay=5,az=6"
    sep = layout.delimiter or " "
    return InputError(
        f"{path.name}: the first line ({first[:40].strip()!r}) is data, not a header", param="columns",
        hint=f"say which column holds what by number, counting from 1 ({{param}} {numbers}"
             f"{'' if timed else ' with {param:sample_rate} HZ'}), or add a header row naming the columns, "
             f"e.g. {sep.join(('t', 'gx', 'gy', 'gz'))!r}"
    )


def _mapped(path: Path, lines: list[str], layout: Layout, columns, accel: bool = False) -> tuple[Layout, dict[str, str]]:
    """The layout whose names hold the gyro columns (the first reading, else another one, e.g. the
    header over a units row) and the mapping of canonical names to its columns."""
    names = layout.names
    if not columns and layout.header is not None and names == [str(i) for i in range(len(names))]:
        raise InputError(
            f"{path.name}: the header ({lines[layout.header][:40].strip()!r}) numbers the columns from 0, as pandas "
            "writes them", param="columns", hint="say which column holds what by those names, e.g. {param} t=0,gx=1,gy=2,gz=3"
        )
    error = None
    for reading in (layout, *layout.others):
        where = "no header row; columns count from 1" if reading.header is None else f"header on line {reading.header + 1}"
        try:
            return reading, resolve(reading.names, columns, path.name, where=where, header=reading.header is not None,
                                    accel=accel)
        except InputError as exc:
            error = error or exc
    raise error


def read_csv_columns(path: str | os.PathLike, columns=None, *, use_pyarrow: bool | None = None,
                     skip_rows: int | None = None, accel: bool = False):
    """Read a text table, plain or compressed.

    Parameters
    ----------
    path : path-like
    columns : dict or str, optional
        Canonical name -> file column, by name or by number counting from 1 (see
        :func:`gyrocal.io._columns.resolve`). A table without a header needs it.
    use_pyarrow : bool, optional
        Force (True) or forbid (False) the pyarrow reader; default: numpy's parser for a small table of
        numbers, else pyarrow when installed.
    skip_rows : int, optional
        Lines above the header (or the first data row) to skip; default: metadata lines are
        found and skipped (see :func:`gyrocal.io._layout.find_layout`).
    accel : bool
        Look for the accelerometer columns ``ax, ay, az`` too.

    Returns
    -------
    data : dict
        Canonical name -> array: floats for numeric quantities, text for ``axis``.
    extra : dict
        Every other column -> array of text, in file order.
    """
    path = Path(path)
    packed = compression(path)
    lines, encoding = _head(path, packed, skip_rows)
    layout = find_layout(lines, path.name, skip_rows)
    if layout.header is None and not columns:
        raise _headerless(path, lines, layout, accel)
    layout, mapping = _mapped(path, lines, layout, columns, accel)
    names = layout.names
    cols = None
    if use_pyarrow is None:
        use_pyarrow = importlib.util.find_spec("pyarrow") is not None  # found, not imported: numpy may do
        if packed is None and (not use_pyarrow or path.stat().st_size <= _SMALL):
            cols = _read_numbers(path, layout, mapping, encoding)
    try:
        if cols is None and use_pyarrow and len(set(names)) == len(names):
            if layout.delimiter is WHITESPACE:
                cols = _read_spaced(path, packed, layout, mapping, encoding, lines[layout.data:])
            else:
                cols = _read_arrow(path, packed, layout, mapping, encoding)
        if cols is None:
            cols = _read_python(path, packed, layout, encoding)
    except _DECOMPRESS_ERRORS as exc:
        raise InputError(f"{path.name}: cannot decompress it as {packed} ({exc})") from None
    numeric = {mapping[c] for c in NUMERIC if c in mapping}
    data = {c: cols[mapping[c]] for c in mapping}
    for c in mapping:
        if mapping[c] in numeric and data[c].dtype != np.float64:
            data[c] = (to_seconds if c == "t" else to_float)(data[c], mapping[c], path.name,
                                                             decimal_comma=layout.decimal_comma)
    if "t" in data and (scale := time_scale(mapping["t"])) != 1.0:
        data["t"] = data["t"] * scale
    extra = {n: cols[n] for n in names if n not in set(mapping.values()) and n in cols}
    return data, extra


def _read_numbers(path: Path, layout: Layout, mapping: dict, encoding: str) -> dict | None:
    """Columns of a plain table whose every column is a mapped number, through numpy's compiled parser
    (correctly rounded, as pyarrow's); None for anything else (text, empty cells, a ragged row), which
    the other readers judge and explain."""
    names = layout.names
    numeric = {mapping[c] for c in NUMERIC if c in mapping}
    if layout.decimal_comma or len(set(names)) != len(names) or not set(names) <= numeric:
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # "input contained no data" and the like: leave it to the others
            with open(path, encoding=encoding) as f:  # a file, not a path: numpy's decompressors stay unloaded
                table = np.loadtxt(f, delimiter=layout.delimiter, skiprows=layout.data, comments=None, ndmin=2)
    except (ValueError, UserWarning):
        return None
    if table.shape[1] != len(names):
        return None
    pieces = {n: [table[:, j]] for j, n in enumerate(names)}
    return _joined(pieces, [mapping[c] for c in ("gx", "gy", "gz")], mapping.get("axis"))


def _read_arrow(path: Path, packed: str | None, layout: Layout, mapping: dict, encoding: str) -> dict:
    """Columns of a text table through pyarrow: all numbers at once (:func:`_filled`), else through the
    streaming reader, each block of rows becoming numpy pieces as it is parsed (joined at the end)."""
    import pyarrow as pa
    import pyarrow.csv as pcsv

    from ._arrow import numeric_to_numpy, text_to_numpy

    names = layout.names
    numeric = [mapping[c] for c in NUMERIC if c in mapping]
    axis, rates = mapping.get("axis"), [mapping[c] for c in ("gx", "gy", "gz")]

    def read(as_float: bool, encoding: str = "utf8") -> dict[str, np.ndarray]:
        types = {n: (pa.float64() if as_float and n in numeric else pa.string()) for n in names}
        pieces: dict[str, list] = {n: [] for n in names}
        all_numbers = all(t == pa.float64() for t in types.values())
        # pyarrow's 1 MiB blocks for numbers (larger ones cost memory and time); fewer for text's per-block work
        block = {} if all_numbers else {"block_size": 1 << 22}
        options = {
            # our stripped names replace the header row
            "read_options": pcsv.ReadOptions(skip_rows=layout.data, column_names=names, encoding=encoding, **block),
            "parse_options": pcsv.ParseOptions(delimiter=layout.delimiter, ignore_empty_lines=True),
            "convert_options": pcsv.ConvertOptions(column_types=types, strings_can_be_null=False,
                                                   decimal_point="," if layout.decimal_comma else "."),
        }
        with arrow_input(path, packed) as source:
            if all_numbers:
                # numbers only: the whole table at once, its blocks parsed on every core (the streaming
                # reader parses on one)
                return _filled(pcsv.read_csv(source, **options), names, rates)
            for batch in pcsv.open_csv(source, **options):
                for n, column in zip(names, batch.columns):
                    pieces[n].append(_piece(column, n))
        cols = _joined(pieces, rates, axis)
        pa.default_memory_pool().release_unused()  # pyarrow's allocator keeps freed blocks
        return cols

    def _piece(column, name: str):
        if pa.types.is_floating(column.type):
            return numeric_to_numpy(column, copy=False)
        return text_to_numpy(column, dtype=str if name == axis else object)

    # pyarrow reads UTF-8 (its BOM included) natively and transcodes anything else
    as_float, encoding = True, "utf8" if encoding == "utf-8-sig" else encoding
    for _ in range(3):
        try:
            return read(as_float, encoding)
        except pa.ArrowInvalid as exc:
            message = str(exc)
            if "invalid UTF8" in message and encoding == "utf8":
                encoding = "latin-1"  # text columns from an older logger: every byte is a latin-1 character
            elif "conversion error" in message and as_float:
                as_float = False  # cells need trimming or hold text: parse them in numpy
            else:
                raise InputError(f"{path.name}: cannot parse the table ({message.splitlines()[0]})") from None
    raise InputError(f"{path.name}: cannot parse the table")


def _filled(table, names: list[str], rates: list[str]) -> dict[str, np.ndarray]:
    """The columns of an all-numbers table in arrays of their own, the rates in one (3, N) block.

    Each record batch goes once copied, in the order pyarrow allocated them, so its allocator frees
    whole regions as the arrays fill: the numbers are held about once, not once by pyarrow and once copied.
    """
    import pyarrow as pa

    from ._arrow import numeric_to_numpy

    n, pool = table.num_rows, pa.default_memory_pool()
    block = np.empty((3, n))
    cols = {name: (block[rates.index(name)] if name in rates else np.empty(n)) for name in names}
    batches = table.to_batches()[::-1]
    del table
    pos = 0
    while batches:
        batch = batches.pop()
        for name, column in zip(names, batch.columns):
            numeric_to_numpy(column, out=cols[name][pos:pos + len(batch)])
        pos += len(batch)
        del batch, column
        if len(batches) % 16 == 0:
            pool.release_unused()
    return cols


def _read_spaced(path: Path, packed: str | None, layout: Layout, mapping: dict, encoding: str,
                 sample: list[str]) -> dict | None:
    """Columns of a whitespace-separated table through pyarrow (`sample`: its first data lines); None
    where it cannot read the lines."""
    import pyarrow as pa

    from ._spaced import regular_table, spaced_numbers, spaced_pieces

    rates = [mapping[c] for c in ("gx", "gy", "gz")]
    if not layout.decimal_comma and set(layout.names) <= {mapping[c] for c in NUMERIC if c in mapping}:
        table = regular_table(path, packed, layout, sample, encoding)
        if table is not None:
            return _filled(table, layout.names, rates)
        cols = spaced_numbers(path, layout, rates) if packed is None and encoding == "utf-8-sig" else None
        if cols is not None:
            return cols
    pieces = spaced_pieces(path, packed, layout, [mapping[c] for c in NUMERIC if c in mapping], mapping.get("axis"),
                           encoding)
    if pieces is None:
        return None
    cols = _joined(pieces, rates, mapping.get("axis"))
    pa.default_memory_pool().release_unused()
    return cols


def _joined(pieces: dict[str, list], rates: list[str], axis: str | None) -> dict[str, np.ndarray]:
    """One array per column from its pieces; the rates share one (3, N) block, whose transpose is the
    recording's column-major (N, 3) array without another copy (see _build._rates_block)."""
    n = sum(len(p) for p in next(iter(pieces.values())))
    block = np.empty((3, n)) if all(p.dtype == np.float64 for r in rates for p in pieces[r]) else None
    cols = {}
    for name in list(pieces):
        parts = pieces.pop(name)  # each column's pieces go as soon as it is joined
        if block is not None and name in rates:
            cols[name] = block[rates.index(name)]
            if parts:
                np.concatenate(parts, out=cols[name])
        elif parts:
            cols[name] = np.concatenate(parts)
        else:
            cols[name] = np.empty(0, dtype=object if name != axis else str)
    return cols


def _read_python(path: Path, packed: str | None, layout: Layout, encoding: str) -> dict:
    with io.TextIOWrapper(open_bytes(path, packed), encoding=encoding, errors="replace", newline="") as f:
        lines = [line for line in f.read().splitlines()[layout.data:] if line.strip()]
    if layout.delimiter is WHITESPACE:
        rows = [line.split() for line in lines]
    else:
        rows = list(csv.reader(lines, delimiter=layout.delimiter))
    names = layout.names
    width = len(names)
    for i, row in enumerate(rows):
        if len(row) != width:
            raise InputError(f"{path.name}: data row {i + 1} has {len(row)} fields, the header has {width}")
    if not rows:
        return {n: np.empty(0, dtype=str) for n in names}
    cols = zip(*rows)
    return {n: np.asarray(col, dtype=str) for n, col in zip(names, cols)}
