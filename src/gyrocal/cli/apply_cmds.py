"""Command ``apply``: correct a recording with any calibration file."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ..choices import OutOfRange, TableModel
from ..errors import InputError
from ._options import given
from ._outputs import check_output, starts_with
from ._reading import READING, read_from_flags
from .app import app, console

__all__ = ["apply"]

_APPLIED = "corrected by gyrocal"  # first line of an apply output: a later apply may replace it
#: Flags that become options of the calibration's ``apply`` when typed (each kind refuses those it lacks).
_APPLY_OPTIONS = ("model", "out_of_range")


@app.command()
def apply(
    ctx: typer.Context,
    calibration: Annotated[Path, typer.Argument(help="A gyrocal calibration or thermal calibration file.")],
    recording: Annotated[Path, typer.Argument(help="Recording to correct.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Corrected CSV.")],
    units: READING.Units = None,
    columns: READING.Columns = None,
    sample_rate: READING.SampleRate = None,
    topic: READING.Topic = None,
    saturation: READING.Saturation = "error",
    no_unit_check: READING.NoUnitCheck = False,
    accel_units: READING.AccelUnits = None,
    accel_sensitivity: READING.AccelSensitivity = None,
    gravity: READING.Gravity = 9.80665,
    model: Annotated[TableModel, typer.Option("--model", help="Thermal files: evaluation in temperature.")]
    = "lagrange",
    out_of_range: Annotated[OutOfRange, typer.Option(
        "--out-of-range", help="Thermal files: temperatures outside the calibrated range.")] = "refuse",
    force: Annotated[bool, typer.Option("--force", help="Replace an existing output that gyrocal did not write.")]
    = False,
) -> None:
    """Correct a recording; gyro columns are replaced by corrected rates, other columns pass through."""
    from ..files import load
    from ..io import write_recording
    from ..units import parse_input_unit

    check_output(output, inputs=(calibration, recording), force=force, replaceable=starts_with(f"# {_APPLIED}"))
    cal = load(calibration)
    expected = cal.input_units
    if units is not None and parse_input_unit(units, "units") != expected:
        raise InputError(f"--units {units} does not match the calibration's input units {expected}; "
                         f"{calibration} applies to data in {expected}")
    rec = read_from_flags(recording, units=expected, columns=columns, sample_rate=sample_rate, topic=topic,
                          saturation=saturation, no_unit_check=no_unit_check, accel_units=accel_units,
                          accel_sensitivity=accel_sensitivity, gravity=gravity)
    options = {name: value for name, value in (("model", model), ("out_of_range", out_of_range))
               if given(ctx, name)}
    corrected = cal.apply(rec, **options)
    out_units = corrected.source_units
    accel = "" if corrected.accel is None else f", ax ay az in {corrected.accel_units}"
    note = f"{_APPLIED} with {Path(calibration).name}; gx gy gz in {out_units}{accel}"
    write_recording(output, corrected, header_comment=note)
    console.print(f"wrote {output} ({len(corrected)} rows, gx gy gz in {out_units})", highlight=False)
