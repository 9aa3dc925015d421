"""Exceptions and warnings raised by gyrocal.

Every error the package raises on purpose derives from :class:`GyrocalError`, so a
caller (and the command line) can tell a problem with the input from a bug.

Errors carry data, not prose for one front end: ``param`` names the Python parameter
at fault, ``value`` the value received and ``hint`` how to fix it. A message or hint
may say ``{param}`` where the parameter's name belongs; :meth:`GyrocalError.render`
fills it in with the caller's name for it (the Python name by default, a flag such
as ``--out-of-range`` on the command line), so no front end rewrites the text.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

__all__ = [
    "GyrocalError",
    "InputError",
    "NonFiniteInputError",
    "UnitError",
    "SaturationError",
    "DegenerateDesignError",
    "NonPhysicalEstimateError",
    "ConvergenceError",
    "FileFormatError",
    "SegmentationError",
    "MissingDependencyError",
    "OutOfRangeError",
    "StoreError",
    "GyrocalWarning",
]

PARAM = "{param}"
_OTHER_PARAM = re.compile(r"\{param:([A-Za-z_]\w*)\}")


class GyrocalError(Exception):
    """Base class of every error raised by gyrocal on purpose.

    Parameters
    ----------
    message : str
        What is wrong, in one sentence; may say ``{param}`` for the parameter's name, and
        ``{param:skip_rows}`` for another parameter's (here ``skip_rows``).
    param : str, optional
        The Python parameter at fault (``"sample_rate"``); front ends map it to their own name.
    value : object, optional
        The value received.
    hint : str, optional
        How to fix it; may say ``{param}`` too.
    """

    def __init__(self, message: str, *, param: str | None = None, value: Any = None, hint: str | None = None):
        super().__init__(message)
        self.message = message
        self.param = param
        self.value = value
        self.hint = hint

    def render(self, name: Callable[[str], str] | None = None) -> str:
        """The one-line text, with ``{param}`` replaced by ``name(param)`` (default: the Python name).

        A message or hint that points to another parameter too names it ``{param:skip_rows}``
        (``"... or skip the lines above it with {param:skip_rows} N"``), filled in the same way.
        """
        text = self.message if not self.hint else f"{self.message}; {self.hint}"
        name = name or (lambda param: param)
        if self.param is not None:
            text = text.replace(PARAM, name(self.param))
        return _OTHER_PARAM.sub(lambda m: name(m.group(1)), text)

    def __str__(self) -> str:
        return self.render()


class InputError(GyrocalError, ValueError):
    """An argument or a recording is malformed: wrong shape, type, column or value."""


class NonFiniteInputError(InputError):
    """The input holds NaN or infinite values."""


class UnitError(InputError):
    """Units are unknown, do not match, or the data look like another unit."""


class SaturationError(InputError):
    """Samples sit at the sensor's full scale, so their values are not measurements."""


class DegenerateDesignError(GyrocalError):
    """The observations cannot determine the parameters (singular information matrix)."""


class NonPhysicalEstimateError(GyrocalError):
    """The estimate is not a valid gyro model, for example a squared scale factor <= 0."""


class ConvergenceError(GyrocalError):
    """An iterative solver stopped before converging.

    Attributes
    ----------
    iterations : int
        Iterations performed before giving up.
    """

    def __init__(self, message: str, iterations: int, **fields):
        super().__init__(message, **fields)
        self.iterations = iterations


class FileFormatError(GyrocalError):
    """A saved file is malformed, of another type, or of an unsupported version.

    Attributes
    ----------
    field : str or None
        The offending field, dotted (``"correction.matrix"``), when one is to blame.
    """

    def __init__(self, message: str, field: str | None = None, **fields):
        super().__init__(message, **fields)
        self.field = field


class SegmentationError(GyrocalError):
    """The windows a method needs could not be found in a recording."""


class MissingDependencyError(GyrocalError, ImportError):
    """An optional dependency (an extra) is not installed."""


class OutOfRangeError(GyrocalError):
    """A temperature lies outside the calibrated range and no extrapolation was allowed."""


class StoreError(GyrocalError):
    """A calibration store cannot be used: unreachable, locked too long, or of a newer schema than this gyrocal."""


class GyrocalWarning(UserWarning):
    """Base class of the warnings gyrocal issues (the command line prints them as one line each)."""
