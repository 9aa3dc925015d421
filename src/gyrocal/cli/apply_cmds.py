"""Command ``apply``: correct a recording with any calibration file."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..choices import OutOfRange, TableModel
from ..constants import STANDARD_GRAVITY
from ..errors import InputError
from ._options import given, iso_time
from ._outputs import check_output, refuse_swapped, starts_with
from ._reading import READING, read_from_flags
from .app import app, console, warn

__all__ = ["apply"]

_APPLIED = "corrected by gyrocal"  # first line of an apply output: a later apply may replace it
#: Flags that become options of the calibration's ``apply`` when typed (each kind refuses those it lacks).
_APPLY_OPTIONS = ("model", "out_of_range")


@app.command()
def apply(
    ctx: typer.Context,
    calibration: Annotated[Path, typer.Argument(help="A gyrocal calibration or thermal calibration file (with "
                                                "--store: the recording).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Corrected CSV.")],
    recording: Annotated[Optional[Path], typer.Argument(help="Recording to correct.")] = None,
    units: READING.UnitsOfCalibration = None,
    columns: READING.Columns = None,
    skip_rows: READING.SkipRows = None,
    sample_rate: READING.SampleRate = None,
    topic: READING.Topic = None,
    saturation: READING.Saturation = "error",
    no_unit_check: READING.NoUnitCheck = False,
    imu: READING.Imu = None,
    accel_units: READING.AccelUnits = None,
    accel_sensitivity: READING.AccelSensitivity = None,
    gravity: READING.Gravity = STANDARD_GRAVITY,
    model: Annotated[TableModel, typer.Option("--model", help="Thermal files: evaluation in temperature.")]
    = "lagrange",
    out_of_range: Annotated[OutOfRange, typer.Option(
        "--out-of-range", help="Thermal files: temperatures outside the calibrated range.")] = "refuse",
    force: Annotated[bool, typer.Option(
        "--force", help="Replace an existing output that gyrocal did not write, and correct data that "
        "'gyrocal apply' already corrected.")] = False,
    store: Annotated[Optional[str], typer.Option(
        "--store", help="Take the calibration from this store: the unit's (--unit) in force at the recording's "
        "time (its file's modification time, or --at); give only the recording (default: none).", metavar="URL",
        rich_help_panel="Production station")] = None,
    unit_serial: Annotated[Optional[str], typer.Option("--unit", help="With --store: the unit's serial (default: none).",
                                                       metavar="SERIAL", rich_help_panel="Production station")] = None,
    at: Annotated[Optional[str], typer.Option("--at", help="With --store: the time (ISO 8601) instead of the "
                                              "recording's (default: its file time).", rich_help_panel="Production station")] = None,
) -> None:
    """Correct a recording; gyro columns are replaced by corrected rates, other columns pass through."""
    # long function: the command's steps in order (calibration, reading, checks, correction, output)
    from ..io import check_csv_name, read_header_comment, write_recording

    if store is not None:
        if recording is not None:
            raise InputError("with --store give only the recording: the calibration comes from the store")
        recording, (cal, calibration) = calibration, _from_store(store, unit_serial, calibration, at)
    elif recording is None:
        raise InputError("give the calibration file and the recording (or --store URL --unit SERIAL and the "
                         "recording)")
    else:
        from ..results.files import load_correction

        refuse_swapped(calibration, recording, command="apply", usage="calibration file comes")
        cal = load_correction(calibration)
    check_output(output, inputs=(calibration, recording), force=force, replaceable=starts_with(f"# {_APPLIED}"))
    check_csv_name(output)
    comment = read_header_comment(recording)
    if not force and comment is not None and comment.startswith(_APPLIED):
        raise InputError(f"{recording.name} was written by 'gyrocal apply' ('# {comment[:60]}'): its rates are "
                         f"corrected already, and {calibration.name} would correct them twice",
                         hint="give the raw recording, or --force to correct it again")
    unit = _unit(units, cal, calibration)
    asked = accel_units is not None
    accel_units, gravity = _accel_reading(ctx, cal, accel_units, gravity)
    read = dict(units=unit, columns=columns, skip_rows=skip_rows, sample_rate=sample_rate, topic=topic,
                saturation=saturation, no_unit_check=no_unit_check, imu=imu)
    try:
        rec = read_from_flags(recording, **read, accel_units=accel_units, accel_sensitivity=accel_sensitivity,
                              gravity=gravity)
    except InputError as exc:
        # a gyro-only log and an IMU calibration whose gyro does not need the accelerometer: correct the gyro
        part = getattr(cal, "accelerometer", None)
        if asked or part is None or part.get("gyro_g_sensitivity") or "no accelerometer column" not in str(exc):
            raise
        rec = read_from_flags(recording, **read)
        console.print(f"note: {recording.name} has no ax ay az: the gyro is corrected, the calibration's "
                      "accelerometer part is not used", highlight=False, soft_wrap=True)
    if not no_unit_check and getattr(cal, "observed", None) is not None:
        _check_observed(cal, rec, recording.name, calibration.name)
    options = {name: value for name, value in (("model", model), ("out_of_range", out_of_range))
               if given(ctx, name)}
    corrected = cal.apply(rec, **options)
    out_units = corrected.source_units
    accel = "" if corrected.accel is None else f", ax ay az in {corrected.accel_units}"
    note = f"{_APPLIED} with {Path(calibration).name}; gx gy gz in {out_units}{accel}"
    write_recording(output, corrected, header_comment=note)
    console.print(f"wrote {output} ({len(corrected)} rows, gx gy gz in {out_units})", highlight=False)


def _check_observed(cal, rec, source: str, name: str) -> None:
    """Warn of data unlike the calibration's (read in its input unit: the rates times a scale, not a copy)."""
    from ..observations.observed import check_observed

    scale = 1.0 / cal.input_scale if rec.units == "rad/s" else 1.0
    note = check_observed(cal.observed, rec.gyro, rec.sample_rate, source=source, calibration=name,
                          sensitivity=cal.sensitivity, output_units=cal.output_units, scale=scale)
    if note is not None:
        warn(note)


