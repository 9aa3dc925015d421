"""A guided calibration session: tell the person what to do next and check each step as it is done.

Each step is recognised with the same segmentation as ``gyrocal calibrate``
(:func:`gyrocal.segmentation.segment`) run on the samples since the step was asked for, once
the motion has stopped: a turn step is accepted when a whole turn about the asked axis and
sense is found, and refused with the segmentation's own reason otherwise (wrong angle, off
axis, another axis); a still step is accepted once the gyro has been still long enough. A
refused step is asked again; :meth:`Guide.redo` reopens the last accepted one. When every step
is accepted, :meth:`Guide.windows` gives the windows for :func:`gyrocal.pipeline.calibrate`.

Sessions:

* ``servo``: the six turns of the servo method of Wang et al. (Fig. 1): +x, -x, +y, -y, +z, -z,
  each followed by a wait (the paper waits 3 s);
* ``hand``: one turn about each axis with still poses between them (biases from the statics,
  as in the Ferraris-style hand session the first-moment estimator handles).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Literal

from ..errors import InputError
from ..recording import Recording
from ..segmentation import segment
from ..segmentation.windows import Window

__all__ = ["GUIDES", "Guide", "GuideEvent", "Step", "SteppedJudge"]

#: Scale factors a guided turn may imply: its measured size within 25 % of the asked one.
_GUIDE_K_RANGE = (0.8, 1 / 0.75)
#: A step still open after this much data [s] looks only at the last _KEEP_S of it (memory and time stay
#: bounded while nobody moves; a turn must take less than that).
_MAX_STEP_S, _KEEP_S = 120.0, 60.0


@dataclass(frozen=True)
class Step:
    """One thing to do: a turn (``label`` such as ``"+x"``) or holding still for ``seconds``."""

    kind: Literal["turn", "still"]
    label: str = ""
    seconds: float = 0.0

    def prompt(self) -> str:
        if self.kind == "still":
            return f"hold the gyro still for {self.seconds:g} s"
        sense = "positive" if self.label[0] == "+" else "negative"
        return (f"turn {self.label} one full turn now (360 deg about the {sense} {self.label[1]} axis), "
                "then hold still")


def _session(turns: tuple[str, ...], still: float, between: bool) -> tuple[Step, ...]:
    steps = [Step("still", seconds=still)]
    for t in turns:
        steps.append(Step("turn", t))
        if between:
            steps.append(Step("still", seconds=still))
    return tuple(steps)


#: The guided sessions by name.
GUIDES: dict[str, tuple[Step, ...]] = {
    "servo": _session(("+x", "-x", "+y", "-y", "+z", "-z"), 2.0, between=False),
    "hand": _session(("+x", "+y", "+z"), 2.0, between=True),
}


@dataclass(frozen=True)
class GuideEvent:
    """What the guide has to say: ``prompt``, ``accepted``, ``refused``, ``redo`` or ``complete``."""

    kind: Literal["prompt", "accepted", "refused", "redo", "complete"]
    step: int
    text: str


class SteppedJudge:
    """Judging at fixed points of the data, so the outcome does not depend on how samples arrived in chunks.

    Subclasses keep ``_checked`` (samples judged so far), ``complete``, and ``_judge(rec, offset, n)``.
    """

    _checked: int

    def _step_through(self, rec: Recording, offset: int, every: float) -> list[GuideEvent]:
        """Judge at every `every` seconds of samples up to the end of `rec` (samples ``offset ..``)."""
        stride = max(1, round(every * rec.sample_rate))
        events: list[GuideEvent] = []
        while not self.complete and self._checked + stride <= offset + len(rec):
            self._checked += stride
            events += self._judge(rec, offset, self._checked)
        return events


class Guide(SteppedJudge):
    """Walk a person through a session (see the module notes).

    Parameters
    ----------
    name : {"servo", "hand"}
        Which session.
    speed : float, optional
        Known turn speed [rad/s]: turns are checked as constant-speed plateaus. Default: whole
        turns of a known angle.
    angle : float
        Angle of every turn [rad] (one revolution).
    settle : float
        Stillness after a motion before it is judged [s].
    """

    def __init__(self, name: str, *, speed: float | None = None, angle: float = 2 * math.pi, settle: float = 1.0):
        if name not in GUIDES:
            raise InputError(f"{{param}} must be one of {', '.join(GUIDES)}, got {name!r}", param="guide", value=name)
        self.name, self.steps = name, GUIDES[name]
        self.speed, self.angle, self.settle = speed, angle, settle
        self.index = 0
        self.since = 0
        self._checked = 0
        self._accepted: list[Window] = []

    @property
    def complete(self) -> bool:
        return self.index >= len(self.steps)

    def windows(self) -> tuple[Window, ...]:
        """The accepted windows (samples of the whole recording), for the final calibration."""
        return tuple(self._accepted)

    @property
    def keep_from(self) -> int:
        """First sample (absolute index) the guide may still look at."""
        return self.since

    def status(self) -> str:
        return f"step {self.index + 1} of {len(self.steps)}"

    def start(self) -> list[GuideEvent]:
        return [self._prompt()]

    def _prompt(self, again: bool = False) -> GuideEvent:
        n = len(self.steps)
        prefix = "again: " if again else ""
        return GuideEvent("prompt", self.index, f"step {self.index + 1}/{n}: {prefix}{self.steps[self.index].prompt()}")

    def redo(self, n_samples: int) -> list[GuideEvent]:
        """Reopen the last accepted step (the samples so far are not used for it)."""
        if not self._accepted:
            return [GuideEvent("redo", self.index, "nothing to redo yet")]
        self._accepted.pop()
        self.index -= 1
        self.since = self._checked = n_samples
        return [GuideEvent("redo", self.index, f"redo step {self.index + 1}"), self._prompt()]

    def update(self, rec: Recording, every: float = 0.25, offset: int = 0) -> list[GuideEvent]:
        """Judge the current step on the recording so far (rad/s, or counts with a sensitivity): `rec` holds
        samples ``offset ..`` of the capture (absolute indices), from :attr:`keep_from` on or earlier.

        Steps are judged every `every` seconds of samples (:class:`SteppedJudge`).
        """
        return self._step_through(rec, offset, every)

    def _judge(self, rec: Recording, offset: int, n: int) -> list[GuideEvent]:
        fs = rec.sample_rate
        if n - self.since > _MAX_STEP_S * fs:
            self.since = n - int(_KEEP_S * fs)
        # segmentation needs about a second of data to find the standstill level
        if n - self.since < max(1.0, self.settle) * fs:
            return []
        part = slice(self.since - offset, n - offset)
        sub = Recording(t=rec.t[part], gyro=rec.gyro[part], units=rec.units,
                        source_units=rec.source_units, sample_rate=fs, sensitivity=rec.sensitivity)
        step = self.steps[self.index]
        ref = {"reference": "speed", "speed": self.speed} if self.speed else {"reference": "angle", "angle": self.angle}
        # a guided turn must be the asked one within 25 %: a tighter scale range than calibration's 0.45-2.2
        seg = segment(sub, require=False, k_range=_GUIDE_K_RANGE, **ref)
        motions = sorted([*seg.rotations, *(w for w, _ in seg.ignored if w.kind == "rotation")], key=lambda w: w.stop)
        return self._judge_still(seg, n, fs, motions) if step.kind == "still" else self._judge_turn(seg, n, fs, motions)

    def _shift(self, w: Window) -> Window:
        return dataclasses.replace(w, start=w.start + self.since, stop=w.stop + self.since)

    def _accept(self, w: Window, text: str, n: int) -> list[GuideEvent]:
        self._accepted.append(self._shift(w))
        events = [GuideEvent("accepted", self.index, text)]
        self.index += 1
        # after a turn, the next step starts where it was judged: the motion is over (with a speed reference
        # the window is only the plateau, and the ramp down must not count as a new motion)
        self.since = n if w.kind == "rotation" else self.since
        if self.complete:
            events.append(GuideEvent("complete", self.index - 1, "every step accepted: calibrating"))
        else:
            events.append(self._prompt())
        return events

    def _judge_still(self, seg, n, fs, motions) -> list[GuideEvent]:
        need = self.steps[self.index].seconds * fs
        last_motion = motions[-1].stop if motions else 0
        for w in seg.statics:
            if w.start >= last_motion and len(w) >= need:
                return self._accept(Window(w.start, int(w.start + need), "static", label="static"),
                                    f"still for {need / fs:g} s: accepted", n)
        return []

    def _judge_turn(self, seg, n, fs, motions) -> list[GuideEvent]:
        if not motions or n - self.since - motions[-1].stop < self.settle * fs:
            return []  # nothing yet, or still moving
        want = self.steps[self.index].label
        for w in seg.rotations:
            if w.label == want:
                return self._accept(w, f"{want}: accepted ({math.degrees(w.angle):.0f} deg in {len(w) / fs:.1f} s)", n)
        why = [r for w, r in seg.ignored if w.kind == "rotation"]
        other = [w.label for w in seg.rotations]
        if other:
            reason = f"turned {', '.join(other)} where {want} was asked"
        else:
            reason = why[0] if why else "no whole turn found"
        self.since = n
        return [GuideEvent("refused", self.index, f"{want}: refused: {reason}"), self._prompt(again=True)]
