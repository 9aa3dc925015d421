"""Automatic segmentation: rotation and static windows cut for a speed or an angle reference.

* Known speed: each turn's constant-speed plateau, ramps trimmed; its reference rate is the speed.
* Known angle: each whole turn, from where the rate leaves the static noise band to where it
  returns; pieces of one turn separated by short pauses (hand turns) are joined. The angle
  integrated from raw readings only approximates the turn (the scale is unknown), so it serves
  as a sanity check: turns far from the declared angle are ignored, with the reason.
* Static windows: the still stretches between motions, trimmed away from motion.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._validation import positive
from ..errors import InputError, SegmentationError
from ..recording import Recording
from ..windows import Window
from ._motion import Motion, detect_motion, runs_of
from ._result import NO_PLATEAU, Segmentation

__all__ = ["segment"]

_DETECT_RATE = 100.0  # [Hz]
_MAX_OFF_AXIS_DEG = 25.0  # 10 deg of mounting misalignment, with room for a hand


def _axis_sign(v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
    ax, sg, _ = _axis_sign(v)
    mag = np.linalg.norm(v, axis=1)
    groups: list[list[int]] = [[0]] if len(runs) else []
    total = v[0].copy() if len(runs) else None
    for i in range(1, len(runs)):
        g = groups[-1]
        gap = (runs[i, 0] - runs[g[-1], 1]) / fs
        gax, gsg, _ = _axis_sign(total[None])
        same = (ax[i] == gax[0] and sg[i] == gsg[0]) or mag[i] < tiny
        both_whole = full is not None and mag[i] >= full and np.linalg.norm(total) >= full
        if same and gap <= max_pause and not both_whole:
            g.append(i)
            total += v[i]
        else:
            groups.append([i])
            total = v[i].copy()
    return groups


def _common_size(mags: np.ndarray, tol: float) -> float:
    """The size most motions share within `tol` (ties: the larger), as their median.

    In counts the turns' size is unknown; the calibration turns are the motions that
    repeat, and they are larger than the re-poses between them.
    """
    cand = np.argsort(mags)[-2000:]  # the largest motions are the candidates; bounds the work
    close = np.abs(mags[None, :] / mags[cand, None] - 1) <= tol  # close[i, j]: motion j near candidate i
    count = close.sum(axis=1)
    best = np.flatnonzero(count == count.max())
    i = best[np.argmax(mags[cand[best]])]
    return float(np.median(mags[close[i]]))


def _hidden_ramp(mo: Motion, start: int, stop: int) -> tuple[int, int]:
    """Samples of a turn's ramps that hide under the noise band, at its start and its end.

    For a linear ramp the time spent below the band ``low`` is the time from ``low`` to
    half speed times ``low / (half - low)``; both ends are measured on the data.
    """
    seg = mo.level[start:stop]
    core = seg[seg > mo.high]
    half = 0.5 * float(np.median(core)) if len(core) else 0.0
    if half <= 1.5 * mo.low:  # too weak to read a ramp from
        return 0, 0
    up = np.flatnonzero(seg >= half)
    k = mo.low / (half - mo.low)
    return math.ceil(up[0] * k), math.ceil((len(seg) - 1 - up[-1]) * k)


def _angle_turns(rec, mo: Motion, angle, max_pause, angle_tol, pad):
    fs = rec.sample_rate
    runs = mo.runs
    v = mo.sums(runs[:, 0], runs[:, 1]) / fs  # integrated readings [reading units x s]
    spread = (mo.clevel[runs[:, 1]] - mo.clevel[runs[:, 0]]) / fs
    scale = 1.0
    if rec.units == "counts":
        # No physical scale: the turns are the motions of the most common size.
        groups = _group_pieces(runs, v, fs, max_pause, None)
        mags = np.array([np.linalg.norm(v[g].sum(axis=0)) for g in groups])
        scale = _common_size(mags, angle_tol) / angle
    groups = _group_pieces(runs, v / scale, fs, max_pause, (1 - angle_tol) * angle, 0.05 * angle)
    # Pad each turn into the standstill around it: slow ramp ends hide under the noise band,
    # and a static sample inside the window costs a little noise but no bias.
    starts = np.array([runs[g[0], 0] for g in groups])
    stops = np.array([runs[g[-1], 1] for g in groups])
    hidden = np.array([_hidden_ramp(mo, a, b) for a, b in zip(starts, stops)]).reshape(-1, 2)
    room_before = starts - np.concatenate(([0], stops[:-1]))
    room_after = np.concatenate((starts[1:], [len(rec)])) - stops
    pad_n = round(pad * fs)
    starts = starts - np.minimum(pad_n + hidden[:, 0], room_before // 2)
    stops = stops + np.minimum(pad_n + hidden[:, 1], room_after // 2)
    chosen, ignored = [], []
    for g, start, stop in zip(groups, starts.tolist(), stops.tolist()):
        vec = v[g].sum(axis=0) / scale
        ax, sg, off = (a[0] for a in _axis_sign(vec[None]))
        turned = float(np.linalg.norm(vec))
        purity = turned * scale / max(float(spread[g].sum()), 1e-300)
        label = f"{'+' if sg > 0 else '-'}{'xyz'[ax]}"
        if abs(turned - angle) <= angle_tol * angle and off <= _MAX_OFF_AXIS_DEG and purity >= 0.9:
            chosen.append(Window(start, stop, "rotation", "xyz"[ax], int(sg), angle, angle * fs / (stop - start), label))
            continue
        if turned < 0.05 * angle:
            reason = f"brief motion: turned {math.degrees(turned):.1f} deg"
        elif abs(turned - angle) > angle_tol * angle:
            reason = (f"wrong angle: turned about {math.degrees(turned):.0f} deg, expected {math.degrees(angle):.0f} "
                      f"+- {100 * angle_tol:.0f} %")
        elif off > _MAX_OFF_AXIS_DEG:
            reason = f"off axis: the turn axis is {off:.0f} deg from the {'xyz'[ax]} axis (at most {_MAX_OFF_AXIS_DEG:.0f})"
        else:
            reason = f"axis not fixed: only {100 * purity:.0f} % of the motion adds up about one axis"
        ignored.append((Window(start, stop, "rotation", "xyz"[ax], int(sg), turned, math.nan, label), reason))
    return chosen, ignored, list(zip(starts.tolist(), stops.tolist()))


def _plateaus(mo: Motion, n: int, level: np.ndarray, plateau_tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Stretches within `plateau_tol` of their run's `level` (vectorised).

    Returns the stretches ``(P, 2)`` and the run each belongs to. A run with a real dip
    inside (two turns with no gap) gives two stretches.
    """
    s0 = mo.runs[:, 0]
    spans = np.diff(np.concatenate(([0], mo.runs.ravel(), [n])))  # gap, run, gap, ..., gap
    thr = np.full(len(spans), np.inf)
    thr[1::2] = (1 - plateau_tol) * level
    above = mo.level >= np.repeat(thr, spans)
    above[s0] = False  # never across two runs
    st = runs_of(above)
    # No dip is closed: a dip below the band is a stop (two turns with no wait), and a turn
    # split by a rare vibration dip still gives two plateaus at the known speed.
    return st, np.searchsorted(s0, st[:, 0], side="right") - 1


