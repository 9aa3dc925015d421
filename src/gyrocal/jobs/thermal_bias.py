"""The job ``thermal-bias``: gyro bias (and accelerometer offset change) against temperature, for PX4 and ArduPilot."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping

from .result import Job, JobResult, judge, paths, read_input

__all__ = ["ThermalBiasJob"]


@dataclass(frozen=True)
class ThermalBiasJob(Job):
    """Inputs of :func:`gyrocal.flight.fit_thermal_bias`: a still log of a warming board with a temperature
    column (a path, read with `reading`, or a ``Recording``), the highest order, the smallest span [degC],
    and the log's `source` section (a flight log's device ids); `flight_log`: the unit is the log format's,
    so the plausibility rule on a declared unit does not apply."""

    name = "thermal-bias"
    kind = "thermal-bias"

    recording: Any
    reading: Mapping = field(default_factory=dict)
    max_order: int = 3
    min_span: float = 10.0
    source: Mapping | None = None
    flight_log: bool = False
    accept_implausible: bool = False
    sources: tuple = ()

    def run(self) -> JobResult:
        from pathlib import Path

        from ..errors import InputError
        from ..flight import fit_thermal_bias
        from ..results.files import to_document

        rec = read_input(self.recording, self.reading, [])
        files = paths(self.recording, *self.sources)
        name = Path(files[0]).name if files else "the recording"
        if rec.temp is None:
            raise InputError(f"{name} has no temperature column; a thermal-bias fit needs one", param="columns",
                             hint="map it with {param} temp=NAME")
        fs = (len(rec) - 1) / float(rec.t[-1] - rec.t[0]) if rec.has_time else rec.sample_rate
        source = dict(self.source) if self.source is not None else {"file": name} if files else {}
        source["units"] = rec.source_units
        if rec.accel is not None:
            source["accel_units"] = rec.accel_source_units
        tb = fit_thermal_bias(rec.gyro, rec.temp, fs, max_order=self.max_order, min_span=self.min_span,
                              source=source, accel=rec.accel)
        diagnosis = None if self.flight_log else implausible(tb, rec, fs)
        doc, accepted = judge(to_document(tb), diagnosis, self.accept_implausible)
        return JobResult(kind=self.kind, job=self.name, document=doc,
                         warnings=tuple(tb.warnings) + ((accepted,) if accepted else ()), inputs=files,
                         value=(tb, rec, fs), implausible=accepted, device_id=source.get("device_id"))


def implausible(tb, rec, fs: float) -> str | None:
    """The plausibility rule on a still log whose unit was declared (deg/s or rad/s)."""
    import numpy as np

    from ..checks.plausibility import still_units

    if rec.source_units not in ("deg/s", "rad/s"):
        return None
    deg = 180 / math.pi
    return still_units(tb.bias_at([tb.tref])[0] * deg, np.asarray(tb.noise_std) * deg / math.sqrt(fs), rec.source_units)