def _from_store(url: str, serial: str | None, recording: Path, at: str | None):
    """The unit's calibration in force at the recording's time, and a name for it (a path of the store)."""
    from datetime import datetime, timezone

    from ..results.calibration import Calibration
    from ..results.files import from_document
    from ..station.identity import check_serial
    from ..store import open_store
    from ..thermal.model import ThermalCalibration

    if serial is None:
        raise InputError("--store needs the unit: give --unit SERIAL")
    serial = check_serial(serial)
    if at is not None:
        when, why = iso_time(at, "--at"), "--at"
    elif recording.is_file():
        when, why = datetime.fromtimestamp(recording.stat().st_mtime, timezone.utc), "the recording's file time"
    else:
        raise InputError(f"recording {recording} not found")
    with open_store(url) as st:
        record = st.in_force(serial, when)
    if record is None:
        raise InputError(f"unit {serial} has no calibration in force at {when:%Y-%m-%dT%H:%M:%SZ} ({why}) in {url}")
    name = Path(f"{serial}-record-{record.id}.json")
    cal = from_document(record.document, name, (Calibration, ThermalCalibration))
    console.print(f"calibration: record {record.id} of {url} ({record.created:%Y-%m-%dT%H:%M:%SZ}), in force at "
                  f"{when:%Y-%m-%dT%H:%M:%SZ} ({why})", highlight=False, soft_wrap=True)
    return cal, name


def _accel_reading(ctx, cal, accel_units: str | None, gravity: float) -> tuple[str | None, float]:
    """A calibration with an accelerometer part reads ``ax, ay, az`` in its input unit and g by default."""
    part = getattr(cal, "accelerometer", None)
    if part is None or part.get("units") is None:
        return accel_units, gravity
    units = part["units"]
    default_gravity = units.get("gravity") or gravity
    return (accel_units or units.get("input"), gravity if given(ctx, "gravity") else default_gravity)


def _unit(units: str | None, cal, calibration: Path) -> str:
    """The unit to read the data in: the calibration's by default. Another rate unit is converted
    (rates are physical), and so are rates for a counts calibration that knows its sensitivity."""
    from ..units import parse_input_unit

    expected = cal.input_units
    if units is None:
        return expected
    unit = parse_input_unit(units, "units")
    convertible = "counts" not in (unit, expected) or (expected == "counts" and cal.sensitivity is not None)
    if unit != expected and not convertible:
        raise InputError(f"{{param}} {units} does not match the calibration's input units {expected}", param="units",
                         value=units, hint=f"{calibration.name} corrects data in {expected}")
    return unit
