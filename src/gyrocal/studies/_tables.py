"""Result tables written twice: CSV for machines, Markdown for the README."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import Sequence

import numpy as np

from .._atomic import write_text_atomic


def _cell(value, digits: int | None) -> str:
    """A number at `digits` significant digits (None: full precision); NaN as blank."""
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return "" if math.isnan(v) else (repr(v) if digits is None else f"{v:.{digits}g}")
    return str(value)


def write_table(stem: Path, header: Sequence[str], rows: Sequence[Sequence], *, digits: int = 4) -> tuple[Path, Path]:
    """Write ``stem.csv`` (full precision) and ``stem.md`` (`digits` significant digits).

    Returns the two paths.
    """
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    writer.writerows([[_cell(v, None) for v in row] for row in rows])
    csv_path, md_path = stem.with_suffix(".csv"), stem.with_suffix(".md")
    write_text_atomic(csv_path, buf.getvalue())
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(_cell(v, digits) for v in row) + " |" for row in rows]
    write_text_atomic(md_path, "\n".join(lines) + "\n")
    return csv_path, md_path
