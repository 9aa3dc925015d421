"""The reading flags, defined once, and the one function that turns them into a Recording.

A command takes the flags it needs as parameters typed with the attributes of
:data:`READING` (``units: READING.Units = None``); a command that reads two recordings
makes a second set with a prefix (``ReadingFlags("ref-")`` gives ``--ref-units`` ...).
:func:`read_from_flags` passes them to :func:`gyrocal.io.read_recording`.
"""

from __future__ import annotations

import contextlib
import re
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..choices import SaturationPolicy
from ..constants import STANDARD_GRAVITY
from ..errors import GyrocalError, InputError

__all__ = ["READING", "ReadingFlags", "prefixed_params", "read_from_flags", "required_units"]



class ReadingFlags:
    """The ``Annotated`` types of the reading flags, for one flag prefix (``""`` or ``"ref-"``)."""

    def __init__(self, prefix: str = ""):
        def opt(name: str, help: str, **kw):
            # the reading flags a help text names carry the same prefix
            return typer.Option(f"--{prefix}{name}", help=re.sub(r"--(?=[a-z])", f"--{prefix}", help), **kw)

        def sensitivity(without: str, per_rad: str = " (per rad/s with --output-units rad/s)"):
            return Annotated[Optional[float], opt(
                "sensitivity", f"For --units counts: LSB per deg/s{per_rad} ({without}).")]

        units = "<rad/s|deg/s|counts>"
        self.Units = Annotated[Optional[str], opt(
            "units", "Unit of the gyro columns as written in the file (required).", metavar=units)]
        #: apply: the calibration knows its unit
        self.UnitsOfCalibration = Annotated[Optional[str], opt(
            "units", "Unit of the gyro columns as written in the file (default: the calibration's input unit; "
            "deg/s and rad/s are converted).", metavar=units)]
        self.Columns = Annotated[Optional[str], opt(
            "columns", "Map gyrocal names to the file's columns, by name or by number from 1, e.g. "
            "gx=gyroX,gy=gyroY,gz=gyroZ[,t=time,temp=T,ax=accX] (default: found by name or a usual alias).")]
        self.SkipRows = Annotated[Optional[int], opt(
            "skip-rows", "Text tables: lines to skip above the header (default: metadata lines such as 'Fs,100' "
            "are found and skipped).")]
        self.SampleRate = Annotated[Optional[float], opt(
            "sample-rate", "Nominal sample rate [Hz]; needed when the file has no time column (default: from the "
            "time column, which wins when both are there).")]
        #: a calibration: without it the scale factors absorb the sensitivity
        self.Sensitivity = sensitivity("default: none; the scale factors absorb it")
        #: commands whose results are physical quantities
        self.SensitivityNeeded = sensitivity("required with --units counts")
        #: a fit that works in counts as well
        self.SensitivityKept = sensitivity("default: none; the rates stay in counts")
        #: a test log read in its calibration's output unit
        self.SensitivityOfCalibration = sensitivity("required with --units counts",
                                                    " (per rad/s for a calibration in rad/s)")
        #: a log read without --output-units (a reference)
        self.SensitivityDegS = sensitivity("default: none; the rates stay in counts", "")
        self.OutputUnits = Annotated[Optional[str], opt(
            "output-units", "Rate unit of the results, rad/s or deg/s (default: the data's; deg/s for counts).",
            metavar="<rad/s|deg/s>")]
        self.Topic = Annotated[Optional[str], opt(
            "topic", "sensor_msgs/Imu topic in a ROS 1/ROS 2/MCAP bag (default: the only one).")]
        self.TimeUnits = Annotated[Optional[str], opt(
            "time-units", "Unit of a time column whose name carries none (default: s; with --sample-rate, steps of "
            "~1000 or ~1e6 periods are read as ms or us, with a note).", metavar="<s|ms|us|ns>")]
        self.Nan = Annotated[str, opt(
            "nan", "Rows with NaN, inf or empty cells in the columns used: 'error' refuses, 'drop' removes them "
            "(counted in a note; they leave a gap in the time stamps, or in the row numbers used as time with "
            "--sample-rate).", metavar="<error|drop>")]
        self.Saturation = Annotated[SaturationPolicy, opt(
            "saturation", "Samples stuck at full scale: refuse (error), drop them, or ignore.")]
        self.NoUnitCheck = Annotated[bool, opt(
            "no-unit-check", "Accept rates that look like another unit (e.g. 4000 'rad/s').")]
        self.AccelUnits = Annotated[Optional[str], opt(
            "accel-units", "Unit of the accelerometer columns (ax, ay, az or acc_x, ...): m/s^2, g or counts "
            "(default: none; those columns pass through as they are).", metavar="<m/s^2|g|counts>")]
        self.AccelSensitivity = Annotated[Optional[float], opt(
            "accel-sensitivity", "For --accel-units counts: LSB per g (default: none; counts stay counts).")]
        self.Gravity = Annotated[float, opt("gravity", "One g [m/s^2], for --accel-units g or counts.")]
        self.Imu = Annotated[Optional[int], opt(
            "imu", "PX4 ULog / ArduPilot DataFlash log: which IMU instance, from 0 (default: the only one; required "
                   "when the log holds several).")]


