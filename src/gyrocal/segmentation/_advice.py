"""What was found instead of the turns a method needs, and the most likely fix.

When no turn is accepted about some axis, the turns that were measured say why: all of them
57 times too small is a unit mistake, all of them a quarter of the declared angle is a wrong
``--angle``, a common factor on a known speed is a wrong ``--speed``. The advice names flags
as ``{param:...}`` placeholders, so the command line shows its flags and Python its parameters.
"""

from __future__ import annotations

import math

import numpy as np

from .._arrays import median

__all__ = ["advise", "measured_turns"]

_DEG = math.degrees(1.0)
_NEAR = 1.5  # a ratio within this factor of a unit's factor points to that unit


def _near(ratio: float, factor: float) -> bool:
    return ratio > 0 and abs(math.log(ratio / factor)) <= math.log(_NEAR)


def measured_turns(ignored, units: str) -> str:
    """``"+x 6.3 deg at 0.957 deg/s, ..."``: the turns left out, as measured (at most 8)."""
    parts = []
    for w, _ in ignored:
        if w.kind != "rotation":
            continue
        label = f"{'+' if w.sign >= 0 else '-'}{w.axis}" if w.axis else "?"
        if units == "rad/s":
            angle = "" if math.isnan(w.angle) else f" {math.degrees(abs(w.angle)):.3g} deg"
            rate = "" if math.isnan(w.rate) else f" at {math.degrees(abs(w.rate)):.3g} deg/s"
        else:
            angle, rate = "", "" if math.isnan(w.rate) else f" at {abs(w.rate):.3g} counts"
        parts.append(label + angle + rate)
    shown = ", ".join(parts[:8]) + (f", ... ({len(parts)} in all)" if len(parts) > 8 else "")
    return shown


def _common(values: list[float]) -> float | None:
    """The median of positive `values` when they agree within 25 %, else None."""
    v = np.abs(np.asarray([x for x in values if math.isfinite(x) and x != 0]))
    if len(v) == 0:
        return None
    med = float(median(v))
    return med if np.all(np.abs(v / med - 1) <= 0.25) else None


def advise(ignored, reference: str, declared: float | None, units: str, *, accepted: int = 0,
           sample_rate: float | None = None, has_time: bool = True) -> str:
    """The most likely fix, from the turns left out and what was declared.

    Parameters
    ----------
    ignored : sequence of (Window, str)
        Windows left out, with their reasons; rotation windows carry the measured angle [rad]
        and mean rate [rad/s, or counts].
    reference : {"speed", "angle"}
    declared : float
        The declared speed [rad/s] or angle [rad].
    units : {"rad/s", "counts"}
        Internal units of the readings.
    accepted : int
        Rotation windows accepted (about other axes).
    sample_rate : float, optional
        The time base [Hz], to name the rate that would explain a common angle error.
    has_time : bool
        Whether the time base came from a time column (else from the declared sample rate).
    """
    turns = [w for w, _ in ignored if w.kind == "rotation"]
    if not turns and accepted:
        return "turn about the missing axes too (in both senses, or with a still pause)"
    if not turns:
        return ("nothing turned above the noise: is it a still log (that is for 'gyrocal noise'), or are the "
                "readings in another unit than {param:units} says?")
    if units != "rad/s" or declared is None:
        return "check {param:units}, {param:speed}/{param:angle}, or give the windows with {param:windows}"
    if reference == "angle":
        seen = _common([w.angle for w in turns])
        what, flag, shown = "turn", "{param:angle}", (lambda v: f"{math.degrees(v):.3g} deg")
    else:
        seen = _common([w.rate for w in turns])
        what, flag, shown = "speed", "{param:speed}", (lambda v: f"{math.degrees(v):.3g} deg/s")
    if seen is None:
        return (f"the turns differ from one another; check {flag}, or give the windows with {{param:windows}}")
    ratio = seen / declared
    if _near(ratio, 1 / _DEG):
        return (f"every {what} reads {1 / ratio:.3g} times smaller than declared, as rad/s read as deg/s would: "
                "are the data in rad/s? ({param:units} rad/s)")
    if _near(ratio, _DEG):
        return (f"every {what} reads {ratio:.3g} times larger than declared, as deg/s read as rad/s would: "
                "are the data in deg/s? ({param:units} deg/s)")
    if reference == "angle":
        degrees = math.degrees(seen)
        if degrees >= 40 and abs(degrees / (snap := 45 * round(degrees / 45)) - 1) <= 0.05:
            degrees = snap  # a gyro's scale error moves the measured angle a few percent off a whole turn
        turned = f"were the turns {degrees:.4g} deg ({flag} {degrees:.4g})?"
        clock = f"if they were {shown(declared)}, the time base is {1 / ratio:.3g} times off"
        if sample_rate and has_time:
            clock += f": is the time column in seconds (it gives {sample_rate:.4g} Hz)?"
        elif sample_rate:
            clock += f": is the sample rate {sample_rate * ratio:.3g} Hz ({{param:sample_rate}} {sample_rate * ratio:.3g})?"
        first, second = (turned, clock) if degrees != math.degrees(seen) else (clock, turned)
        return f"every turn measures about {shown(seen)}, not {shown(declared)}: {first} Or, {second}"
    return (f"every plateau measures about {shown(seen)}, not {shown(declared)}: was the speed {shown(seen)} "
            f"({flag} {math.degrees(seen):.3g})?")
