"""Where a text table starts and how it is written: metadata lines, header row, delimiter,
decimal comma.

Real logs are not all ``t,gx,gy,gz`` on line 1. A logger writes ``Fs,100`` lines first; a
spreadsheet in a European locale writes ``0,005;1,25``; numpy writes ``# t gx gy gz``; a
serial dump has no header at all. The layout is read from the first 64 KiB: the data rows
(the last lines read) fix the delimiter and the number of fields; the header is the first
line with that many fields that reads as names and is followed by a data row; lines above it
are metadata and skipped.
"""

from __future__ import annotations

import csv
import functools
import re
from dataclasses import dataclass
from statistics import median

from ..errors import InputError

__all__ = ["Layout", "find_layout", "split", "WHITESPACE"]

DELIMITERS = (",", ";", "\t", "|")
WHITESPACE = None  # delimiter value meaning "runs of spaces or tabs"
_TAIL = 20  # data rows that fix the layout
_NEUTRAL = {"", "na", "n/a", "nan", "-nan", "null", "none", "inf", "-inf", "+inf"}
_COMMA_NUMBER = re.compile(r"^[+-]?\d*,\d+(?:[eE][+-]?\d+)?$")
_POINT_NUMBER = re.compile(r"^[+-]?\d*\.\d+(?:[eE][+-]?\d+)?$")
_EXCEL_SEP = re.compile(r"^\s*sep=(.)\s*$", re.IGNORECASE)


@dataclass(frozen=True)
class Layout:
    """How a text table is laid out.

    Attributes
    ----------
    header : int or None
        Line index of the header row; None for a table without one.
    data : int
        Line index of the first data row (lines above it are skipped).
    delimiter : str or None
        Field separator; None for runs of whitespace.
    decimal_comma : bool
        Numbers are written ``1,5`` (never with a comma delimiter).
    names : list of str
        Column names: the header's, or ``"1" .. "n"`` for a table without a header.
    others : tuple of Layout
        Other readings to try, in order, when the names do not hold the gyro columns: a header
        over a units row, where this reading took the units for names.
    """

    header: int | None
    data: int
    delimiter: str | None
    decimal_comma: bool
    names: list[str]
    others: tuple["Layout", ...] = ()


def split(line: str, delimiter: str | None) -> list[str]:
    """The stripped fields of one line."""
    if delimiter is WHITESPACE:
        return line.split()
    return [c.strip() for c in next(csv.reader([line], delimiter=delimiter), [""])]


def _is_number(cell: str, comma_ok: bool) -> bool:
    try:
        float(cell.replace(",", ".") if comma_ok else cell)
    except ValueError:
        return False
    return True


def _text_share(cells: list[str], comma_ok: bool) -> float | None:
    """Share of the non-empty cells that are not numbers (None: every cell empty)."""
    full = [c for c in cells if c.lower() not in _NEUTRAL]
    if not full:
        return None if not any(cells) else 0.0
    return sum(not _is_number(c, comma_ok) for c in full) / len(full)


def _is_content(line: str) -> bool:
    return bool(line.strip()) and not line.lstrip().startswith("#")


@dataclass(frozen=True)
class _Fit:
    delimiter: str | None
    width: int
    text_share: float  # typical share of text cells in a data row
    score: tuple


def _fit(rows: list[str], d: str | None) -> _Fit | None:
    counts = [len(split(r, d)) for r in rows]
    width = max(set(counts), key=lambda c: (counts.count(c), c))
    if width < 2:
        return None
    shares = [s for r, c in zip(rows, counts) if c == width and (s := _text_share(split(r, d), d != ",")) is not None]
    share = median(shares) if shares else 1.0
    # most rows with one width first, then the most numeric reading (decides ';' with decimal commas
    # against ','), then more fields
    return _Fit(d, width, share, (counts.count(width), -share, width))


def _is_data(line: str, fit: _Fit) -> bool:
    cells = split(line, fit.delimiter)
    if len(cells) != fit.width:
        return False
    share = _text_share(cells, fit.delimiter != ",")
    # halfway between a typical data row and a row of names: one bad cell keeps a row data
    return share is not None and share < fit.text_share + (1.0 - fit.text_share) / 2


def _is_numbered_header(cells: list[str]) -> bool:
    """``0,1,2,...``: the header pandas writes for a frame without column names."""
    return len(cells) >= 2 and cells == [str(i) for i in range(len(cells))]


def _decimal_comma(lines: list[str], fit: _Fit) -> bool:
    if fit.delimiter == ",":
        return False
    cells = [c for line in lines for c in split(line, fit.delimiter)]
    commas = sum(bool(_COMMA_NUMBER.match(c)) for c in cells)
    return commas > sum(bool(_POINT_NUMBER.match(c)) for c in cells)  # a mix is refused cell by cell later


