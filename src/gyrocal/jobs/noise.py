"""The job ``noise``: Allan deviation of a log at rest, with the figures' intervals."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

from .result import Job, JobResult, paths, read_input

__all__ = ["NoiseJob"]


@dataclass(frozen=True)
class NoiseJob(Job):
    """Inputs of :func:`gyrocal.noise.characterise_recording`: a log at rest in physical units (a path, read
    with `reading`, or a ``Recording``) and what to do when it moves (``restrict`` or ``refuse``)."""

    name = "noise"
    kind = "noise"

    recording: Any
    reading: Mapping = field(default_factory=dict)
    motion: str = "restrict"
    source: Mapping | None = None  # the file section; default: the recording's file name
    sources: tuple = ()

    def run(self) -> JobResult:
        from pathlib import Path

        from ..errors import InputError
        from ..noise import characterise_recording
        from ..results.files import to_document

        rec = read_input(self.recording, self.reading, [])
        if rec.units == "counts" or rec.accel_units == "counts":
            raise InputError("noise figures are physical quantities, so raw counts need their sensitivity")
        files = paths(self.recording, *self.sources)
        source = dict(self.source) if self.source is not None else {"file": Path(files[0]).name} if files else None
        report = characterise_recording(rec, motion=self.motion, source=source)

        def figure():
            from ..plotting.noise import allan_figure

            return allan_figure(report, title=(source or {}).get("file", ""))

        return JobResult(kind=self.kind, job=self.name, document=to_document(report), figures={"allan": figure},
                         inputs=files, value=report)
