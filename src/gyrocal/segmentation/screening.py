"""Windows a calibration must not use as they are: turns across a real gap, varying rates for the paper's methods.

* A real gap (samples never delivered, see :mod:`gyrocal.recording.timebase`) inside a whole turn hides
  angle: the trapezoid across it is exact only if the rate was linear there. The angle it may
  hide is bounded by the rates on either side; a turn keeps that bound as the uncertainty of its
  angle when it is small (at most 1 % of the turn), and is left out otherwise, with the gap in
  the reason. Plateau means (speed reference) and static means lose nothing but samples.
* A break (the log is not contiguous, see :mod:`gyrocal.recording.breaks`) inside a turn joins two
  unrelated motions: the turn is left out. A static window across one is cut there into its parts.
* Algorithm 1 and LM (the servo method of Wang et al., eq. 4-8) average ``m^2`` and assume a
  constant speed in every window; a window whose rate varies (ramps, a hand turn) reads k low by
  about half its squared coefficient of variation. They refuse such windows and point to the
  default method, which is exact on whole turns.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from .._white import difference_variance
from ..errors import InputError
from ..recording import Recording
from ..recording.breaks import spans_break, split_spans
from ..recording.timebase import Gap, TimeBase
from ._result import Segmentation
from .windows import Window

__all__ = ["MAX_GAP_SHARE", "MAX_RATE_CV", "rate_variation", "reference_variances", "require_constant_rate",
           "screen_breaks", "screen_gaps"]

#: Shortest part of a static window cut at a break that is kept [samples].
MIN_STATIC_PART = 10

#: Largest rate variation (sd / mean, noise removed) the paper's methods accept: k low by about 0.5 %.
MAX_RATE_CV = 0.10
#: A turn whose time-stamp gaps may hide more than this share of its angle is left out.
MAX_GAP_SHARE = 0.01


def _name(w: Window, i: int | None = None) -> str:
    where = f"samples {w.start}:{w.stop}"
    label = w.label or (f"{'+' if w.sign >= 0 else '-'}{w.axis}" if w.axis else w.kind)
    return f"{'' if i is None else f'window {i} '}({label}, {where})"


def _gap_bound(rec: Recording, t: np.ndarray, w: Window, gap: Gap, baseline: np.ndarray) -> tuple[float, float]:
    """Bound on the angle a gap hides [reading units x s], and the turn's measured angle there.

    The trapezoid across a gap takes the mean of the rates at its ends. The rate inside stays
    between the rates seen one gap-length before and after (a turn's rate is continuous), so
    the error is at most the gap's length times half their difference, plus three standard
    errors of those means for the noise.
    """
    i = gap.index
    length = float(t[i] - t[i - 1])
    before = slice(max(w.start, int(np.searchsorted(t, t[i - 1] - length))), i)
    after = slice(i, min(w.stop, max(i + 1, int(np.searchsorted(t, t[i] + length)))))
    seg = rec.gyro[w.start:w.stop] - baseline
    u = seg.mean(axis=0)
    u = u / (np.linalg.norm(u) or 1.0)
    rb = (rec.gyro[before] - baseline) @ u
    ra = (rec.gyro[after] - baseline) @ u
    noise = math.sqrt(float(difference_variance(np.diff(seg @ u))))
    spread = abs(float(ra.mean()) - float(rb.mean())) / 2 + 3 * noise * math.sqrt(1 / len(ra) + 1 / len(rb))
    dt = np.diff(t[w.start:w.stop])[:, None]
    return length * spread, float(np.linalg.norm(np.sum((seg[1:] + seg[:-1]) / 2 * dt, axis=0)))


def screen_breaks(seg: Segmentation, breaks) -> Segmentation:
    """Windows across a break: turns left out (with the reason), static windows cut into their parts."""
    if not breaks or not any(spans_break(w.start, w.stop, breaks) for w in seg.windows):
        return seg
    kept, dropped = [], []
    for w in seg.windows:
        if not spans_break(w.start, w.stop, breaks):
            kept.append(w)
        elif w.kind == "rotation":
            at = next(b for b in breaks if w.start < b < w.stop)
            dropped.append((w, f"break: the log is not contiguous inside the turn (before sample {at}); "
                               "its angle joins two unrelated motions"))
        else:
            kept += [dataclasses.replace(w, start=a, stop=b) for a, b in split_spans(w.start, w.stop, breaks)
                     if b - a >= MIN_STATIC_PART]
    return dataclasses.replace(seg, windows=tuple(kept), ignored=seg.ignored + tuple(dropped))


def screen_gaps(seg: Segmentation, rec: Recording, tb: TimeBase, reference: str, times: np.ndarray | None = None,
                max_share: float = MAX_GAP_SHARE) -> tuple[Segmentation, dict[tuple[int, int], float]]:
    """Turns (angle reference) across real gaps: kept with an angle uncertainty, or left out.

    Returns the segmentation with the turns whose gaps may hide more than `max_share` of their
    angle moved to ``ignored`` (with the reason), and for the others the relative variance of
    their angle [1], keyed by ``(start, stop)``: the reference rate's variance is that times
    the rate squared.
    """
    if reference != "angle" or not tb.gaps:
        return seg, {}
    kept, dropped, rel_var = [], [], {}
    for w in seg.windows:
        gaps = tb.gaps_in(w.start, w.stop) if w.kind == "rotation" else ()
        if not gaps:
            kept.append(w)
            continue
        bounds = [_gap_bound(rec, rec.t if times is None else times, w, g, seg.baseline) for g in gaps]
        turned = bounds[0][1]
        bound = math.sqrt(sum(b * b for b, _ in bounds))  # independent gaps
        lost = sum(g.lost for g in gaps)
        if turned > 0 and bound <= max_share * turned:
            kept.append(w)
            rel_var[(w.start, w.stop)] = (bound / turned) ** 2 / 3.0  # uniform within the bound
            continue
        worst = max(gaps, key=lambda g: g.step)
        dropped.append((w, f"gap: {lost} sample(s) missing inside the turn ({worst.step * 1e3:.4g} ms step at sample "
                           f"{worst.index}); the angle they hide may be {100 * bound / max(turned, 1e-300):.2g} % "
                           f"of the turn (at most {100 * max_share:g} % is accepted)"))
    return dataclasses.replace(seg, windows=tuple(kept), ignored=seg.ignored + tuple(dropped)), rel_var


def reference_variances(windows: Sequence[Window], reference: str, value: float, reference_sd: float | None,
                        gap_var: dict[tuple[int, int], float]) -> list[float]:
    """Relative variance [1] of every window's reference rate: a gap's bound (:func:`screen_gaps`) plus the
    declared accuracy of each turn's angle, `reference_sd` [rad] (independent from turn to turn); 0 for
    static windows.

    A robot or a turntable states its angle (or speed) accuracy; no residual can show an error that all the
    turns about an axis share, so only a declared accuracy puts it in the 1-sigma.
    """
    if reference_sd is not None and not (math.isfinite(reference_sd) and reference_sd >= 0):
        raise InputError(f"{{param}} must be a finite number >= 0, got {reference_sd!r}", param="reference_sd",
                         value=reference_sd)
    out = []
    for w in windows:
        rel = gap_var.get((w.start, w.stop), 0.0)
        if w.kind == "rotation" and reference_sd:
            size = w.angle if reference == "angle" and math.isfinite(w.angle) else value
            rel += (reference_sd / size) ** 2
        out.append(rel if w.kind == "rotation" else 0.0)
    return out


def rate_variation(samples: np.ndarray, baseline: np.ndarray) -> float:
    """Coefficient of variation of a window's rate along its turn axis, white noise removed.

    The rate is ``(m - baseline) . u`` with ``u`` the window's mean direction; its variance less
    the noise variance along ``u`` (from first differences) over its squared mean. The paper's
    mean of squares reads ``k`` low by about half its square.
    """
    d = np.asarray(samples, dtype=float) - baseline
    mean = d.mean(axis=0)
    speed = float(np.linalg.norm(mean))
    if speed == 0:
        return math.inf
    u = mean / speed
    s = d @ u
    noise = float(difference_variance(np.diff(s)))
    return math.sqrt(max(float(s.var()) - noise, 0.0)) / speed


def require_constant_rate(rec: Recording, windows: Sequence[Window], baseline: np.ndarray, method: str) -> None:
    """Refuse, for the paper's methods, a rotation window whose rate varies more than `MAX_RATE_CV`."""
    name = {"algorithm1": "Algorithm 1", "lm": "LM"}.get(method, method)
    for i, w in enumerate(windows):
        if w.kind != "rotation":
            continue
        cv = rate_variation(rec.gyro[w.start:w.stop], baseline)
        if cv > MAX_RATE_CV:
            raise InputError(
                f"rotation {_name(w, i)}: its rate varies {100 * cv:.0f} % (sd/mean, noise removed). "
                f"{name} (the servo method of Wang et al., eq. 4-8) assumes a constant speed in every window and "
                f"would read k low by about {50 * cv * cv:.2g} %", param="method", value=method,
                hint="use the default method ({param} first-moment), which is exact on whole turns, or "
                "constant-speed plateaus (a known speed)"
            )
