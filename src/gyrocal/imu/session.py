"""Calibrate a whole IMU from one hand session: statics, accelerometer, then gyro.

Two kinds of session:

* **multi-position** (Tedaldi et al., ICRA 2014): the board rests in many orientations and is
  turned by hand between them. Still poses are found in the data
  (:func:`~gyrocal.imu.statics.detect_statics`); the accelerometer comes from the gravity
  magnitude over the poses, the gyro from matching the gravity direction across each turn.
* **Ferraris** (imucal's protocol: six still poses ``x_p, x_a, y_p, y_a, z_p, z_a`` with each
  axis up and down, then turns ``x_rot, y_rot, z_rot`` of a known angle about the vertical),
  given as labelled windows. The poses' directions are known, so the accelerometer takes the
  12-parameter model in the frame of the box; the gyro joins the six poses in sequence and
  uses each turn's known angle about the vertical measured in the poses on either side of it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .._validation import at_least, finite_array, positive
from ..errors import InputError, SegmentationError
from ..recording.breaks import spans_break, split_spans
from ..segmentation.windows import Window
from ..units import STANDARD_GRAVITY
from ._fit import unchecked_warning
from .accel import AccelFit, fit_accelerometer
from .gyro import GyroFit, Turn, fit_gyroscope
from .poses import Coverage, coverage
from .statics import Static, StaticDetection, detect_statics, summarise_statics
from .sweep import sweep_statics

__all__ = ["FERRARIS_POSES", "ImuCalibrationResult", "calibrate_imu"]

#: imucal's pose labels and the specific-force direction each stands for (x_p: x up, reads +g).
FERRARIS_POSES = {"x_p": (1, 0, 0), "x_a": (-1, 0, 0), "y_p": (0, 1, 0), "y_a": (0, -1, 0),
                  "z_p": (0, 0, 1), "z_a": (0, 0, -1)}
#: Furthest a still pose may be from a turn to give its axis [s].
_TURN_NEIGHBOUR_S = 5.0
#: Poses before and after a turn further apart than this were not on the same face [deg].
_SAME_FACE_DEG = 5.0
#: Coverage spread below which the poses see one direction poorly.
_POOR_SPREAD = 0.3


@dataclass(frozen=True)
class ImuCalibrationResult:
    """A whole-IMU calibration from a hand session.

    Attributes
    ----------
    kind : {"multi-position", "ferraris"}
    statics : tuple of Static
        The poses used, in time order.
    detection : StaticDetection or None
        What the detector measured (None when the poses came from windows).
    coverage : Coverage
        Of the calibrated gravity directions.
    accel : AccelFit
    gyro : GyroFit
    turns : tuple of Turn
        Known-angle turns used (Ferraris sessions), with the vertical measured beside each.
    warnings : tuple of str
    """

    kind: Literal["multi-position", "ferraris"]
    statics: tuple[Static, ...]
    detection: StaticDetection | None
    coverage: Coverage
    accel: AccelFit
    gyro: GyroFit
    turns: tuple[Turn, ...] = field(default_factory=tuple)
    warnings: tuple[str, ...] = field(default_factory=tuple)


def _ferraris_labels(windows: Sequence[Window]) -> bool:
    labels = {w.label for w in windows if w.kind == "static"}
    return set(FERRARIS_POSES) <= labels


def _neighbour_axis(turn: Window, detected: Sequence[Static], accel: AccelFit):
    """The vertical during a turn: calibrated direction of the still poses just before and just after it.

    Returns ``(axis, std, spread_deg)`` or None when no pose lies within a few seconds of the turn;
    ``spread_deg`` is the angle between the two poses (0 with one), large when the board was
    not put back on the face it turned on.
    """
    before = [s for s in detected if s.stop <= turn.start + 1 and turn.start - s.stop < _TURN_NEIGHBOUR_S * _rate(s)]
    after = [s for s in detected if s.start >= turn.stop - 1 and s.start - turn.stop < _TURN_NEIGHBOUR_S * _rate(s)]
    near = ([before[-1]] if before else []) + ([after[0]] if after else [])
    if not near:
        return None
    f = accel.correct(np.array([s.accel_mean for s in near]))
    u = f / np.linalg.norm(f, axis=1, keepdims=True)
    axis = u.mean(axis=0)
    axis /= np.linalg.norm(axis)
    se = np.array([np.abs(accel.matrix) @ s.accel_se for s in near])
    std = float(np.sqrt(np.mean(se**2) / len(near)) / accel.gravity)
    spread = float(np.degrees(np.arccos(np.clip(u[0] @ u[-1], -1, 1))))
    return axis, std, spread


def _rate(s: Static) -> float:
    return (s.count - 1) / max(s.duration, 1e-12)


def _ferraris_turns(t, gyro, accel_raw, windows, accel: AccelFit, statics, breaks=()) -> tuple[list[Turn], list[str]]:
    """Known-angle turns, each about the vertical measured in the poses beside it."""
    det = detect_statics(t, gyro, accel_raw, min_duration=0.5, breaks=breaks)
    turns, notes = [], []
    for w in windows:
        if w.kind != "rotation":
            continue
        if spans_break(w.start, w.stop, breaks):
            notes.append(f"turn {w.label or w.start}: the log is not contiguous inside it (a break at sample "
                         f"{next(b for b in breaks if w.start < b < w.stop)}); not used")
            continue
        angle = abs(w.angle) if math.isfinite(w.angle) else 2 * math.pi
        found = _neighbour_axis(w, det.statics, accel)
        if found is None:
            pose = next((s for s in statics if w.label[:1] and s.label == f"{w.label[:1]}_p"), None)
            if pose is None:
                notes.append(f"turn {w.label or w.start}: no still pose beside it to give its axis; not used")
                continue
            i = statics.index(pose)
            found = accel.directions[i], float(accel.direction_std[i]), 0.0
            notes.append(f"turn {w.label}: no still pose beside it; its axis is taken from pose {pose.label}")
        elif found[2] > _SAME_FACE_DEG:
            notes.append(f"turn {w.label or w.start}: the board rests {found[2]:.0f} deg differently before and "
                         "after it, so it did not turn about the vertical alone; its known angle is less reliable")
        turns.append(Turn(w.start, w.stop, angle, found[0], found[1], w.label))
    return turns, notes


def _pairs_without_gaps(statics, gaps, breaks=()) -> tuple[np.ndarray, list[str]]:
    """Consecutive pose pairs whose move holds no gap and no break, and why the others were left out."""
    gaps, breaks = np.asarray(list(gaps), dtype=int), np.asarray(list(breaks), dtype=int)
    keep, notes = [], []
    for i in range(len(statics) - 1):
        a, b = statics[i].stop - 1, statics[i + 1].start
        if np.any((breaks > a) & (breaks <= b)):
            notes.append(f"pose {i + 1} -> {i + 2} left out: the log is not contiguous in the move between them "
                         f"(a break at sample {int(breaks[(breaks > a) & (breaks <= b)][0])})")
        elif np.any((gaps > a) & (gaps <= b)):
            notes.append(f"pose {i + 1} -> {i + 2} left out: samples are missing in the move between them")
        else:
            keep.append((i, i + 1))
    return np.array(keep, dtype=int).reshape(-1, 2), notes


def _given_statics(t, gyro, accel, windows, breaks) -> tuple[tuple[Static, ...], list[str]]:
    """The still windows given, each cut to its longest part where a break falls inside it."""
    spans, notes = [], []
    for w in sorted((w for w in windows if w.kind == "static"), key=lambda w: w.start):
        if w.stop > len(t):
            raise InputError(f"a still window ends past the recording's {len(t)} samples")
        a, b = max(split_spans(w.start, w.stop, breaks), key=lambda p: p[1] - p[0])
        if (a, b) != (w.start, w.stop):
            notes.append(f"pose {w.label or w.start}: the log is not contiguous inside it; its longest part, samples "
                         f"{a}-{b}, is used")
        spans.append((a, b, w.label))
    statics = summarise_statics(t, gyro, accel, [(a, b) for a, b, _ in spans], [lab for _, _, lab in spans])
    return statics, notes


def calibrate_imu(t, gyro, accel, *, gravity: float = STANDARD_GRAVITY, windows: Sequence[Window] | None = None,
                  accel_model="auto", gyro_model="auto", g_sensitivity: bool = False,
                  min_static: float = 1.0, gaps: Sequence[int] = (), breaks: Sequence[int] = (),
                  threshold: float | None = None) -> ImuCalibrationResult:
    """Calibrate the accelerometer and the gyro of a hand session.

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s]: the real stamps, used for the gyro's integration.
    gyro : array_like, shape (N, 3)
        Gyro readings [rad/s, or counts].
    accel : array_like, shape (N, 3)
        Accelerometer readings [m/s^2, or counts].
    gravity : float
        Local gravity [m/s^2].
    windows : sequence of Window, optional
        Still poses (``kind="static"``) and turns chosen by hand. imucal's labels
        (``x_p ... z_a``, ``x_rot ...``) make it a Ferraris session. Without windows the still
        poses are detected.
    accel_model, gyro_model : str
        See :func:`~gyrocal.imu.accel.fit_accelerometer` and :func:`~gyrocal.imu.gyro.fit_gyroscope`.
    g_sensitivity : bool
        Fit the gyro's sensitivity to specific force where the poses determine it.
    min_static : float
        Shortest still pose the detector keeps [s].
    gaps : sequence of int
        Samples before which samples are missing (:attr:`gyrocal.recording.timebase.TimeBase.gaps`): a turn
        across a gap has lost angle, so the pose pair around it is left out.
    breaks : sequence of int
        Samples that start a new part of a log that is not contiguous (:attr:`gyrocal.recording.timebase.TimeBase.breaks`):
        no pose, pair or turn spans one.
    threshold : float or None
        Multiplier of the detector's stillness thresholds; None tries several
        (:func:`~gyrocal.imu.statics.sweep_statics`).
    """
    t = finite_array("t", t, ndim=1)
    gyro = finite_array("gyro", gyro, shape_tail=(3,), ndim=2)
    accel = finite_array("accel", accel, shape_tail=(3,), ndim=2)
    gravity = positive("gravity", gravity)
    if not len(t) == len(gyro) == len(accel):
        raise InputError(f"t, gyro and accel need one row per sample, got {len(t)}, {len(gyro)}, {len(accel)}")
    ferraris = windows is not None and _ferraris_labels(windows)
    detection, notes = None, []
    if windows is not None:
        statics, notes = _given_statics(t, gyro, accel, windows, breaks)
    else:
        detection = sweep_statics(t, gyro, accel, min_duration=at_least("min_static", min_static, 0.0, " s"),
                                  breaks=breaks, gravity=gravity, accel_model=accel_model,
                                  multiplier=None if threshold is None else positive("threshold", threshold))
        statics = detection.statics
    if not statics:
        raise SegmentationError(f"no still pose of {min_static:g} s or more was found; hold the board still "
                                "between turns (rest it on a table) for 2 s or more in each orientation, or raise "
                                "--threshold (multiplier of the stillness thresholds)")
    means = np.array([s.accel_mean for s in statics])
    se = np.array([s.accel_se for s in statics])
    directions = np.array([FERRARIS_POSES[s.label] for s in statics]) if ferraris else None
    afit = fit_accelerometer(means, se, gravity=gravity, model=accel_model, directions=directions)
    force = afit.correct(accel)
    turns, turn_notes = (_ferraris_turns(t, gyro, accel, windows, afit, statics, breaks) if ferraris else ([], []))
    pairs, pair_notes = _pairs_without_gaps(statics, gaps, breaks)
    notes += turn_notes + pair_notes
    gfit = fit_gyroscope(t, gyro, force, statics, afit, pairs=pairs, turns=turns, model=gyro_model,
                         g_sensitivity=g_sensitivity)
    cov = coverage(afit.directions)
    warnings = (list(afit.fit.warnings) + unchecked_warning("accelerometer", afit.choice) + notes
                + list(gfit.fit.warnings) + unchecked_warning("gyro", gfit.choice))
    if cov.spread < _POOR_SPREAD and not ferraris:
        warnings.append(f"the poses cover the sphere poorly (spread {cov.spread:.2f} of 1); add poses with the "
                        f"sensor direction ({', '.join(f'{v:+.2f}' for v in cov.weakest_axis)}) up or down")
    return ImuCalibrationResult(kind="ferraris" if ferraris else "multi-position", statics=tuple(statics),
                                detection=detection, coverage=cov, accel=afit, gyro=gfit, turns=tuple(turns),
                                warnings=tuple(warnings))