#: The reading flags without a prefix.
READING = ReadingFlags()


def required_units(units: str | None) -> str:
    """The --units value, which the command cannot do without."""
    from ..units import parse_input_unit

    if units is None:
        raise InputError("{param} is required: rad/s, deg/s or counts (the unit of the gyro columns)", param="units")
    return parse_input_unit(units, "units")


def read_from_flags(
    path: Path,
    *,
    units: str,
    columns: str | None = None,
    skip_rows: int | None = None,
    sample_rate: float | None = None,
    sensitivity: float | None = None,
    output_units: str | None = None,
    topic: str | None = None,
    saturation: SaturationPolicy = "error",
    no_unit_check: bool = False,
    accel_units: str | None = None,
    accel_sensitivity: float | None = None,
    gravity: float = STANDARD_GRAVITY,
    need_accel: bool = False,
    imu: int | None = None,
    time_units: str | None = None,
    nan: str = "error",
    notes: list | None = None,
):
    """A :class:`~gyrocal.recording.Recording` from the reading flags (see :func:`gyrocal.io.read_recording`)."""
    from ..io import read_recording
    from .app import console

    notes = [] if notes is None else notes
    rec = read_recording(path, units=units, columns=columns, skip_rows=skip_rows, sample_rate=sample_rate,
                          sensitivity=sensitivity,
                          output_units=output_units, topic=topic, check_units=not no_unit_check,
                          saturation=saturation, accel_units=accel_units, accel_sensitivity=accel_sensitivity,
                          gravity=gravity, need_accel=need_accel, imu=imu, time_units=time_units,
                         nan=nan, notes=notes)
    for note in notes:
        console.print(f"note: {note}", highlight=False, soft_wrap=True, markup=False)
    return rec


@contextlib.contextmanager
def prefixed_params(prefix: str):
    """Errors raised inside the block name the prefixed flags: reading a reference log with
    ``prefixed_params("ref_")``, a bad ``units`` shows as ``--ref-units``, and a hint's
    ``{param:check_units}`` as ``--ref-no-unit-check`` (where those flags exist)."""
    from ._flags import FLAGS

    def prefixed(name: str) -> str:
        return f"{prefix}{name}" if f"{prefix}{name}" in FLAGS else name

    try:
        yield
    except GyrocalError as exc:
        if exc.param is not None:
            exc.param = prefixed(exc.param)
        other = re.compile(r"\{param:([A-Za-z_]\w*)\}")
        exc.message = other.sub(lambda m: f"{{param:{prefixed(m.group(1))}}}", exc.message)
        if exc.hint:
            exc.hint = other.sub(lambda m: f"{{param:{prefixed(m.group(1))}}}", exc.hint)
        raise
