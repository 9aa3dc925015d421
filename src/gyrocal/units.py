"""Angular-rate units at the edges of the package.

Everything inside gyrocal is SI (rad/s, s). Other units are converted here, when
reading, printing or exporting, and every saved file records the units it uses.
"""

from __future__ import annotations

import math
from typing import get_args

import numpy as np

from .choices import InputUnit, RateUnit
from .constants import MAD_TO_SIGMA, STANDARD_GRAVITY  # noqa: F401  (defined once, numpy-free)
from .errors import UnitError

__all__ = ["RateUnit", "InputUnit", "accel_scale", "RATE_UNITS", "parse_rate_unit", "parse_input_unit", "to_rad_s", "from_rad_s", "unit_factor",
           "input_scale"]


RATE_UNITS: tuple[str, ...] = get_args(RateUnit)

_FACTOR_TO_RAD_S = {"rad/s": 1.0, "deg/s": math.pi / 180.0}
_ALIASES = {
    "rad/s": "rad/s", "rad/sec": "rad/s", "rads": "rad/s", "rad": "rad/s", "radps": "rad/s",
    "deg/s": "deg/s", "deg/sec": "deg/s", "dps": "deg/s", "°/s": "deg/s", "degps": "deg/s", "deg": "deg/s",
    "counts": "counts", "count": "counts", "lsb": "counts", "raw": "counts",
}


def _parse(name: str, value: str, allowed: tuple[str, ...]) -> str:
    key = str(value).strip().lower()
    unit = _ALIASES.get(key)
    if unit not in allowed:
        raise UnitError(f"{{param}} {value!r} is not a known unit; use one of {', '.join(allowed)}", param=name,
                        value=value)
    return unit


def parse_rate_unit(value: str, name: str = "units") -> RateUnit:
    """Return the canonical spelling of a rate unit (``rad/s`` or ``deg/s``)."""
    return _parse(name, value, RATE_UNITS)  # type: ignore[return-value]


def parse_input_unit(value: str, name: str = "units") -> InputUnit:
    """Return the canonical spelling of a recording's unit (rate units or ``counts``)."""
    return _parse(name, value, get_args(InputUnit))  # type: ignore[return-value]


def unit_factor(unit: str) -> float:
    """Multiplier that turns values in `unit` into rad/s."""
    return _FACTOR_TO_RAD_S[parse_rate_unit(unit)]


def to_rad_s(values, unit: str) -> np.ndarray:
    """Convert rates from `unit` to rad/s."""
    return np.asarray(values, dtype=float) * unit_factor(unit)


def from_rad_s(values, unit: str) -> np.ndarray:
    """Convert rates from rad/s to `unit`."""
    return np.asarray(values, dtype=float) / unit_factor(unit)


def input_scale(input_units: str, sensitivity: float | None, output_units: str) -> float:
    """Internal units per input unit: rad/s per deg/s or rad/s; for counts, rad/s per count through the
    sensitivity [LSB per output unit], or 1 (counts stay counts) without one."""
    if input_units == "counts":
        return 1.0 if sensitivity is None else unit_factor(output_units) / sensitivity
    return unit_factor(input_units)


def accel_scale(units: str, sensitivity: float | None, gravity: float) -> float:
    """Internal accelerometer units (m/s^2, or counts without a sensitivity) per unit of `units`."""
    if units == "counts":
        return 1.0 if sensitivity is None else gravity / sensitivity
    return {"m/s^2": 1.0, "g": gravity}[units]