def _speed_turns(rec, mo: Motion, speed, speed_tol, plateau_tol, min_plateau):
    fs = rec.sample_rate
    runs = mo.runs
    if not len(runs):
        return [], [], []
    s0, s1 = runs[:, 0], runs[:, 1]
    quarter = (s1 - s0) // 4
    level = mo.mean_level(s0 + quarter, s1 - quarter)
    ref = speed if rec.units == "rad/s" else float(np.median(level[level >= 0.5 * level.max()]))
    st, owner = _plateaus(mo, len(rec), level, plateau_tol)
    # Trim the smoothing's reach, and a third of the ramp seen before the plateau: vibration can
    # lift the level into the band while the ramp still has a part to go.
    same_prev = np.concatenate(([False], owner[1:] == owner[:-1]))
    same_next = np.concatenate((owner[1:] == owner[:-1], [False]))
    before = st[:, 0] - np.where(same_prev, np.roll(st[:, 1], 1), s0[owner])
    after = np.where(same_next, np.roll(st[:, 0], -1), s1[owner]) - st[:, 1]
    margin = mo.smooth + round(0.05 * fs)
    p0, p1 = st[:, 0] + margin + before // 3, st[:, 1] - margin - after // 3
    long = p1 - p0 >= max(min_plateau * fs, 2)
    p0, p1, owner = p0[long], p1[long], owner[long]
    mean = mo.mean_level(p0, p1)
    c2 = np.concatenate(([0.0], np.cumsum(mo.level**2)))
    sq = (c2[p1] - c2[p0]) / np.maximum(p1 - p0, 1)
    cv = np.sqrt(np.maximum(sq - mean**2, 0)) / np.where(mean > 0, mean, 1)
    ax, sg, off = _axis_sign(mo.sums(p0, p1))
    unit = 180 / math.pi if rec.units == "rad/s" else 1.0
    uname = "deg/s" if rec.units == "rad/s" else "counts"
    chosen, ignored = [], []
    for i in range(len(p0)):
        label = f"{'+' if sg[i] > 0 else '-'}{'xyz'[ax[i]]}"
        if abs(mean[i] - ref) > speed_tol * ref:
            reason = (f"wrong speed: turned at about {mean[i] * unit:.3g} {uname}, expected {ref * unit:.3g} "
                      f"+- {100 * speed_tol:.0f} %")
        elif cv[i] > plateau_tol:
            reason = f"speed not constant: it varies {100 * cv[i]:.0f} % (at most {100 * plateau_tol:.0f} %)"
        elif off[i] > _MAX_OFF_AXIS_DEG:
            reason = f"off axis: the turn axis is {off[i]:.0f} deg from the {'xyz'[ax[i]]} axis"
        else:
            n = int(p1[i] - p0[i])
            chosen.append(Window(int(p0[i]), int(p1[i]), "rotation", "xyz"[ax[i]], int(sg[i]), speed * n / fs, speed, label))
            continue
        ignored.append((Window(int(p0[i]), int(p1[i]), "rotation", "xyz"[ax[i]], int(sg[i]), label=label), reason))
    ax, sg, _ = _axis_sign(mo.sums(s0, s1))
    for i in np.setdiff1d(np.arange(len(runs)), owner).tolist():
        label = f"{'+' if sg[i] > 0 else '-'}{'xyz'[ax[i]]}"
        ignored.append((Window(int(s0[i]), int(s1[i]), "rotation", "xyz"[ax[i]], int(sg[i]), label=label),
                        f"{NO_PLATEAU}: no {min_plateau:g} s stretch within {100 * plateau_tol:.0f} % of a steady speed"))
    return chosen, ignored, [tuple(r) for r in runs.tolist()]


