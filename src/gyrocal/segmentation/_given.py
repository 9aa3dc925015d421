"""Windows given by a person (a windows file): references attached, and turns the others contradict left out.

A declared angle in a windows file is a hypothesis, as it is for detection (:mod:`._select`).
Each turn's measured angle (raw integral, standstill level removed) and its declared one imply a
scale factor ``declared / measured``; one scale factor per axis explains every right turn. A turn
whose implied k is more than :data:`~._select.AGREE_TOL` from what the other turns about its axis
imply (leave-one-out: their median, when they agree among themselves) is left out, with its
declared and measured angle in the reason. With two turns about an axis that disagree, neither
outvotes the other: the one whose k is implausible (more than :data:`PLAUSIBLE` from 1 for physical
units, or from the other axes' k for counts) is left out when the other is plausible; otherwise
both stay, with a warning naming them.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from .._arrays import median
from ..errors import InputError
from ._measure import measure_turn, standstill_level
from ._result import Segmentation
from ._select import AGREE_TOL
from .windows import Window

__all__ = ["PLAUSIBLE", "given_windows"]

#: A scale factor this far from 1 (physical units) is implausible (the CLI's --accept-implausible rule).
PLAUSIBLE = 0.2
#: A given window's first or last tenth may turn this much slower than its middle (--speed only).
_SPEED_SPREAD = 0.1


def _name(i: int, w: Window) -> str:
    turn = f"{'+' if w.sign >= 0 else '-'}{w.axis}"
    return f"window {i} ({w.label + ', ' if w.label and w.label != turn else ''}{turn})"


def _require_constant_speed(samples: np.ndarray, w: Window, i: int) -> None:
    """Refuse a window with ramps: the speed reference holds only on the constant-speed part."""
    tenths = np.linalg.norm([part.mean(axis=0) for part in np.array_split(samples, min(10, len(samples)))], axis=1)
    middle = float(median(tenths))
    worst = float(min(tenths[0], tenths[-1]))
    if worst < (1 - _SPEED_SPREAD) * middle:
        raise InputError(
            f"rotation window {i} ({w.label or f'{w.start}:{w.stop}'}) is not at constant speed: an end of it turns "
            f"at {100 * worst / middle:.0f} % of its middle (a ramp); with a known speed the windows must cover only "
            "the constant-speed part: trim them, or use the angle reference (--angle) with whole turns"
        )


def given_windows(rec, windows: Sequence[Window], reference: str, speed, angle, *, screen: bool = True) -> Segmentation:
    """A :class:`Segmentation` from user windows: axis and sense filled in, references attached, and
    (angle reference, `screen`) the turns the others contradict left out."""
    windows = list(windows)
    if not windows:
        raise InputError("windows is empty; give rotation and static windows, or None to detect them")
    n, fs = len(rec), rec.sample_rate
    for w in windows:
        if not isinstance(w, Window):
            raise InputError(f"windows must hold gyrocal.segmentation.windows.Window objects, got {type(w).__name__}")
        if w.stop > n:
            raise InputError(f"window {w.label or ''} {w.start}:{w.stop} ends after the recording ({n} samples)")
    base = standstill_level(rec, windows)
    out = []
    for i, w in enumerate(windows):
        if w.kind == "static":
            out.append(dataclasses.replace(w, rate=0.0))
            continue
        if w.axis is None or w.sign == 0:
            v = rec.gyro[w.start:w.stop].mean(axis=0) - base
            j = int(np.abs(v).argmax())
            w = dataclasses.replace(w, axis="xyz"[j], sign=1 if v[j] >= 0 else -1)
        if reference == "speed":
            _require_constant_speed(rec.gyro[w.start:w.stop] - base, w, i)
            w = dataclasses.replace(w, angle=speed * len(w) / fs, rate=speed)
        else:
            a = w.angle if math.isfinite(w.angle) else angle
            if a is None:
                raise InputError(f"rotation window {i} ({w.label or f'{w.start}:{w.stop}'}) has no angle; give angle")
            a = abs(float(a))
            w = dataclasses.replace(w, angle=a, rate=a * fs / len(w))
        out.append(w)
    ignored, warnings = [], []
    if reference == "angle" and screen:
        measured = [measure_turn(rec, w, base)[0] if w.kind == "rotation" else math.nan for w in out]
        ignored, warnings = contradicted(out, measured, physical=rec.units != "counts")
        left = {id(w) for w, _ in ignored}
        out = [w for w in out if id(w) not in left]
    return Segmentation(tuple(out), tuple(ignored), "file", fs, base, np.full(3, np.nan), units=rec.units,
                        warnings=tuple(warnings))


def _head(i: int, w: Window, measured: float, counts: bool) -> str:
    size = f"{measured:.4g} counts s" if counts else f"{math.degrees(measured):.1f} deg"
    return f"{_name(i, w)} declared {math.degrees(w.angle):g} deg, measured {size}"


def contradicted(windows: Sequence[Window], measured: Sequence[float], *, physical: bool
                 ) -> tuple[list[tuple[Window, str]], list[str]]:
    """The rotation `windows` whose declared angle the other turns contradict, with the reasons, and warnings
    for axes whose turns disagree without one to blame. `measured`: each window's raw angle (NaN if static)."""
    # long function: per axis, leave-one-out among three or more turns, then the two-turn case
    rot = [i for i, w in enumerate(windows) if w.kind == "rotation" and measured[i] > 0]
    logk = {i: math.log(windows[i].angle / measured[i]) for i in rot}
    tol = math.log1p(AGREE_TOL)
    ignored: list[tuple[Window, str]] = []
    warnings: list[str] = []
    blamed: set[int] = set()

    def leave(i: int, why: str) -> None:
        head = _head(i, windows[i], measured[i], not physical)
        ignored.append((windows[i], f"wrong angle: {head}: {why}"))
        warnings.append(f"{head}: left out, the other turns contradict its declared angle; correct it in the windows "
                        "file")
    for a in "xyz":
        mine = [i for i in rot if windows[i].axis == a]
        for i in mine if len(mine) >= 3 else ():
            others = np.array([logk[j] for j in mine if j != i])
            centre = float(median(others))
            if abs(logk[i] - centre) > tol and np.all(np.abs(others - centre) <= tol):
                blamed.add(i)
                why = (f"k {math.exp(logk[i]):.3g} where the other {len(others)} {a} turns imply {math.exp(centre):.3g}: "
                       "one scale factor cannot explain both; left out")
                leave(i, why)
    for a in "xyz":
        mine = [i for i in rot if windows[i].axis == a and i not in blamed]
        ks = np.array([logk[i] for i in mine])
        if len(mine) < 2 or np.ptp(ks) <= tol:
            continue
        if physical:
            ref, what = 0.0, "1"
        else:  # counts: one full-scale setting for the chip, so the other axes' k
            other = [logk[i] for i in rot if windows[i].axis != a and i not in blamed]
            ref, what = (float(median(other)), "the other axes' k") if other else (math.nan, "")
        near = [i for i in mine if math.isfinite(ref) and abs(logk[i] - ref) <= math.log1p(PLAUSIBLE)]
        listing = ", ".join(f"{_name(i, windows[i])} declared {math.degrees(windows[i].angle):g} deg implies k "
                            f"{math.exp(logk[i]):.3g}" for i in mine)
        far = [i for i in mine if i not in near]
        if near and far and np.ptp([logk[i] for i in near]) <= tol:
            for i in far:
                why = (f"k {math.exp(logk[i]):.3g} where the other {a} turn{'s imply' if len(near) > 1 else ' implies'} "
                       f"{math.exp(median([logk[j] for j in near])):.3g}; with so few turns neither outvotes the "
                       f"other, and this k is more than {100 * PLAUSIBLE:.0f} % from {what}: left out")
                leave(i, why)
            continue
        warnings.append(f"the {a} turns disagree about k ({listing}) and too few turns say which declared angle is "
                        "wrong: check them in the windows file; k" + a + " is their compromise")
    return ignored, warnings
