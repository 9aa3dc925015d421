"""Automatic segmentation: rotation and static windows cut for a speed or an angle reference.

* Known speed: each turn's constant-speed plateau, ramps trimmed; its reference rate is the
  speed (:mod:`._plateaus`).
* Known angle: each whole turn, from where the rate leaves the static noise band to where it
  returns; pieces of one turn separated by short pauses (hand turns) are joined (:mod:`._turns`).
* Either way a turn is recognised by its structure (one dominant axis, steady or clean), and
  the declaration is checked, not imposed: one scale factor per axis must explain every turn
  taken for the declared one (:mod:`._select`); the others are ignored with their measured size.
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
from ._advice import advise
from ._motion import detect_motion, runs_of
from ._plateaus import speed_turns
from ._result import Segmentation
from ._select import AGREE_TOL, K_RANGE
from ._turns import angle_turns
from .windows import Window

__all__ = ["segment"]

_DETECT_RATE = 100.0  # [Hz]


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
    start, stop = w.start * d, total if w.stop >= n else w.stop * d
    if w.kind != "rotation" or math.isnan(w.rate):
        return dataclasses.replace(w, start=start, stop=stop)
    if reference == "angle":
        return dataclasses.replace(w, start=start, stop=stop, rate=w.angle * fs / (stop - start))
    return dataclasses.replace(w, start=start, stop=stop, angle=w.rate * (stop - start) / fs)


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
    k_range: tuple[float, float] = K_RANGE,
    agree_tol: float = AGREE_TOL,
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
    k_range : (float, float)
        Scale factors a turn taken for the declared one may imply (declared / measured size);
        the default 0.45-2.2 finds a poor gyro with k from 0.5 to 2.
    agree_tol : float
        Relative spread allowed between the measured sizes (raw angle or plateau speed) of the
        turns about one axis: one scale factor per axis must explain them all.
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
    require_motion_or_noise(rec.gyro)
    # Detect on block means at about 100-200 Hz: a turn's edges need no finer time, and fast logs
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
        rot, ign, spans = angle_turns(view, mo, angle, max_pause, pad, k_range=k_range, agree_tol=agree_tol)
    else:
        rot, ign, spans = speed_turns(view, mo, speed, plateau_tol, min_plateau, k_range=k_range, agree_tol=agree_tol)
    busy = np.concatenate([mo.busy, np.asarray(spans, dtype=np.int64).reshape(-1, 2)])
    sta, ign_sta = _statics(n, view.sample_rate, busy, static_trim, min_static, mo.smooth)
    up = functools.partial(_upsample, d=d, n=n, total=len(rec), fs=fs, reference=reference)
    ignored = tuple((up(w), r) for w, r in ign + ign_sta)
    seg = Segmentation(tuple(up(w) for w in rot + sta), ignored, reference, fs, mo.baseline,
                       mo.noise_std * math.sqrt(d), rec.units,
                       advise(ignored, reference, speed if reference == "speed" else angle, rec.units,
                              accepted=len(rot), sample_rate=fs, has_time=rec.has_time))
    if require:
        seg.require()
    return seg


def require_motion_or_noise(gyro: np.ndarray) -> None:
    """Refuse readings that never change on any axis (all zero, or a stuck sensor): nothing to segment."""
    g = np.asarray(gyro)
    if np.ptp(g[:1000], axis=0).any() or np.ptp(g, axis=0).any():
        return
    level = ", ".join(f"{v:.6g}" for v in g[0])
    raise SegmentationError(
        f"every reading is the same ({level} on x, y, z): the sensor was not running or the columns are not "
        "the gyro's; check the file and --columns"
    )
