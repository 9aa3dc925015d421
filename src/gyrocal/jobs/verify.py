"""The job ``verify``: a calibration against a reference gyro that recorded the same motion (the validation of
the servo method of Wang et al., Tables IV-V)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

from .result import Job, JobResult, paths, read_input

__all__ = ["VerifyJob"]


@dataclass(frozen=True)
class VerifyJob(Job):
    """Inputs of :func:`gyrocal.verify.verify_calibration`: a calibration (a file or a loaded one), the test log
    and the reference log (paths read with `reading` / `ref_reading`, or ``Recording`` objects), the bootstrap
    (`seed`, `replicates`), whether to fit the clock drift, the figures' `stretch` (T0, T1) [s on the test
    clock], and the thermal files' `apply_options` (model, out_of_range)."""

    name = "verify"
    kind = "verify"

    calibration: Any
    test: Any
    reference: Any
    reading: Mapping = field(default_factory=dict)
    ref_reading: Mapping = field(default_factory=dict)
    seed: int = 0
    replicates: int = 1000
    fit_drift: bool = True
    stretch: tuple[float, float] | None = None
    apply_options: Mapping = field(default_factory=dict)
    names: Mapping | None = None  # the report's inputs section; default: the files' names

    def run(self) -> JobResult:
        import os

        from ..results.files import to_document
        from ..verify import verify_calibration

        cal = self.calibration
        if isinstance(cal, (str, os.PathLike)):
            from ..results.files import load_correction

            cal = load_correction(cal)
        rec = read_input(self.test, self.reading, [])
        ref = read_input(self.reference, self.ref_reading, [])
        names = dict(self.names) if self.names is not None else {
            key: p.name for key, p in zip(("calibration", "test", "reference"),
                                          (paths(self.calibration) + paths(self.test) + paths(self.reference)))}
        report, series = verify_calibration(cal, rec, ref, seed=self.seed, fit_drift=self.fit_drift,
                                            replicates=self.replicates, inputs=names, **dict(self.apply_options))
        return JobResult(kind=self.kind, job=self.name, document=to_document(report), warnings=tuple(report.warnings),
                         figures=_figures(series, self.stretch),
                         inputs=paths(self.calibration, self.test, self.reference), value=(report, series))


def _figures(series, stretch) -> dict:
    """before.png (when the raw readings are known), after.png and errors.png, drawn when called."""
    def overlay(calibrated: bool):
        def draw():
            from ..plotting.verify import overlay_figure

            return overlay_figure(series, calibrated=calibrated, stretch=stretch)
        return draw

    def errors():
        from ..plotting.verify import error_figure

        return error_figure(series, stretch=stretch)

    out = {"after": overlay(True), "errors": errors}
    return ({"before": overlay(False)} | out) if series.raw is not None else out