@dataclass(frozen=True)
class _View:
    """What detection needs of a recording, at the detection rate."""

    units: str
    sample_rate: float
    n: int

    def __len__(self) -> int:
        return self.n


def _upsample(w: Window, *, d: int, n: int, total: int, fs: float, reference: str) -> Window:
    """A window found on blocks of `d` samples, in recording samples (the last block takes the tail)."""
    w = dataclasses.replace(w, start=w.start * d, stop=total if w.stop >= n else w.stop * d)
    if w.kind != "rotation" or math.isnan(w.rate):
        return w
    if reference == "angle":
        return dataclasses.replace(w, rate=w.angle * fs / len(w))
    return dataclasses.replace(w, angle=w.rate * len(w) / fs)


def _statics(n: int, fs: float, busy: np.ndarray, trim_s: float, min_s: float, smooth: int):
    marks = np.zeros(n + 1, dtype=np.int64)
    if len(busy):
        np.add.at(marks, busy[:, 0], 1)
        np.add.at(marks, busy[:, 1], -1)
    still = runs_of(np.cumsum(marks[:-1]) == 0)
    trim = int(round(trim_s * fs))
    start = np.where(still[:, 0] > 0, still[:, 0] + trim, 0)
    stop = np.where(still[:, 1] < n, still[:, 1] - trim, n)
    chosen, ignored = [], []
    for (a, b), (ra, rb) in zip(zip(start.tolist(), stop.tolist()), still.tolist()):
        if b - a >= max(min_s * fs, 2):
            chosen.append(Window(a, b, "static", rate=0.0, label="static"))
        elif rb - ra >= 2 * smooth:
            ignored.append((Window(ra, rb, "static", label="static"),
                            (f"short static: {max(b - a, 0) / fs:.2f} s after trimming {trim_s:g} s from motion, "
                             f"at least {min_s:g} s needed")))
    return chosen, ignored


