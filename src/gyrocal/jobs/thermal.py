"""The job ``thermal``: a temperature table from a turntable session (the full-temperature-range method)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from .result import Job, JobResult, judge

__all__ = ["ThermalJob"]


@dataclass(frozen=True)
class ThermalJob(Job):
    """Inputs of :func:`gyrocal.thermal.calibrate_thermal`: a session (one file or a folder, read with
    `reading`, the options of :func:`gyrocal.io.read_session`; or recordings already read with their
    `names`), the units, the step settling [s], the full scale [rad/s], temperatures [degC] and orders."""

    name = "thermal"
    kind = "thermal"

    session: Any
    units: str  # of the gyro and table_rate columns as read (counts, or a rate unit)
    input_units: str | None = None  # of the table: the rate unit counts are scaled to; default: `units`
    output_units: str | None = None
    reading: Mapping = field(default_factory=dict)
    names: tuple[str, ...] | None = None
    settle: float = 2.0
    full_scale: float | None = None
    temp_tolerance: float = 2.0
    reference_temp: float = 25.0
    max_order: int = 3
    temp_tau: float = 20.0
    accept_implausible: bool = False

    def run(self) -> JobResult:
        import os

        from ..thermal import calibrate_thermal

        recs, names = self.session, self.names
        if isinstance(recs, (str, os.PathLike)):
            from ..io import read_session

            reading = {"saturation": "ignore", **self.reading}
            recs, names = read_session(Path(recs), units=self.units, **reading)
        cal, fit = calibrate_thermal(recs, input_units=self.input_units or self.units,
                                     output_units=self.output_units or self.input_units or self.units,
                                     settle=self.settle, full_scale=self.full_scale,
                                     temp_tolerance=self.temp_tolerance, reference_temp=self.reference_temp,
                                     max_order=self.max_order, temp_tau=self.temp_tau, names=names)
        doc, accepted = judge(cal.to_document(), implausible(cal), self.accept_implausible)
        inputs: tuple[Path, ...] = ()
        if isinstance(self.session, (str, os.PathLike)):
            folder = Path(self.session)
            inputs = tuple(folder / n for n in names) if folder.is_dir() else (folder,)  # a folder: each file read
        return JobResult(kind=self.kind, job=self.name, document=doc, warnings=(accepted,) if accepted else (),
                         inputs=inputs, value=(cal, fit), implausible=accepted)


def implausible(cal) -> str | None:
    """The plausibility rule on the table's scale factors (1 / Kxx.. at the temperature where they are worst)."""
    import numpy as np

    from ..checks.plausibility import far_scale

    k = 1.0 / np.abs(cal.kg[:, :3])  # K maps the table's rate to the reading; the scale factor is its inverse
    worst = int(np.argmax(np.max(np.abs(np.log(k)), axis=1)))
    text = far_scale(k[worst], cal.input_units, "the table_rate column is not the table's rate about {}")
    return None if text is None else f"at {cal.temps[worst]:.1f} degC, {text}"
