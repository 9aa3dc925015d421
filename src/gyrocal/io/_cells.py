"""Text cells to numbers, with messages that name the column and the first bad row."""

from __future__ import annotations

import warnings

import numpy as np

from ..errors import InputError

_EMPTY = {"", "na", "n/a", "null", "none", "nan", "-nan"}


def to_float(values, column: str, source: str, *, decimal_comma: bool = False) -> np.ndarray:
    """Parse text cells into floats; empty or NA cells become NaN.

    With `decimal_comma` (a table delimited by ``;``, TAB or spaces whose numbers are written
    ``1,5``), a comma is the decimal mark and a point is refused: it could be a thousands separator.
    Row numbers in messages count data rows from 1 (the row after the header).

    Raises
    ------
    InputError
        A cell is not a number.
    """
    raw = np.asarray(values, dtype=object)
    raw[np.equal(raw, None)] = ""  # pyarrow gives None for empty text cells
    cells = np.char.strip(raw.astype(str))
    cells = np.where(np.isin(np.char.lower(cells), list(_EMPTY)), "nan", cells)
    if decimal_comma:
        pointed = np.char.find(cells, ".") >= 0
        if pointed.any():
            i = int(np.argmax(pointed))
            raise InputError(
                f"{source}: column {column!r} holds {str(cells[i])[:40]!r} at data row {i + 1}, but the table writes "
                "decimal commas (1,5); a point there may be a thousands separator: write every number one way"
            )
        cells = np.char.replace(cells, ",", ".")
    try:
        return cells.astype(float)
    except ValueError:
        for i, cell in enumerate(cells):
            try:
                float(cell)
            except ValueError:
                hint = " (decimal comma? write 1.5, not 1,5)" if "," in cell else ""
                raise InputError(
                    f"{source}: column {column!r} holds non-numeric cell {str(cell)[:40]!r} at data row {i + 1}{hint}",
                    param="columns", hint="fix the cell or map another column with {param}"
                ) from None
        raise


def to_seconds(values, column: str, source: str, *, decimal_comma: bool = False) -> np.ndarray:
    """Parse a time column: numbers [s], or ISO 8601 date-times (seconds since the epoch)."""
    try:
        return to_float(values, column, source, decimal_comma=decimal_comma)
    except InputError as exc:
        try:
            with warnings.catch_warnings():  # numpy warns on a 'Z' or offset suffix; it still reads UTC
                warnings.simplefilter("ignore")
                stamps = np.asarray(np.char.strip(np.asarray(values, dtype=str)), dtype="datetime64[ns]")
        except ValueError:
            raise exc from None
        if np.isnat(stamps).any():
            raise exc from None
        return stamps.astype(np.int64) * 1e-9