def segment(
    rec: Recording,
    *,
    reference: Literal["speed", "angle"],
    speed: float | None = None,
    angle: float | None = 2 * math.pi,
    max_pause: float = 1.0,
    pad: float = 0.1,
    angle_tol: float = 0.25,
    speed_tol: float = 0.25,
    plateau_tol: float = 0.15,
    min_plateau: float = 0.5,
    min_static: float = 0.5,
    static_trim: float = 0.25,
    require: bool = True,
) -> Segmentation:
    """Find the rotation and static windows of a recording.

    Parameters
    ----------
    rec : Recording
        Readings in rad/s, or raw counts (thresholds are relative to the data).
    reference : {"speed", "angle"}
        ``speed``: known constant speed, windows are the plateaus. ``angle``: known angle
        per turn, windows are whole turns.
    speed : float, optional
        The known speed [rad/s]; required with ``reference="speed"``.
    angle : float, optional
        Angle of every turn [rad] (default, or None: one revolution).
    max_pause : float
        Longest stop inside one turn [s] (hand turns in pieces).
    pad : float
        Standstill kept on each side of a whole turn [s] (angle reference).
    angle_tol, speed_tol : float
        Relative tolerance of the raw integrated angle, or of the plateau speed, around the
        declared one; turns outside are ignored (the scale error is unknown, so keep it loose).
    plateau_tol : float
        Relative band of the plateau around its own level (covers servo vibration).
    min_plateau, min_static : float
        Shortest plateau and static window kept [s].
    static_trim : float
        Time cut from each end of a static stretch next to motion [s].
    require : bool
        Raise :class:`~gyrocal.errors.SegmentationError` unless every axis has a rotation,
        in both senses or with a static window.
    """
    if reference not in ("speed", "angle"):
        raise InputError(f"reference must be 'speed' or 'angle', got {reference!r}")
    fs = rec.sample_rate
    if reference == "speed":
        if speed is None:
            raise InputError("reference='speed' needs the known speed [rad/s]; give speed=")
        speed = abs(positive("speed", abs(float(speed))))
    angle = 2 * math.pi if angle is None else positive("angle", abs(float(angle)))
    if len(rec) < 4:
        raise SegmentationError(f"the recording has {len(rec)} sample(s); nothing to segment")
    # Detect on block means at about 200 Hz: a turn's edges need no finer time, and fast logs
    # then cost one pass over the samples.
    # 1e-3 of slack: a rate measured a hair under a multiple (199.995 Hz from epoch stamps) decimates as
    # the nominal one does, so detection never depends on where the time column starts
    d = max(1, int(fs / _DETECT_RATE * (1 + 1e-3)))
    n = len(rec) // d
    gyro = np.asarray(rec.gyro, dtype=float)
    if d > 1:  # block means axis by axis as matrix-vector products: contiguous views for column-major logs
        gyro = np.stack([col.reshape(n, d) @ np.full(d, 1.0 / d) for col in gyro.T[:, : n * d]], axis=1)
    view = _View(rec.units, fs / d, n)
    mo = detect_motion(gyro, view.sample_rate)
    if reference == "angle":
        rot, ign, spans = _angle_turns(view, mo, angle, max_pause, angle_tol, pad) if len(mo.runs) else ([], [], [])
    else:
        rot, ign, spans = _speed_turns(view, mo, speed, speed_tol, plateau_tol, min_plateau)
    busy = np.concatenate([mo.busy, np.asarray(spans, dtype=np.int64).reshape(-1, 2)])
    sta, ign_sta = _statics(n, view.sample_rate, busy, static_trim, min_static, mo.smooth)
    up = functools.partial(_upsample, d=d, n=n, total=len(rec), fs=fs, reference=reference)
    seg = Segmentation(tuple(up(w) for w in rot + sta), tuple((up(w), r) for w, r in ign + ign_sta), reference, fs,
                       mo.baseline, mo.noise_std * math.sqrt(d))
    if require:
        seg.require()
    return seg
