"""The two readings of a declared plateau speed under a periodic ripple, and which one the data favour.

A servo's speed ripple leaves a partial cycle at each end of a plateau. The declared speed is then
either the level under the ripple (:func:`gyrocal.observations.longrun.fit_level`: a servo whose angle error is
bounded) or the mean over the whole plateau, ramp end to ramp start (a motion that covers its
commanded angle there). They differ by the mean of the ripple's partial cycles
(:func:`partial_cycles`), which does not shrink with a longer window. :func:`weigh_readings` compares
the two by how well opposite turns about one axis agree with the standstill offset (their readings
sum to twice it, misalignment included) and averages them by that evidence: level and variance of a
mixture of two models, so the spread between them is carried where the data cannot tell.
"""

from __future__ import annotations

import math

import numpy as np

from .longrun import line_mean, ramp_end

__all__ = ["partial_cycles", "weigh_readings"]


def partial_cycles(gyro: np.ndarray, span: tuple[int, int], x: np.ndarray, t: np.ndarray, lines: list[float],
                   level: np.ndarray) -> np.ndarray:
    """Mean (3,) of a plateau's fitted ripple over the whole plateau, ramp end to ramp start.

    `gyro` holds the block means, the plateau `x` (at times `t`, in block steps) spans ``span`` of them
    and has `level` under its ripple lines; the ramps are found beyond the window
    (:func:`gyrocal.observations.longrun.ramp_end`), else the window's own ends stand for them.
    """
    if not lines:
        return np.zeros(x.shape[1])
    a, b = span
    j = int(np.argmax(np.abs(level)))
    sign, look = np.sign(level[j]), b - a
    a0, b1 = max(0, a - look), min(len(gyro), b + look)
    up = ramp_end(sign * gyro[a0:a, j], abs(level[j]))
    down = ramp_end(sign * gyro[b:b1, j][::-1], abs(level[j]))
    lo = 0.0 if up is None else a0 + up - a
    hi = float(t[-1]) if down is None else b1 - 1 - down - a
    return line_mean(x, t, lines, lo, hi)


def _evidence(out: dict, windows: dict, statics: dict, lrv: np.ndarray) -> float:
    """Chi-square of the plateau means' reading less that of the levels' (pairs of opposite turns)."""
    n = sum(len(b) for b in statics.values())
    offset = sum(b.sum(axis=0) for b in statics.values()) / n
    chi = np.zeros(2)
    for axis in {w.axis for w in windows.values()}:
        sides = [[i for i, w in windows.items() if w.axis == axis and w.sign == s] for s in (1, -1)]
        if not all(sides):
            continue
        total, var, shift = np.zeros(3), 4 * lrv / n, np.zeros(3)
        for side in sides:
            total = total + np.mean([out[i]["level"] for i in side], axis=0)
            var = var + np.sum([out[i]["mean_var"] for i in side], axis=0) / len(side) ** 2
            shift = shift + np.mean([out[i]["cycles"] for i in side], axis=0)
        chi += [np.sum((total - 2 * offset) ** 2 / var), np.sum((total + shift - 2 * offset) ** 2 / var)]
    return float(chi[1] - chi[0])


def weigh_readings(out: dict, windows: dict, statics: dict, lrv: np.ndarray | None) -> None:
    """Replace each plateau's level in `out` by the two readings' mixture, widening its ``mean_var``.

    `windows` are the plateaus by index, `statics` the static windows' block means, `lrv` their pooled
    long-run variance per block mean (None: no evidence, the readings weigh evenly).
    """
    p = 0.5
    if lrv is not None and all("mean_var" in out[i] for i in windows):
        p = 1.0 / (1.0 + math.exp(float(np.clip(0.5 * _evidence(out, windows, statics, lrv), -50, 50))))
    for i in windows:
        delta = out[i].pop("cycles")
        out[i]["level"] = out[i]["level"] + p * delta
        if "mean_var" in out[i]:
            out[i]["mean_var"] = out[i]["mean_var"] + p * (1 - p) * delta**2
