"""Argument checks shared by the public entry points.

Messages name the argument, what was received and what would be accepted.
"""

from __future__ import annotations

import numpy as np

from .errors import InputError, NonFiniteInputError

#: 0 K in degC: no temperature reads below it.
ABSOLUTE_ZERO = -273.15


def finite_array(name: str, value, *, shape_tail: tuple[int, ...] = (), ndim: int | None = None) -> np.ndarray:
    """Return `value` as a float array, checking its trailing shape and finiteness."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be numeric, got {type(value).__name__}") from exc
    if ndim is not None and arr.ndim != ndim:
        raise InputError(f"{name} must have {ndim} dimension(s), got shape {arr.shape}")
    if shape_tail and arr.shape[arr.ndim - len(shape_tail):] != shape_tail:
        want = "(..., " + ", ".join(map(str, shape_tail)) + ")"
        raise InputError(f"{name} must have shape {want}, got {arr.shape}")
    # a sum is one cheap pass and finite when every term is; only its overflow needs the full test
    if not np.isfinite(arr.sum()) and not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))
        raise NonFiniteInputError(
            f"{name} holds {len(bad)} NaN or infinite value(s), first at index {tuple(int(i) for i in bad[0])}; "
            "drop or fill those samples first"
        )
    return arr


def vector3(name: str, value) -> np.ndarray:
    """Return `value` as a finite float array of shape (3,)."""
    return finite_array(name, value, shape_tail=(3,), ndim=1)


def positive(name: str, value: float) -> float:
    """Return `value` as a float, refusing anything that is not finite and > 0."""
    try:
        v = float(value)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{{param}} must be a number, got {value!r}", param=name, value=value) from exc
    if not np.isfinite(v):
        raise NonFiniteInputError(f"{{param}} must be finite and > 0, got {value!r}", param=name, value=value)
    if v <= 0:
        raise InputError(f"{{param}} must be finite and > 0, got {value!r}", param=name, value=value)
    return v


def temperature(name: str, value: float) -> float:
    """Return `value` [degC] as a float, refusing anything not finite or below absolute zero."""
    return at_least(name, value, ABSOLUTE_ZERO, " degC")


def at_least(name: str, value: float, low: float, unit: str = "") -> float:
    """Return `value` as a float, refusing anything that is not finite and >= `low`."""
    try:
        v = float(value)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{{param}} must be a number, got {value!r}", param=name, value=value) from exc
    if not (np.isfinite(v) and v >= low):
        raise InputError(f"{{param}} must be finite and >= {low:g}{unit}, got {value!r}", param=name, value=value)
    return v


def refuse_options(options: dict, accepted: tuple[str, ...], what: str) -> None:
    """Refuse keyword options that `what` does not take, naming the first one (``param``)."""
    unknown = [k for k in options if k not in accepted]
    if unknown:
        took = f"it takes {', '.join(f'{{param:{a}}}' for a in accepted)}" if accepted else "it takes none"
        raise InputError(f"{{param}} does not apply to {what} ({took})", param=unknown[0],
                         value=options[unknown[0]])
