"""The job ``imu``: gyro and accelerometer together from still poses and hand turns."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

from ..constants import STANDARD_GRAVITY
from .result import Job, JobResult, judge, paths, read_input

__all__ = ["ImuJob"]


@dataclass(frozen=True)
class ImuJob(Job):
    """Inputs of :func:`gyrocal.imu.run.calibrate_recording`: a recording with accelerometer columns (a path,
    read with `reading`, or a ``Recording``), the still poses (a windows file or ``Window`` list; None:
    detected), the models, gravity [m/s^2] and the output units."""

    name = "imu"
    kind = "imu"

    recording: Any
    reading: Mapping = field(default_factory=dict)
    windows: Any = None
    gravity: float = STANDARD_GRAVITY
    accel_model: str = "auto"
    gyro_model: str = "auto"
    g_sensitivity: bool = False
    min_static: float = 1.0
    threshold: float | None = None
    output_units: str | None = None
    accel_output_units: str = "m/s^2"
    accept_implausible: bool = False
    sensor_lag: float | None = None  # the temperature sensor's lag behind the die [s]
    sources: tuple = ()  # files the recording came from (the recording, the accelerometer's log), when read before

    def run(self) -> JobResult:
        import os

        from ..imu.run import calibrate_recording, implausible

        rec = read_input(self.recording, {"need_accel": True, **self.reading}, [])
        win = self.windows
        if isinstance(win, (str, os.PathLike)):
            from ..io import read_windows

            win = read_windows(win, sample_rate=rec.sample_rate, t0=float(rec.t[0]), n_samples=len(rec),
                               t=rec.t if rec.has_time else None)
        run = calibrate_recording(rec, windows=win, gravity=self.gravity, accel_model=self.accel_model,
                                  gyro_model=self.gyro_model, g_sensitivity=self.g_sensitivity,
                                  min_static=self.min_static, output_units=self.output_units,
                                  accel_output_units=self.accel_output_units, threshold=self.threshold,
                                  sensor_lag=self.sensor_lag)
        doc, accepted = judge(run.calibration.to_document(), implausible(run.calibration), self.accept_implausible)

        inputs = paths(self.recording, *self.sources[:1], self.windows, *self.sources[1:])

        def figure():
            from ..plotting.imu import poses_figure

            return poses_figure(run.result, title=f"{inputs[0].name + ': ' if inputs else ''}whole-IMU calibration")

        return JobResult(kind=self.kind, job=self.name, document=doc,
                         warnings=tuple(run.warnings) + ((accepted,) if accepted else ()),
                         figures={"poses": figure}, inputs=inputs,
                         value=run, implausible=accepted)
