"""The guided multi-position hand session of a whole IMU: hold still in a pose, turn to the next one.

Where to go next comes from gyrocal's pose planning: first the plan of
:func:`gyrocal.imu.poses.pose_sequence` (each pose a 90 deg tilt from the last, filling the
sphere: the plan :func:`gyrocal.imu.planning.predict_poses` predicts the accuracy of), then,
once the poses actually held cover that plan, the centre of the largest empty cap
(:func:`gyrocal.imu.poses.coverage`). Each target is named by the nearest of 26 orientations a
person can find on a box: a face up ("z up", "x down"), an edge up, a corner up.

Each pose is judged live with the still-pose detector of the whole-IMU calibration
(:func:`gyrocal.imu.statics.detect_statics`, thresholds from the data's own noise), run on the
samples since the previous pose began, at fixed points of the data (every 0.25 s of samples), so
the outcome does not depend on how the bytes arrived. A pose is accepted once the board has been
still for the hold time (less the detector's window, as the planning counts it) and its gravity
direction is more than 10 deg (:data:`gyrocal.imu.poses.DISTINCT_DEG`) from every pose accepted
before; it is refused, saying why, when the stillness ends too soon or repeats an earlier pose.
:meth:`PoseGuide.redo` takes back the last pose. The session is complete when there are enough
poses and they cover the sphere (:data:`MIN_SPREAD`); :meth:`PoseGuide.windows` gives the poses
for :func:`gyrocal.imu.run.calibrate_recording`.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from .. import quaternion as quat
from ..errors import InputError
from ..imu.planning import DETECTOR_WINDOW
from ..imu.poses import DISTINCT_DEG, UP, coverage, pose_sequence
from ..imu.statics import detect_statics
from ..recording import Recording
from ..segmentation.windows import Window
from .guide import GuideEvent, SteppedJudge

__all__ = ["CANDIDATES", "HOLD_S", "MIN_POSES", "MIN_SPREAD", "PoseGuide", "describe", "guided_directions",
           "next_target", "plan_directions"]

#: Poses of a complete session by default: the smallest plan of :func:`gyrocal.imu.planning.suggest_poses`
#: (fewer leave the 9-parameter accelerometer too few spare equations to check its fit).
MIN_POSES = 12
#: Coverage spread the poses must reach (1 = even over the sphere; the calibration warns below 0.3).
MIN_SPREAD = 0.5
#: Still time asked for in each pose [s] (the planning's default static duration).
HOLD_S = 2.0
#: Shortest stillness that counts as an attempt at a pose [s] (shorter pauses are part of a turn).
MIN_STILL_S = 1.0
#: A plan target this close to a pose held is done [deg].
COVERED_DEG = 25.0
#: The detector looks at the samples since this many poses back, and at most MAX_CONTEXT_S [s] of them; it
#: calls a stillness too short only when it had SHORT_CONTEXT_S [s] or more to measure its thresholds on.
CONTEXT_POSES, MAX_CONTEXT_S, SHORT_CONTEXT_S = 3, 40.0, 5.0
#: Stillness in the same orientation again this soon after it is the same pose (a nudge, or a false alarm of the
#: detector), not a new one; and a stillness counts as over only once this much of something else followed [s].
BUMP_S = 1.0

#: The 26 orientations a person can find on a box: faces, edges and corners up (unit vectors, sensor frame).
_CUBE = [v for v in itertools.product((-1, 0, 1), repeat=3) if any(v)]
_CUBE.sort(key=lambda v: sum(map(abs, v)))
CANDIDATES = np.array(_CUBE, dtype=float) / np.linalg.norm(_CUBE, axis=1, keepdims=True)


def _name(v) -> str:
    parts = [f"{'xyz'[i]} {'up' if c > 0 else 'down'}" for i, c in enumerate(v) if c]
    if len(parts) == 1:
        return parts[0]
    if len(parts) == 2:
        return f"halfway between {parts[0]} and {parts[1]} (45 deg tilt)"
    return f"a corner up: {parts[0]}, {parts[1]} and {parts[2]} (each axis 35 deg from level)"


_NAMES = [_name(v) for v in _CUBE]


def _angles(u: np.ndarray, dirs) -> np.ndarray:
    """Angles [deg] between the unit vector `u` and each unit vector of `dirs`."""
    return np.degrees(np.arccos(np.clip(np.asarray(dirs).reshape(-1, 3) @ u, -1.0, 1.0)))


def describe(u) -> str:
    """The nearest box orientation of gravity direction `u` (sensor frame), with how far off it is."""
    u = np.asarray(u, float) / np.linalg.norm(u)
    ang = _angles(u, CANDIDATES)
    i = int(np.argmin(ang))
    return _NAMES[i] + (f", {ang[i]:.0f} deg off" if ang[i] > DISTINCT_DEG else "")


def plan_directions(n: int = MIN_POSES, tilt_deg: float = 90.0) -> np.ndarray:
    """The planned gravity directions (m, 3), m <= n: :func:`pose_sequence`'s poses snapped to box orientations."""
    q = pose_sequence(max(int(n), 2), tilt_deg)
    ups = quat.rotate(q * [1, -1, -1, -1], UP)  # 'up' as the sensor sees it
    idx = np.argmax(ups @ CANDIDATES.T, axis=1)
    return CANDIDATES[list(dict.fromkeys(idx.tolist()))]


