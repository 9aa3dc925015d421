"""Column naming shared with other readers of tabular text (the serial text lines of ``gyrocal capture``)."""

from ._columns import CANONICAL, REQUIRED, parse_columns, resolve, time_scale

__all__ = ["CANONICAL", "REQUIRED", "parse_columns", "resolve", "time_scale"]
