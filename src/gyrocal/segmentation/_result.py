"""The result of a segmentation: the windows chosen, and what was ignored and why."""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from ..errors import SegmentationError
from ._advice import measured_turns
from .windows import Window

__all__ = ["Segmentation", "describe_found"]

Reference = Literal["speed", "angle", "file"]

#: Start of the reason given to a turn without a steady-speed stretch (speed reference).
NO_PLATEAU = "no plateau"


def _turn_label(w: Window) -> str:
    return f"{'+' if w.sign >= 0 else '-'}{w.axis}" if w.axis else "?"


def describe_found(windows, ignored=()) -> str:
    """``"rotations +x, -x x2, +y; 3 static window(s); 2 ignored"``: what a session holds."""
    rot = Counter(_turn_label(w) for w in windows if w.kind == "rotation")
    order = [f"{s}{a}" for a in "xyz" for s in "+-"]
    turns = ", ".join(f"{k} x{rot[k]}" if rot[k] > 1 else k for k in order + ["?"] if rot[k])
    n_static = sum(w.kind == "static" for w in windows)
    text = f"rotations {turns or 'none'}; {n_static} static window(s)"
    if ignored:
        reasons = Counter(reason.split(":")[0] for _, reason in ignored)
        text += f"; ignored {len(ignored)} ({', '.join(f'{n} {r}' for r, n in reasons.items())})"
    return text


@dataclass(frozen=True)
class Segmentation:
    """Windows found in a recording.

    Attributes
    ----------
    windows : tuple of Window
        The windows chosen (rotations and static), in time order. Rotation windows carry
        their reference: ``rate`` [rad/s] (the known speed, or ``angle / duration``) and
        ``angle`` [rad].
    ignored : tuple of (Window, str)
        Candidate windows left out, each with the reason.
    reference : {"speed", "angle", "file"}
        What the rotation windows were cut for (``file``: given by the user).
    sample_rate : float
        Sampling rate [Hz], to print times.
    baseline : ndarray, shape (3,)
        Reading at standstill [reading units].
    noise_std : ndarray, shape (3,)
        Per-sample noise on the quietest stretches [reading units].
    units : {"rad/s", "counts"}
        Internal units of the readings (to show the turns measured).
    advice : str
        The most likely fix when the turns a method needs are missing (see :meth:`require`).
    warnings : tuple of str
        What a person should check in the windows given (turns that disagree with none to blame).
    """

    windows: tuple[Window, ...]
    ignored: tuple[tuple[Window, str], ...] = ()
    reference: Reference = "file"
    sample_rate: float = 1.0
    baseline: np.ndarray = field(default_factory=lambda: np.zeros(3))
    noise_std: np.ndarray = field(default_factory=lambda: np.full(3, np.nan))
    units: str = "rad/s"
    advice: str = ""
    warnings: tuple[str, ...] = ()

    def __post_init__(self):
        object.__setattr__(self, "windows", tuple(sorted(self.windows, key=lambda w: w.start)))
        object.__setattr__(self, "ignored", tuple(sorted(self.ignored, key=lambda p: p[0].start)))

    @property
    def rotations(self) -> tuple[Window, ...]:
        return tuple(w for w in self.windows if w.kind == "rotation")

    @property
    def statics(self) -> tuple[Window, ...]:
        return tuple(w for w in self.windows if w.kind == "static")

    def require(self, *, static_allowed: bool = True, min_rotations: int = 0) -> None:
        """Raise :class:`SegmentationError` unless every axis is turned about, in both
        senses or (when `static_allowed`) with a static window, with at least `min_rotations`.
        """
        rot = self.rotations
        signs = {a: {w.sign for w in rot if w.axis == a} for a in "xyz"}
        has_static = static_allowed and bool(self.statics)
        missing = [a for a in "xyz" if not signs[a]]
        one_sense = [a for a in "xyz" if len(signs[a]) == 1 and not has_static]
        if not (missing or one_sense or len(rot) < min_rotations):
            return
        need = []
        if missing:
            need.append(f"no rotation about {', '.join(missing)}")
        if one_sense:
            need.append(f"only one sense about {', '.join(one_sense)}"
                        + (" and no static window" if static_allowed else ""))
        if len(rot) < min_rotations:
            need.append(f"{len(rot)} rotation(s) where the method needs {min_rotations}")
        short = any(why.startswith(NO_PLATEAU) for _, why in self.ignored)
        turns = measured_turns(self.ignored, self.units)
        advice = ("turns too short to hold a steady speed: calibrate with the angle reference ({param:angle} 360)"
                  if short else self.advice
                  or ("add the missing rotation windows to the windows file ({param:windows})"
                      if self.reference == "file" else
                      "check {param:speed}/{param:angle} and {param:units}, or give the windows with {param:windows}"))
        raise SegmentationError(
            f"found {describe_found(self.windows, self.ignored)}: {'; '.join(need)}"
            + (f"; the turns left out measure {turns}" if turns else ""),
            hint="the method needs a rotation about every axis, in both senses"
                 + (" or with a static window" if static_allowed else "") + f"; most likely: {advice}")

    def summary(self, rate_unit: str = "deg/s") -> str:
        """Plain-text table of the windows chosen and ignored (rates in `rate_unit`)."""
        f = 180 / math.pi if rate_unit == "deg/s" else 1.0
        fs = self.sample_rate
        lines = [f"{describe_found(self.windows, self.ignored)} (reference: {self.reference})"]
        head = f"{'window':<9}{'kind':<10}{'samples':>16}{'t [s]':>18}{'angle [deg]':>13}{'rate [' + rate_unit + ']':>16}"
        lines.append(head)

        def row(w: Window, name: str) -> str:
            ang = "" if math.isnan(w.angle) else f"{math.degrees(w.angle):.1f}"
            rate = "" if math.isnan(w.rate) else f"{w.rate * f:.3f}"
            span = f"{w.start}:{w.stop}"
            times = f"{w.start / fs:.2f}-{w.stop / fs:.2f}"
            return f"{name:<9}{w.kind:<10}{span:>16}{times:>18}{ang:>13}{rate:>16}"

        for w in self.windows:
            lines.append(row(w, _turn_label(w) if w.kind == "rotation" else "static"))
        for w, reason in self.ignored:
            lines.append(row(w, "ignored") + f"  {reason}")
        return "\n".join(lines)