def next_target(plan: np.ndarray, held) -> np.ndarray:
    """Where the next pose should go: the first `plan` direction no pose `held` (k, 3) covers, else the box
    orientation nearest the centre of the largest empty cap."""
    dirs = np.asarray(held, float).reshape(-1, 3)
    for d in plan:
        if not len(dirs) or _angles(d, dirs).min() > COVERED_DEG:
            return d
    free = [c for c in CANDIDATES if _angles(c, dirs).min() > DISTINCT_DEG]
    centre = coverage(dirs).empty_cap_centre
    return max(free or list(CANDIDATES), key=lambda c: float(c @ centre))


def guided_directions(poses: int = MIN_POSES) -> np.ndarray:
    """The targets (m, 3) a person who lands every pose exactly is asked for, until the session is complete."""
    plan, held = plan_directions(poses), []
    while len(held) < poses or coverage(np.array(held)).spread < MIN_SPREAD:
        held.append(next_target(plan, held))
    return np.array(held)


def _merged(statics, gap: int) -> list[tuple[np.ndarray, list[tuple[int, int]]]]:
    """Still intervals as ``(accel mean, pieces)``: the detector's intervals, with those less than `gap` samples
    apart joined when the board points the same way on both sides (a nudge, or a false alarm of the detector,
    whose thresholds come from the few seconds of data it is given), not a move to another pose. `pieces` are
    the detector's own intervals ``(start, stop)``: a pose's samples come from one of them, never across a gap."""
    out: list[list] = []
    for st in statics:
        u = st.accel_mean / np.linalg.norm(st.accel_mean)
        if out and st.start - out[-1][2][-1][1] < gap and _angles(u, out[-1][0] / out[-1][1])[0] <= DISTINCT_DEG:
            out[-1][0] = out[-1][0] + st.accel_mean * st.count
            out[-1][1] += st.count
            out[-1][2].append((st.start, st.stop))
        else:
            out.append([st.accel_mean * st.count, st.count, [(st.start, st.stop)]])
    return [(total / count, pieces) for total, count, pieces in out]


@dataclass
class _Pose:
    start: int              # absolute samples, stop exclusive; stop grows while the board stays still
    stop: int
    direction: np.ndarray   # unit gravity direction, raw accelerometer, sensor frame
    target: np.ndarray


