"""Reading and writing noise files, and the ``--noise-density`` argument that accepts one."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from .._jsonfile import read_json
from ..errors import FileFormatError, InputError
from ..files import load, save
from .report import NoiseReport

__all__ = ["load_noise", "noise_density_arg", "save_noise"]

_DEG_SUFFIXES = ("deg/s/rthz", "deg/s/sqrt(hz)", "dps/rthz", "deg/s/√hz")


def save_noise(path: str | os.PathLike, report: NoiseReport) -> None:
    """Write a noise report as JSON (atomically)."""
    save(report, path)


def load_noise(path: str | os.PathLike) -> NoiseReport:
    """Read a noise file (version 2, or version 1 upgraded), validating every field.

    Every gyro density must be a number > 0: a zero density would make any
    uncertainty computed from it zero.
    """
    return load(path, NoiseReport)


def _zero_axes(path: str) -> list[str]:
    """The gyro axes whose density a noise file (version 1 or 2) gives as zero or less."""
    doc = read_json(path)
    if doc.get("version") == 1:
        values = doc.get("arw") or []
    else:
        values = [((doc.get("gyroscope") or {}).get(a) or {}).get("density", {}).get("value") for a in "xyz"]
    return [a for a, v in zip("xyz", values) if isinstance(v, (int, float)) and not v > 0]


def noise_density_arg(value: str) -> np.ndarray:
    """Parse a ``--noise-density`` option into a per-axis gyro density (3,) [rad/s/sqrt(Hz)].

    Accepts a number in rad/s/sqrt(Hz), a number followed by ``deg/s/rtHz``, or the
    path of a noise file written by ``gyrocal noise --json``.
    """
    text = str(value).strip()
    if text.lower().endswith(".json") or Path(text).is_file():
        try:
            return load_noise(text).density
        except FileFormatError as exc:
            zero = _zero_axes(text)
            if not zero:
                raise
            raise InputError(f"{{param}} {text} gives a zero noise density on {', '.join(zero)}, which would give a "
                             "zero 1-sigma (a noise file of all-zero or constant data?)", param="noise_density",
                             value=text, hint="measure the noise on a real static log (gyrocal noise)") from exc
    number, factor = text, 1.0
    for suffix in _DEG_SUFFIXES:
        if text.lower().endswith(suffix):
            number, factor = text[: -len(suffix)], math.pi / 180.0
    try:
        density = float(number) * factor
    except ValueError:
        raise InputError(
            f"--noise-density={value!r} is neither a number [rad/s/sqrt(Hz)], 'N deg/s/rtHz', nor a noise JSON file"
        ) from None
    if not density > 0 or not math.isfinite(density):
        raise InputError(f"--noise-density must be finite and > 0, got {value!r}")
    return np.full(3, density)
