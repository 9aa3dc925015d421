"""Whole turns for a known angle: pieces joined, padded into standstill, checked against the declaration.

Each whole turn is kept from where the rate leaves the static noise band to where it returns;
pieces of one turn separated by short pauses (hand turns) are joined. The raw integrated angle
(the scale is unknown) only tells which motions are the declared turns:
:func:`~gyrocal.segmentation._select.select_by_axis` keeps those that one scale factor per
axis explains, and reports the others with their measured angle.
"""

from __future__ import annotations

import math

import numpy as np

from .._arrays import median
from ._motion import Motion
from ._select import AGREE_TOL, K_RANGE, select_by_axis
from .windows import Window

__all__ = ["MAX_OFF_AXIS_DEG", "angle_turns", "axis_sign"]

MAX_OFF_AXIS_DEG = 25.0  # 10 deg of mounting misalignment, with room for a hand
_MIN_PURITY = 0.9  # share of a turn's motion that must add up about one axis
_JOIN = 0.75  # pieces that each reach this share of the declared angle are whole turns: never joined


def axis_sign(v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Dominant axis, its sign and the angle off that axis [deg] of vectors (R, 3)."""
    ax = np.abs(v).argmax(axis=1)
    comp = v[np.arange(len(v)), ax]
    norm = np.linalg.norm(v, axis=1)
    off = np.degrees(np.arccos(np.clip(np.abs(comp) / np.where(norm > 0, norm, 1), 0, 1)))
    return ax, np.where(comp >= 0, 1, -1), off


def _group_pieces(runs, v, fs, max_pause, full, tiny=0.0) -> list[list[int]]:
    """Join consecutive runs about one axis and sense separated by at most `max_pause` [s].

    Two runs that each already look like a whole turn (``|angle| >= full``) stay apart, so
    repeated turns with a short wait are not merged. A run smaller than `tiny` (a wobble
    between the pieces of a hand turn) joins the turn it interrupts whatever its axis.
    """
    ax, sg, _ = axis_sign(v)
    mag = np.linalg.norm(v, axis=1)
    groups: list[list[int]] = [[0]] if len(runs) else []
    total = v[0].copy() if len(runs) else None
    for i in range(1, len(runs)):
        g = groups[-1]
        gap = (runs[i, 0] - runs[g[-1], 1]) / fs
        gax, gsg, _ = axis_sign(total[None])
        same = (ax[i] == gax[0] and sg[i] == gsg[0]) or mag[i] < tiny
        both_whole = full is not None and mag[i] >= full and np.linalg.norm(total) >= full
        if same and gap <= max_pause and not both_whole:
            g.append(i)
            total += v[i]
        else:
            groups.append([i])
            total = v[i].copy()
    return groups


def _structural(vec: np.ndarray, spread: np.ndarray, scale: float):
    """Axis, sign, angle off axis [deg], size and purity of grouped motions (G, 3)."""
    ax, sg, off = axis_sign(vec)
    size = np.linalg.norm(vec, axis=1)
    purity = size * scale / np.maximum(spread, 1e-300)
    return ax, sg, off, size, purity


def _counts_scale(runs, v, spread, fs, max_pause, angle) -> float:
    """Counts x s per radian: the largest clean turn about each axis, median over the axes.

    Counts carry no physical scale. The calibration turns are the largest clean motions
    about each axis; the most common motion size would be the re-poses between them.
    """
    groups = _group_pieces(runs, v, fs, max_pause, None)
    vec = np.array([v[g].sum(axis=0) for g in groups])
    ax, _, off, size, purity = _structural(vec, np.array([spread[g].sum() for g in groups]), 1.0)
    clean = (off <= MAX_OFF_AXIS_DEG) & (purity >= _MIN_PURITY)
    tops = [size[clean & (ax == j)].max() for j in range(3) if np.any(clean & (ax == j))]
    return float(median(tops)) / angle if tops else 1.0


def _hidden_ramp(mo: Motion, start: int, stop: int) -> tuple[int, int]:
    """Samples of a turn's ramps that hide under the noise band, at its start and its end.

    For a linear ramp the time spent below the band ``low`` is the time from ``low`` to
    half speed times ``low / (half - low)``; both ends are measured on the data.
    """
    seg = mo.level[start:stop]
    core = seg[seg > mo.high]
    half = 0.5 * float(median(core)) if len(core) else 0.0
    if half <= 1.5 * mo.low:  # too weak to read a ramp from
        return 0, 0
    up = np.flatnonzero(seg >= half)
    k = mo.low / (half - mo.low)
    return math.ceil(up[0] * k), math.ceil((len(seg) - 1 - up[-1]) * k)


def _padded(mo: Motion, starts, stops, n: int, pad_n: int) -> tuple[np.ndarray, np.ndarray]:
    """Turn spans padded into the standstill around them, at most half the gap to a neighbour.

    Slow ramp ends hide under the noise band, and a static sample inside the window costs a
    little noise but no bias.
    """
    hidden = np.array([_hidden_ramp(mo, a, b) for a, b in zip(starts, stops)]).reshape(-1, 2)
    room_before = starts - np.concatenate(([0], stops[:-1]))
    room_after = np.concatenate((starts[1:], [n])) - stops
    return (starts - np.minimum(pad_n + hidden[:, 0], room_before // 2),
            stops + np.minimum(pad_n + hidden[:, 1], room_after // 2))


def angle_turns(view, mo: Motion, angle: float, max_pause: float, pad: float, *,
                k_range=K_RANGE, agree_tol=AGREE_TOL):
    """Rotation windows for a declared `angle` [rad]: ``(chosen, ignored, spans)``."""
    fs = view.sample_rate
    runs = mo.runs
    if not len(runs):
        return [], [], []
    v = mo.sums(runs[:, 0], runs[:, 1]) / fs  # integrated readings [reading units x s]
    spread = (mo.clevel[runs[:, 1]] - mo.clevel[runs[:, 0]]) / fs
    scale = _counts_scale(runs, v, spread, fs, max_pause, angle) if view.units == "counts" else 1.0
    groups = _group_pieces(runs, v / scale, fs, max_pause, _JOIN * angle, 0.05 * angle)
    vec = np.array([v[g].sum(axis=0) for g in groups]) / scale
    ax, sg, off, turned, purity = _structural(vec, np.array([spread[g].sum() for g in groups]), scale)
    starts, stops = _padded(mo, np.array([runs[g[0], 0] for g in groups]), np.array([runs[g[-1], 1] for g in groups]),
                            len(view), round(pad * fs))
    brief = turned < 0.05 * angle
    clean = ~brief & (off <= MAX_OFF_AXIS_DEG) & (purity >= _MIN_PURITY)
    keep, why = select_by_axis(turned, ax, angle, eligible=clean, k_range=k_range, agree_tol=agree_tol,
                               describe=lambda a: f"{math.degrees(a):.0f} deg")
    chosen, ignored = [], []
    for i, (start, stop) in enumerate(zip(starts.tolist(), stops.tolist())):
        label = f"{'+' if sg[i] > 0 else '-'}{'xyz'[ax[i]]}"
        if keep[i]:
            chosen.append(Window(start, stop, "rotation", "xyz"[ax[i]], int(sg[i]), angle,
                                 angle * fs / (stop - start), label))
            continue
        if brief[i]:
            reason = f"brief motion: turned {math.degrees(turned[i]):.1f} deg"
        elif off[i] > MAX_OFF_AXIS_DEG:
            reason = (f"off axis: the turn axis is {off[i]:.0f} deg from the {'xyz'[ax[i]]} axis "
                      f"(at most {MAX_OFF_AXIS_DEG:.0f})")
        elif purity[i] < _MIN_PURITY:
            reason = f"axis not fixed: only {100 * purity[i]:.0f} % of the motion adds up about one axis"
        else:
            reason = f"wrong angle: turned {why[i]}"
        ignored.append((Window(start, stop, "rotation", "xyz"[ax[i]], int(sg[i]), float(turned[i]), math.nan, label),
                        reason))
    return chosen, ignored, list(zip(starts.tolist(), stops.tolist()))