class PoseGuide(SteppedJudge):
    """Walk a person through a multi-position hand session (see the module notes).

    Parameters
    ----------
    poses : int
        Poses needed (at least 6; default :data:`MIN_POSES`).
    hold : float
        Still time asked for in each pose [s].
    every : float
        Data between two judgements [s].
    """

    name = "multi-position"

    def __init__(self, *, poses: int = MIN_POSES, hold: float = HOLD_S, every: float = 0.25):
        if int(poses) != poses or poses < 6:
            raise InputError(f"{{param}} must be a whole number >= 6, got {poses!r}", param="poses", value=poses)
        if not hold > DETECTOR_WINDOW + MIN_STILL_S:
            raise InputError(f"{{param}} must exceed {DETECTOR_WINDOW + MIN_STILL_S:g} s, got {hold!r}",
                             param="hold", value=hold)
        self.poses, self.hold, self.every = int(poses), float(hold), float(every)
        self.accepted: list[_Pose] = []
        self._plan = plan_directions(self.poses)
        self._after = 0      # a new pose's stillness must start at or after this sample
        self._told = 0       # stillness starting before this sample has been called too short
        self._checked = 0    # samples judged so far
        self._lo = 0         # first sample the detector looked at last time
        self.target = next_target(self._plan, [])

    # -- state -----------------------------------------------------------------------------------------------

    @property
    def spread(self) -> float:
        return coverage(np.array([p.direction for p in self.accepted])).spread if self.accepted else 0.0

    @property
    def complete(self) -> bool:
        return len(self.accepted) >= self.poses and self.spread >= MIN_SPREAD

    @property
    def keep_from(self) -> int:
        """First sample (absolute index) the guide may still look at."""
        return self._lo

    def status(self) -> str:
        return f"{len(self.accepted)} of {self.poses} poses, coverage spread {self.spread:.2f} (needs {MIN_SPREAD:g})"

    def windows(self) -> tuple[Window, ...]:
        """The accepted poses as still windows (samples of the whole recording), in time order."""
        return tuple(Window(p.start, p.stop, "static", label=f"pose {i + 1}") for i, p in enumerate(self.accepted))

    # -- what it says ----------------------------------------------------------------------------------------

    def _prompt(self, again: bool = False) -> GuideEvent:
        k = len(self.accepted) + 1
        of = f"/{self.poses}" if k <= self.poses else f" (coverage spread {self.spread:.2f}, needs {MIN_SPREAD:g})"
        return GuideEvent("prompt", k - 1, f"pose {k}{of}: {'again: ' if again else ''}turn the board to "
                                           f"{describe(self.target)}, then hold it still for {self.hold:g} s")

    def start(self) -> list[GuideEvent]:
        return [GuideEvent("prompt", 0, f"{self.poses} poses or more, each held still for {self.hold:g} s; "
                                        "'z up' means the board's +z axis points straight up"), self._prompt()]

    def redo(self, n_samples: int) -> list[GuideEvent]:
        """Take back the last accepted pose; a new one must begin after sample `n_samples`."""
        if not self.accepted:
            return [GuideEvent("redo", 0, "nothing to redo yet")]
        pose = self.accepted.pop()
        self.target, self._after = pose.target, n_samples
        k = len(self.accepted) + 1
        return [GuideEvent("redo", k - 1, f"redo pose {k}: move the board, then hold it still again"), self._prompt()]

    # -- judging ---------------------------------------------------------------------------------------------

    def update(self, rec: Recording, offset: int = 0) -> list[GuideEvent]:
        """Judge the poses on the samples so far: `rec` holds samples ``offset ..`` of the capture (absolute
        indices), with the accelerometer, from :attr:`keep_from` on or earlier."""
        if rec.accel is None:
            raise InputError("the multi-position guide needs the accelerometer: send 6-axis frames (the example "
                             "firmware with an accelerometer sensitivity) or text lines with ax, ay, az columns",
                             param="guide")
        return self._step_through(rec, offset, self.every)

    def _judge(self, rec: Recording, offset: int, n: int) -> list[GuideEvent]:
        fs = rec.sample_rate
        # the detector measures its thresholds on the data it is given: the last few poses give it enough quiet
        anchor = self.accepted[-CONTEXT_POSES].start if len(self.accepted) >= CONTEXT_POSES else 0
        self._lo = lo = max(anchor, offset, n - int(MAX_CONTEXT_S * fs))
        window = int(round(DETECTOR_WINDOW * fs)) | 1
        if n - lo < 4 * window:
            return []  # the detector needs a few windows of data
        part = slice(lo - offset, n - offset)
        t = rec.t[part]
        det = detect_statics(t, rec.gyro[part], rec.accel[part], min_duration=MIN_STILL_S)
        bump = int(BUMP_S * fs)
        # near the end of the data the detector's moving window is cut short and a move just begun looks still:
        # a pose's samples stop a window before the end (its duration is judged on everything)
        edge = len(t) - det.window
        for mean, pieces in _merged(det.statics, bump):
            u = mean / np.linalg.norm(mean)
            last = self.accepted[-1] if self.accepted else None
            if last is not None and pieces[0][0] + lo < last.stop and pieces[-1][1] + lo > last.start:
                for a, b in pieces:  # the last pose, still held: its window grows while the stillness lasts
                    if a + lo < last.stop and b + lo > last.start:
                        last.stop = max(last.stop, min(b, edge) + lo)
                continue
            pieces = [(a, b) for a, b in pieces if a + lo >= self._after]  # stillness before a verdict is done
            if not pieces:
                continue
            start, stop = pieces[0][0] + lo, pieces[-1][1] + lo
            if last is not None and start - last.stop < bump and _angles(u, last.direction)[0] <= DISTINCT_DEG:
                continue  # a nudge while holding the last pose
            duration = float(t[pieces[-1][1] - 1] - t[pieces[0][0]])
            if duration >= self.hold - DETECTOR_WINDOW:
                self._after = n
                a, b = max(pieces, key=lambda p: min(p[1], edge) - p[0])
                return self._decide(a + lo, max(min(b, edge), a + 1) + lo, u, duration)
            # something else followed it (and the detector had enough data to judge): the stillness was too short
            if len(t) - (stop - lo) >= bump and start >= self._told and len(t) >= SHORT_CONTEXT_S * fs:
                self._told = stop  # said once; it may still grow into a pose if the detector cut it short
                k = len(self.accepted) + 1
                return [GuideEvent("refused", k - 1, f"pose {k}: refused: still for only {duration:.1f} s; hold "
                                                     f"it {self.hold:g} s"), self._prompt(again=True)]
        return []

    def _decide(self, start: int, stop: int, u: np.ndarray, duration: float) -> list[GuideEvent]:
        k = len(self.accepted) + 1
        if self.accepted:
            ang = _angles(u, [p.direction for p in self.accepted])
            i = int(np.argmin(ang))
            if ang[i] <= DISTINCT_DEG:
                why = (f"the same pose as pose {i + 1} ({ang[i]:.0f} deg apart; a new pose must be more than "
                       f"{DISTINCT_DEG:g} deg from every earlier one)")
                return [GuideEvent("refused", k - 1, f"pose {k}: refused: {why}"), self._prompt(again=True)]
        off = float(_angles(u, self.target)[0])
        self.accepted.append(_Pose(start, stop, u, self.target))
        aim = "" if off <= COVERED_DEG else f", {off:.0f} deg from the pose asked for (taken all the same)"
        events = [GuideEvent("accepted", k - 1, f"pose {k}: accepted: {describe(u)}, still {duration:.1f} s{aim}; "
                                                f"{self.status()}")]
        if self.complete:
            events.append(GuideEvent("complete", k - 1, "enough poses, covering the sphere: calibrating"))
        else:
            self.target = next_target(self._plan, [p.direction for p in self.accepted])
            events.append(self._prompt())
        return events

