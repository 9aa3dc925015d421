"""Delimited text recordings (CSV, TSV, whitespace), read column by column.

Large files go through ``pyarrow.csv`` (multithreaded, columnar); without pyarrow, or
for whitespace-separated files, a pure-Python reader does the same job more slowly.
"""

from __future__ import annotations

import codecs
import csv
import os
from pathlib import Path

import numpy as np

from ..errors import InputError
from ._cells import to_float, to_seconds
from ._columns import NUMERIC, resolve, time_scale

__all__ = ["read_csv_columns", "sniff"]

_HEAD_BYTES = 1 << 16
_DELIMITERS = (",", ";", "\t", "|")
WHITESPACE = None  # delimiter value meaning "runs of spaces or tabs"


def _split(line: str, delimiter: str | None) -> list[str]:
    if delimiter is WHITESPACE:
        return line.split()
    return [c.strip() for c in next(csv.reader([line], delimiter=delimiter))]


def sniff(lines: list[str], source: str = "file") -> tuple[int, str | None]:
    """Index of the header line and the delimiter of a text table.

    Blank lines and ``#`` comment lines before the header are skipped. The delimiter is
    the candidate (``, ; TAB |``) that splits the header into at least two fields and the
    most of the next lines into as many; runs of whitespace when none splits the header.
    """
    h = next((i for i, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")), None)
    if h is None:
        raise InputError(f"{source}: no header row (the file is empty or holds only comments)")
    rows = [line for line in lines[h + 1:h + 21] if line.strip()]
    best, best_score = WHITESPACE, (-1, 0)
    for d in _DELIMITERS:
        n = len(_split(lines[h], d))
        score = (sum(len(_split(line, d)) == n for line in rows), n)
        if n >= 2 and score > best_score:
            best, best_score = d, score
    return h, best


# UTF-32 first: its little-endian BOM starts with UTF-16's
_BOMS = ((codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"),
         (codecs.BOM_UTF16_LE, "utf-16"), (codecs.BOM_UTF16_BE, "utf-16"))


def _head(path: Path) -> tuple[list[str], str]:
    """The first lines of a text table, and its encoding: UTF-8 unless a UTF-16/32 BOM says otherwise
    (Excel's "Unicode text" is UTF-16); both readers decode that encoding, which drops the BOM."""
    with open(path, "rb") as f:
        raw = f.read(_HEAD_BYTES)
    encoding = next((enc for bom, enc in _BOMS if raw.startswith(bom)), "utf-8-sig")
    lines = raw.decode(encoding, errors="replace").splitlines()
    return (lines[:-1] if len(raw) == _HEAD_BYTES and len(lines) > 1 else lines), encoding  # the last line may be cut


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def read_csv_columns(path: str | os.PathLike, columns=None, *, use_pyarrow: bool | None = None,
                     accel: bool = False):
    """Read a text table.

    Parameters
    ----------
    path : path-like
    columns : dict or str, optional
        Canonical name -> file column (see :func:`gyrocal.io._columns.resolve`).
    use_pyarrow : bool, optional
        Force (True) or forbid (False) the pyarrow reader; default: when installed.
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
    lines, encoding = _head(path)
    h, delimiter = sniff(lines, path.name)
    names = _split(lines[h], delimiter)
    if not columns and all(_is_number(n) for n in names):  # mapped numeric names are a real header
        sep = delimiter or " "
        raise InputError(
            f"{path.name}: the first line ({lines[h][:40].strip()!r}) is data, not a header; add a header row "
            f"naming the columns, e.g. {sep.join(('t', 'gx', 'gy', 'gz'))!r} (t optional with --sample-rate)"
        )
    mapping = resolve(names, columns, path.name, accel=accel)
    if use_pyarrow is None:
        try:
            import pyarrow.csv  # noqa: F401

            use_pyarrow = True
        except ImportError:
            use_pyarrow = False
    if use_pyarrow and delimiter is not WHITESPACE and len(set(names)) == len(names):
        cols = _read_arrow(path, h, delimiter, names, mapping, encoding)
    else:
        cols = _read_python(path, h, delimiter, names, mapping, encoding)
    numeric = {mapping[c] for c in NUMERIC if c in mapping}
    data = {c: cols[mapping[c]] for c in mapping}
    for c in mapping:
        if mapping[c] in numeric and data[c].dtype != np.float64:
            data[c] = (to_seconds if c == "t" else to_float)(data[c], mapping[c], path.name)
    if "t" in data and (scale := time_scale(mapping["t"])) != 1.0:
        data["t"] = data["t"] * scale
    extra = {n: cols[n] for n in names if n not in set(mapping.values()) and n in cols}
    return data, extra


def _read_arrow(path: Path, h: int, delimiter: str, names: list[str], mapping: dict, encoding: str) -> dict:
    import pyarrow as pa
    import pyarrow.csv as pcsv

    numeric = [mapping[c] for c in NUMERIC if c in mapping]

    def read(as_float: bool, encoding: str = "utf8"):
        types = {n: (pa.float64() if as_float and n in numeric else pa.string()) for n in names}
        return pcsv.read_csv(
            path,
            # our stripped names replace the header row; skip_rows=0 keeps pyarrow's parallel fast path
            read_options=pcsv.ReadOptions(skip_rows=h, column_names=names, skip_rows_after_names=1, encoding=encoding),
            parse_options=pcsv.ParseOptions(delimiter=delimiter, ignore_empty_lines=True),
            convert_options=pcsv.ConvertOptions(column_types=types, strings_can_be_null=False),
        )

    # pyarrow reads UTF-8 (its BOM included) natively and transcodes anything else
    as_float, encoding = True, "utf8" if encoding == "utf-8-sig" else encoding
    for _ in range(3):
        try:
            table = read(as_float, encoding)
            break
        except pa.ArrowInvalid as exc:
            message = str(exc)
            if "invalid UTF8" in message and encoding == "utf8":
                encoding = "latin-1"  # text columns from an older logger: every byte is a latin-1 character
            elif "conversion error" in message and as_float:
                as_float = False  # cells need trimming or hold text: parse them in numpy
            else:
                raise InputError(f"{path.name}: cannot parse the table ({message.splitlines()[0]})") from None
    else:
        raise InputError(f"{path.name}: cannot parse the table")
    rates = [mapping[c] for c in ("gx", "gy", "gz")]
    cols = {}
    if all(pa.types.is_float64(table.column(n).type) for n in rates):
        # fill one (3, N) block chunk by chunk: the recording is built on its transpose, a
        # column-major (N, 3) array, without another copy (see _build._rates_block)
        block = np.empty((3, table.num_rows))
        for j, name in enumerate(rates):
            pos = 0
            for chunk in table.column(name).chunks:
                block[j, pos:pos + len(chunk)] = chunk.to_numpy(zero_copy_only=False)
                pos += len(chunk)
            cols[name] = block[j]
    return {n: cols[n] if n in cols else table.column(n).to_numpy() for n in names}


def _read_python(path: Path, h: int, delimiter: str | None, names: list[str], mapping: dict, encoding: str) -> dict:
    with open(path, encoding=encoding, errors="replace", newline="") as f:
        lines = [line for line in f.read().splitlines()[h + 1:] if line.strip()]
    if delimiter is WHITESPACE:
        rows = [line.split() for line in lines]
    else:
        rows = list(csv.reader(lines, delimiter=delimiter))
    width = len(names)
    for i, row in enumerate(rows):
        if len(row) != width:
            raise InputError(f"{path.name}: data row {i + 1} has {len(row)} fields, the header has {width}")
    if not rows:
        return {n: np.empty(0, dtype=str) for n in names}
    cols = zip(*rows)
    return {n: np.asarray(col, dtype=str) for n, col in zip(names, cols)}
