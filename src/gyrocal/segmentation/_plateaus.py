"""Constant-speed plateaus for a known speed, recognised by their structure.

A plateau is a steady stretch of one turn (within `plateau_tol` of the turn's own level), about
one axis, trimmed of its ramps. Its level is then compared with the declared speed through a
per-axis scale factor (:func:`~gyrocal.segmentation._select.select_by_axis`), never by
closeness alone, so a gyro with k from 0.5 to 2 is found.
"""

from __future__ import annotations

import math

import numpy as np

from .._arrays import median
from ._motion import Motion, runs_of
from ._result import NO_PLATEAU
from ._select import AGREE_TOL, K_RANGE, select_by_axis
from ._turns import MAX_OFF_AXIS_DEG, axis_sign
from .windows import Window

__all__ = ["speed_turns"]

#: A dip inside a turn that stays above this share of its level is vibration, not a stop.
_STOP = 0.5


def _join_dips(st: np.ndarray, owner: np.ndarray, level: np.ndarray, run_level: np.ndarray) -> np.ndarray:
    """Join stretches of one run whose level never drops below `_STOP` of the run's level between them.

    At low sample rates the smoothing spans few samples, and noise plus vibration dip the
    level out of the plateau band now and then: that is one turn, not two. Two turns with no
    wait between them stop in between and stay apart.
    """
    if len(st) < 2:
        return st
    out = [st[0].copy()]
    for i in range(1, len(st)):
        a, b = out[-1][1], st[i, 0]
        if owner[i] == owner[i - 1] and (b <= a or level[a:b].min() >= _STOP * run_level[owner[i]]):
            out[-1][1] = st[i, 1]
        else:
            out.append(st[i].copy())
    return np.array(out)


def _plateaus(mo: Motion, n: int, level: np.ndarray, plateau_tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Stretches within `plateau_tol` of their run's `level` (vectorised), dips joined.

    Returns the stretches ``(P, 2)`` and the run each belongs to. A run with a real stop
    inside (two turns with no gap) gives two stretches.
    """
    s0 = mo.runs[:, 0]
    spans = np.diff(np.concatenate(([0], mo.runs.ravel(), [n])))  # gap, run, gap, ..., gap
    thr = np.full(len(spans), np.inf)
    thr[1::2] = (1 - plateau_tol) * level
    above = mo.level >= np.repeat(thr, spans)
    above[s0] = False  # never across two runs
    st = runs_of(above)
    owner = np.searchsorted(s0, st[:, 0], side="right") - 1
    st = _join_dips(st, owner, mo.level, level)
    return st, np.searchsorted(s0, st[:, 0], side="right") - 1


def _trimmed(mo: Motion, st, owner, fs: float, min_plateau: float):
    """Plateau spans trimmed of the smoothing's reach and a third of the ramp seen before them.

    Vibration can lift the level into the band while the ramp still has some way to go.
    """
    s0, s1 = mo.runs[:, 0], mo.runs[:, 1]
    same_prev = np.concatenate(([False], owner[1:] == owner[:-1]))
    same_next = np.concatenate((owner[1:] == owner[:-1], [False]))
    before = st[:, 0] - np.where(same_prev, np.roll(st[:, 1], 1), s0[owner])
    after = np.where(same_next, np.roll(st[:, 0], -1), s1[owner]) - st[:, 1]
    margin = mo.smooth + round(0.05 * fs)
    p0, p1 = st[:, 0] + margin + before // 3, st[:, 1] - margin - after // 3
    long = p1 - p0 >= max(min_plateau * fs, 2)
    return p0[long], p1[long], owner[long]


def speed_turns(view, mo: Motion, speed: float, plateau_tol: float, min_plateau: float, *,
                k_range=K_RANGE, agree_tol=AGREE_TOL):
    """Plateau windows for a declared `speed` [rad/s]: ``(chosen, ignored, spans)``."""
    fs = view.sample_rate
    runs = mo.runs
    if not len(runs):
        return [], [], []
    s0, s1 = runs[:, 0], runs[:, 1]
    quarter = (s1 - s0) // 4
    level = mo.mean_level(s0 + quarter, s1 - quarter)
    # counts: the declared speed reads as the level of the larger turns (no physical scale)
    ref = speed if view.units == "rad/s" else float(median(level[level >= 0.5 * level.max()]))
    st, owner = _plateaus(mo, len(view), level, plateau_tol)
    p0, p1, owner = _trimmed(mo, st, owner, fs, min_plateau)
    mean = mo.mean_level(p0, p1)
    c2 = np.concatenate(([0.0], np.cumsum(mo.level**2)))
    sq = (c2[p1] - c2[p0]) / np.maximum(p1 - p0, 1)
    cv = np.sqrt(np.maximum(sq - mean**2, 0)) / np.where(mean > 0, mean, 1)
    ax, sg, off = axis_sign(mo.sums(p0, p1))
    unit = 180 / math.pi if view.units == "rad/s" else 1.0
    uname = "deg/s" if view.units == "rad/s" else "counts"
    steady = (cv <= plateau_tol) & (off <= MAX_OFF_AXIS_DEG)
    keep, why = select_by_axis(mean, ax, ref, eligible=steady, k_range=k_range, agree_tol=agree_tol,
                               describe=lambda r: f"{r * unit:.3g} {uname}")
    chosen, ignored = [], []
    for i in range(len(p0)):
        label = f"{'+' if sg[i] > 0 else '-'}{'xyz'[ax[i]]}"
        if keep[i]:
            n = int(p1[i] - p0[i])
            chosen.append(Window(int(p0[i]), int(p1[i]), "rotation", "xyz"[ax[i]], int(sg[i]), speed * n / fs, speed,
                                 label))
            continue
        if cv[i] > plateau_tol:
            reason = f"speed not constant: it varies {100 * cv[i]:.0f} % (at most {100 * plateau_tol:.0f} %)"
        elif off[i] > MAX_OFF_AXIS_DEG:
            reason = f"off axis: the turn axis is {off[i]:.0f} deg from the {'xyz'[ax[i]]} axis"
        else:
            reason = f"wrong speed: turned at {why[i]}"
        ignored.append((Window(int(p0[i]), int(p1[i]), "rotation", "xyz"[ax[i]], int(sg[i]), rate=float(mean[i]),
                               label=label), reason))
    ax, sg, _ = axis_sign(mo.sums(s0, s1))
    unowned = np.ones(len(runs), dtype=bool)
    unowned[owner] = False  # the runs that hold no plateau
    for i in np.flatnonzero(unowned).tolist():
        label = f"{'+' if sg[i] > 0 else '-'}{'xyz'[ax[i]]}"
        ignored.append((Window(int(s0[i]), int(s1[i]), "rotation", "xyz"[ax[i]], int(sg[i]), label=label),
                        f"{NO_PLATEAU}: no {min_plateau:g} s stretch within {100 * plateau_tol:.0f} % of a steady speed"))
    return chosen, ignored, [tuple(r) for r in runs.tolist()]
