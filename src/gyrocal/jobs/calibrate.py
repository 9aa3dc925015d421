"""The job ``calibrate``: scale and bias from a recording of turns (the servo method of Wang et al.)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any, Mapping

from .result import Job, JobResult, judge, paths, read_input

__all__ = ["CalibrateJob"]


@dataclass(frozen=True)
class CalibrateJob(Job):
    """Inputs of :func:`gyrocal.pipeline.calibrate`: a recording (a path, read with `reading`, the options of
    :func:`gyrocal.io.read_recording`, or a ``Recording``), the reference (`speed` rad/s or `angle` rad
    per turn, with its 1-sigma `reference_sd` in the same unit), the method, the windows (a windows file or
    ``Window`` list; None: detected), the per-sample noise [rad/s] and the output rate unit."""

    name = "calibrate"
    kind = "calibration"

    recording: Any
    reading: Mapping = field(default_factory=dict)
    speed: float | None = None
    angle: float | None = None
    reference_sd: float | None = None
    method: str = "first-moment"
    windows: Any = None
    noise_std: Any = None
    output_units: str | None = None
    accept_implausible: bool = False
    notes: tuple[str, ...] = ()  # the reading's notes, when the recording was read before
    sources: tuple = ()  # files the recording came from, when it was read before

    def run(self) -> JobResult:
        from ..pipeline import calibrate

        read_notes = list(self.notes)
        rec = read_input(self.recording, self.reading, read_notes)
        win = self._windows(rec)
        speed, angle = self.speed, self.angle
        if speed is None and angle is None:
            import math

            angle = 2 * math.pi  # one full turn per window, as the command's default
        unit = self.output_units or ("deg/s" if rec.source_units == "counts" else rec.source_units)  # as the CLI
        run = calibrate(rec, speed=speed, angle=angle, method=self.method, windows=win, noise_std=self.noise_std,
                        output_units=unit, reference_sd=self.reference_sd)
        cal = _with_notes(run.calibration, read_notes)
        doc, accepted = judge(cal.to_document(), run.implausible, self.accept_implausible)
        inputs = paths(self.recording, *self.sources, self.windows)
        title = f"{inputs[0].name + ': ' if inputs else ''}{'speed' if speed is not None else 'angle'} reference"

        def figure():
            from ..plotting.calibration import calibration_figure
            from ..segmentation.windows import Window

            return calibration_figure(rec, [Window.from_dict(d) for d in cal.windows], cal, speed=speed, title=title)

        return JobResult(kind=self.kind, job=self.name, document=doc,
                         warnings=tuple(run.warnings) + ((accepted,) if accepted else ()), notes=tuple(run.notes),
                         quality=run.quality, figures={"calibration": figure},
                         inputs=inputs, value=run,
                         implausible=accepted)

    def _windows(self, rec):
        import os

        if not isinstance(self.windows, (str, os.PathLike)):
            return self.windows
        from ..io import read_windows

        return read_windows(self.windows, sample_rate=rec.sample_rate, t0=float(rec.t[0]), n_samples=len(rec),
                            t=rec.t if rec.has_time else None)


def _with_notes(cal, notes: list):
    """The calibration with the reading's notes (rows dropped, ms stamps recognised) first in its fit's notes."""
    if not notes or cal.fit is None:
        return cal
    return dataclasses.replace(cal, fit={**cal.fit, "notes": list(notes) + list(cal.fit.get("notes", []))})
