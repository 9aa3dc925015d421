"""Exceptions raised by gyrocal.

Every error the package raises on purpose derives from :class:`GyrocalError`, so a
caller (and the command line) can tell a problem with the input from a bug.
"""

from __future__ import annotations

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
    "GyrocalWarning",
]


class GyrocalError(Exception):
    """Base class of every error raised by gyrocal on purpose."""


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

    def __init__(self, message: str, iterations: int):
        super().__init__(message)
        self.iterations = iterations


class FileFormatError(GyrocalError):
    """A saved file is malformed, of another type, or of an unsupported version.

    Attributes
    ----------
    field : str or None
        The offending field, dotted (``"correction.matrix"``), when one is to blame.
    """

    def __init__(self, message: str, field: str | None = None):
        super().__init__(message)
        self.field = field


class SegmentationError(GyrocalError):
    """The windows a method needs could not be found in a recording."""


class MissingDependencyError(GyrocalError, ImportError):
    """An optional dependency (an extra) is not installed."""


class OutOfRangeError(GyrocalError):
    """A temperature lies outside the calibrated range and no extrapolation was allowed."""


class GyrocalWarning(UserWarning):
    """Base class of the warnings gyrocal issues (the command line prints them as one line each)."""
