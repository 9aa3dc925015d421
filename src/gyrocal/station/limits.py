"""Acceptance limits: a TOML file of bounds per parameter, and the guard-banded decision against them.

Layout (every table optional; an unknown parameter, key or unit is refused by name)::

    guard = 2                 # value +- guard * sigma must lie inside the bounds (ISO 14253-1)
    [limits.k]                # each of kx, ky, kz
    min = 0.99
    max = 1.01
    [limits.b]                # the sensor's bias, each axis (the reading at rest is its negative)
    max_abs = 2.0
    unit = "deg/s"

A criterion passes when the whole interval ``value +- guard * sigma`` lies inside its bounds: a
value whose uncertainty reaches over a bound is not accepted (conformance proved, ISO 14253-1), so
an honest 1-sigma is what the verdict rests on. The bounds of ``sigma_*`` parameters judge the
1-sigma itself (a session too short or too noisy to prove anything is refused by them, not passed).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError

__all__ = ["PARAMETERS", "Bound", "Limits", "read_limits"]

_DEG = math.pi / 180.0
#: Unit name -> internal units per unit, by the kind of quantity.
UNITS: dict[str, dict[str, float]] = {
    "scale": {"1": 1.0, "ppm": 1e-6, "%": 1e-2},
    "rate": {"rad/s": 1.0, "deg/s": _DEG, "deg/h": _DEG / 3600.0, "mdps": _DEG / 1000.0},
    "angle": {"rad": 1.0, "mrad": 1e-3, "deg": _DEG, "arcmin": _DEG / 60.0},
    "density": {"rad/s/rtHz": 1.0, "deg/s/rtHz": _DEG, "deg/h/rtHz": _DEG / 3600.0, "mdps/rtHz": _DEG / 1000.0},
    "probability": {"1": 1.0},
}
#: Parameter -> (kind of quantity, default unit, what it is).
PARAMETERS: dict[str, tuple[str, str, str]] = {
    "k": ("scale", "1", "scale factor of each axis"),
    "b": ("rate", "rad/s", "bias of each axis"),
    "misalignment": ("angle", "rad", "each off-diagonal element of the scale-misalignment matrix"),
    "noise_density": ("density", "rad/s/rtHz", "white-noise density of each axis"),
    "bias_instability": ("rate", "rad/s", "bias instability of each axis"),
    "thermal_residual": ("rate", "rad/s", "largest residual RMS of the temperature points"),
    "p_value": ("probability", "1", "the fit's goodness-of-fit p-value"),
    "sigma_k": ("scale", "1", "1-sigma of each scale factor"),
    "sigma_b": ("rate", "rad/s", "1-sigma of each bias"),
}
_KEYS = ("min", "max", "max_abs", "unit")


@dataclass(frozen=True)
class Bound:
    """Bounds of one parameter, in its stated unit; ``None`` where not set.

    ``scale`` is internal units per stated unit (values are compared after dividing by it).
    """

    parameter: str
    unit: str
    scale: float
    min: float | None = None
    max: float | None = None
    max_abs: float | None = None

    def interval(self) -> tuple[float, float]:
        """The accepted interval [low, high] in the stated unit."""
        low = -math.inf if self.min is None else self.min
        high = math.inf if self.max is None else self.max
        if self.max_abs is not None:
            low, high = max(low, -self.max_abs), min(high, self.max_abs)
        return low, high

    def to_document(self) -> dict:
        return {"parameter": self.parameter, "unit": self.unit, "min": self.min, "max": self.max,
                "max_abs": self.max_abs}


@dataclass(frozen=True)
class Limits:
    """A limits file: the guard factor and the bounds of each parameter it names."""

    guard: float
    bounds: tuple[Bound, ...]
    source: str = ""

    def to_document(self) -> dict:
        return {"guard": self.guard, "source": self.source, "bounds": [b.to_document() for b in self.bounds]}


def _number(value, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{where} must be a finite number, got {value!r}")
    return float(value)


def _bound(name: str, table, where: str) -> Bound:
    if name not in PARAMETERS:
        raise InputError(f"{where}: unknown parameter {name!r}; known: {', '.join(PARAMETERS)}")
    if not isinstance(table, dict):
        raise InputError(f"{where}.{name} must be a table with min, max or max_abs")
    unknown = sorted(set(table) - set(_KEYS))
    if unknown:
        raise InputError(f"{where}.{name}: unknown key {unknown[0]!r}; a bound has {', '.join(_KEYS)}")
    kind, default, _ = PARAMETERS[name]
    unit = table.get("unit", default)
    if unit not in UNITS[kind]:
        raise InputError(f"{where}.{name}: unknown unit {unit!r}; {name} takes {', '.join(UNITS[kind])}")
    values = {key: _number(table[key], f"{where}.{name}.{key}") for key in ("min", "max", "max_abs") if key in table}
    if not values:
        raise InputError(f"{where}.{name} sets no bound: give min, max or max_abs")
    bound = Bound(name, unit, UNITS[kind][unit], **values)
    low, high = bound.interval()
    if not low < high:
        raise InputError(f"{where}.{name}: its bounds leave nothing to accept ({low:g} to {high:g} {unit})")
    return bound


def read_limits(path: str | Path) -> Limits:
    """Read and check a limits file (TOML); every mistake is named in one line."""
    path = Path(path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"limits file {path} not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"limits file {path} cannot be read: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"limits file {path} is not TOML: {exc}") from None
    unknown = sorted(set(doc) - {"guard", "limits"})
    if unknown:
        raise InputError(f"{path}: unknown top-level key {unknown[0]!r}; a limits file has guard and [limits.*]")
    guard = _number(doc.get("guard", 2), f"{path}: guard")
    if guard < 0:
        raise InputError(f"{path}: guard must be >= 0 (value +- guard x sigma inside the bounds), got {guard:g}")
    tables = doc.get("limits", {})
    if not isinstance(tables, dict) or not tables:
        raise InputError(f"{path} sets no limits: add tables such as [limits.k] with min and max")
    bounds = tuple(_bound(name, table, f"{path}: limits") for name, table in tables.items())
    return Limits(guard, bounds, str(path))