def find_layout(lines: list[str], source: str = "file", skip_rows: int | None = None) -> Layout:
    """The layout of a text table from its first lines.

    Parameters
    ----------
    lines : list of str
        The first lines of the file (blank ones included, so indices are line numbers - 1).
    source : str
        File name for messages.
    skip_rows : int, optional
        Lines to skip before the header (or the first data row); default: found from the data.

    Raises
    ------
    InputError
        No table in the lines.
    """
    start = 0
    forced = None
    if skip_rows is not None:
        start = skip_rows
    elif lines and (m := _EXCEL_SEP.match(lines[0])):  # Excel's "sep=;" first line names the delimiter
        start, forced = 1, m.group(1)
    content = [i for i in range(start, len(lines)) if _is_content(lines[i])]
    if not content:
        where = f" after skipping {skip_rows} line(s)" if skip_rows else ""
        raise InputError(f"{source}: no header row{where} (the file is empty or holds only comments)")
    tail = [lines[i] for i in content[-_TAIL:]]
    candidates = (forced,) if forced is not None else (*DELIMITERS, WHITESPACE)
    fits = [f for d in candidates if (f := _fit(tail, d)) is not None]
    fit = max(fits, key=lambda f: f.score) if fits else _Fit(forced or ",", 1, 1.0, ())
    comma = _decimal_comma([lines[i] for i in content[-_TAIL:] if _is_data(lines[i], fit)], fit)
    if skip_rows is not None:
        return _layout_at(lines, content, 0, fit, comma)
    return _detect(lines, content, fit, comma)


def _detect(lines: list[str], content: list[int], fit: _Fit, comma: bool) -> Layout:
    """The header: the first line of names followed by a data row. Names right above it are
    kept as other readings (a header over a units row, or metadata of the table's width)."""

    @functools.cache  # judged on demand: a header near the top leaves the thousands of lines below unread
    def is_row(pos: int) -> bool:
        line = lines[content[pos]]  # pandas writes its numbered header first, and only there
        return _is_data(line, fit) and not (pos == 0 and _is_numbered_header(split(line, fit.delimiter)))

    def is_names(pos: int) -> bool:
        return len(split(lines[content[pos]], fit.delimiter)) in (fit.width, fit.width - 1) and not is_row(pos)

    first = next((pos for pos in range(len(content) - 1) if not is_row(pos) and is_names(pos) and is_row(pos + 1)),
                 None)
    if first is None:
        data = next((pos for pos in range(len(content)) if is_row(pos)), None)
        if data is None:  # no data row at all: the first line of the table's width is its header
            pos = next((p for p, i in enumerate(content) if len(split(lines[i], fit.delimiter)) == fit.width), 0)
            return _layout_at(lines, content, pos, fit, comma)
        commented = _comment_header(lines, content[data], fit)
        if commented is not None:
            return Layout(commented[0], content[data], fit.delimiter, comma, commented[1])
        return Layout(None, content[data], fit.delimiter, comma, [str(j + 1) for j in range(fit.width)])
    block = [first]
    while block[0] > 0 and is_names(block[0] - 1):
        block.insert(0, block[0] - 1)
    layouts = []
    for j in reversed(range(len(block))):
        between = [lines[content[p]] for p in block[j + 1:]]
        data = first + 1 if all(_is_units_row(line, fit) for line in between) else block[j] + 1
        layouts.append(_layout_at(lines, content, block[j], fit, comma, data=content[data]))
    # a header over a units row ("s,deg/s,...") is the second reading, metadata of the table's width the first
    return Layout(**{**layouts[0].__dict__, "others": tuple(layouts[1:])})


def _layout_at(lines: list[str], content: list[int], pos: int, fit: _Fit, comma: bool, *, data: int | None = None) \
        -> Layout:
    """The header at ``content[pos]`` (or, when that line is data, a table without a header)."""
    i = content[pos]
    cells = split(lines[i], fit.delimiter)
    if _is_data(lines[i], fit) and not _is_numbered_header(cells):
        return Layout(None, i, fit.delimiter, comma, [str(j + 1) for j in range(len(cells))])
    if len(cells) == fit.width - 1:  # R's write.csv: no name above the row-name column
        cells = ["", *cells]
    if data is None:
        data = content[pos + 1] if pos + 1 < len(content) else len(lines)
    return Layout(i, data, fit.delimiter, comma, cells)


_UNITS = {"", "s", "sec", "secs", "seconds", "ms", "us", "µs", "ns", "min", "h", "deg", "degree", "degrees", "rad",
          "dps", "deg/s", "°/s", "º/s", "rad/s", "rps", "rpm", "mdps", "degc", "°c", "ºc", "c", "k", "lsb", "count",
          "counts", "raw", "g", "mg", "m/s2", "m/s^2", "m/s²", "hz", "%", "-", "1", "ut", "µt", "gauss"}


def _is_units_row(line: str, fit: _Fit) -> bool:
    """A row of units under a header: ``s,deg/s,deg/s,deg/s`` or ``[s];[dps];...``."""
    return all(re.sub(r"[\s\[\]\(\)\{\}]", "", c).lower() in _UNITS for c in split(line, fit.delimiter))


def _comment_header(lines: list[str], first_data: int, fit: _Fit) -> tuple[int, list[str]] | None:
    """A ``# t gx gy gz`` comment right above the data (numpy's savetxt header), as names."""
    i = first_data - 1
    while i >= 0 and not lines[i].strip():
        i -= 1
    if i < 0 or not lines[i].lstrip().startswith("#"):
        return None
    body = lines[i].lstrip()[1:]
    cells = split(body, fit.delimiter)
    if len(cells) != fit.width or _is_data(body, fit):
        return None
    return i, cells
