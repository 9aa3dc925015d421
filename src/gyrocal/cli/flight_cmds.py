"""Command ``thermal-bias``: gyro bias (and the accelerometer's offset change) against temperature from a still
log of a warming board."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..constants import STANDARD_GRAVITY
from ._options import AcceptImplausible
from ._outputs import check_output, json_format
from ._reading import READING, read_from_flags, required_units
from ._station import StationFlags, conclude, finish, station_flags, write_and_store
from .app import app, console, warn

__all__ = ["thermal_bias"]


def _read(log: Path, units, columns, sample_rate, sensitivity, output_units, imu, accel: dict):
    """The recording and what the log says about its IMU (PX4 device ids, ArduPilot IMU number)."""
    from ..errors import InputError
    from ..io.flightlog import flight_log_kind, read_flight_log

    if log.is_file() and flight_log_kind(log) is not None:
        rec, info = read_flight_log(log, imu=imu, units=units, accel_units=accel["accel_units"])
        source = {"file": log.name, **info}
    else:
        rec = read_from_flags(log, units=required_units(units), columns=columns, sample_rate=sample_rate,
                              sensitivity=sensitivity, output_units=output_units, imu=imu, **accel)
        source = {"file": log.name}
    if accel["accel_units"] is not None and rec.accel is None:
        raise InputError(f"{log.name} has no accelerometer columns (ax, ay, az)", param="accel_units",
                         hint="map them with --columns ax=..,ay=..,az=.., or leave out {param}")
    if rec.accel_units == "counts":
        raise InputError("the accelerometer's change with temperature is fitted in m/s^2, so raw counts need their "
                         "sensitivity", param="accel_sensitivity", hint="give {param} (LSB per g)")
    return rec, source


def _summary(tb, unit: str, factor: float, title: str | None = None):
    import numpy as np
    from rich.table import Table

    table = Table(title=title or f"bias = sum X_n (T - {tb.tref:.2f})^n, T clipped to {tb.tmin:.2f}..{tb.tmax:.2f} "
                  "degC", caption="value above its 1-sigma")
    for col in ("axis", "order", f"at {tb.tmin:.1f} C\n{unit}", f"at {tb.tref:.1f} C\n{unit}",
                f"at {tb.tmax:.1f} C\n{unit}", f"1-sigma max\n{unit}", f"residual\n{unit}"):
        table.add_column(col, justify="right", no_wrap=True)
    temps = [tb.tmin, tb.tref, tb.tmax]
    bias, sd = tb.value_at(temps) * factor, tb.std_at(temps) * factor
    worst = tb.std_at(np.linspace(tb.tmin, tb.tmax, 25)).max(axis=0) * factor
    for a, axis in enumerate("xyz"):
        table.add_row(axis, str(int(tb.orders[a])), *(f"{bias[i, a]:.4g}\n\u00b1{sd[i, a]:.2g}" for i in range(3)),
                      f"{worst[a]:.2g}", f"{tb.residual_rms[a] * factor:.2g}")
    return table


@app.command("thermal-bias")
@station_flags
def thermal_bias(
    log: Annotated[Path, typer.Argument(help="Still log of a warming board: PX4 .ulg, ArduPilot .bin, CSV, ...")],
    output: Annotated[Optional[Path], typer.Option(
        "-o", "--output", help="Thermal-bias file to write, JSON (default: none, print only).")] = None,
    units: READING.Units = None,
    columns: READING.Columns = None,
    sample_rate: READING.SampleRate = None,
    sensitivity: READING.SensitivityKept = None,
    output_units: READING.OutputUnits = None,
    imu: READING.Imu = None,
    max_order: Annotated[int, typer.Option("--max-order", help="Highest order tried, 0-3 (firmwares take cubics).")]
    = 3,
    min_span: Annotated[float, typer.Option(
        "--min-span", help="Smallest temperature span accepted [degC] (ArduPilot's minimum: 10).")] = 10.0,
    accel_units: Annotated[Optional[str], typer.Option(
        "--accel-units", help="Also fit the accelerometer's offset change from the reference temperature: unit of "
        "its columns, m/s^2 or g (counts with --accel-sensitivity; flight logs: m/s^2) (default: gyro only).",
        metavar="<m/s^2|g|counts>")] = None,
    accel_sensitivity: READING.AccelSensitivity = None,
    gravity: READING.Gravity = STANDARD_GRAVITY,
    force: Annotated[bool, typer.Option("--force", help="Replace an -o file that is not a thermal-bias file.")]
    = False,
    accept_implausible: AcceptImplausible = False,
    flags: StationFlags = StationFlags(),
) -> None:
    """Fit gyro bias (and accelerometer offset change) against temperature for PX4 and ArduPilot (then
    'gyrocal export --format px4' or ardupilot)."""
    from ..flight import ThermalBias

    check_output(output, inputs=(log,), force=force, replaceable=json_format(ThermalBias.FORMAT))
    accel = {"accel_units": accel_units, "accel_sensitivity": accel_sensitivity, "gravity": gravity}
    rec, source = _read(log, units, columns, sample_rate, sensitivity, output_units, imu, accel)
    from ..io.flightlog import flight_log_kind
    from ..jobs import run_job

    result = run_job("thermal-bias", recording=rec, sources=(log,), source=source, max_order=max_order,
                     min_span=min_span, flight_log=log.is_file() and flight_log_kind(log) is not None,
                     accept_implausible=accept_implausible)
    if result.implausible is not None:
        warn(result.implausible)
    tb, rec, fs = result.value
    result, verdict = finish(result, flags)
    record = write_and_store(result, flags, output, verdict)
    _print(tb, rec, output_units, gravity, fs)
    if output is not None:
        console.print(f"wrote {output}")
    conclude(console, result, flags, record, verdict)


def _print(tb, rec, output_units, gravity: float, fs: float) -> None:
    from ..units import unit_factor

    shown = rec.source_units if rec.source_units in ("rad/s", "deg/s") else (output_units or "deg/s")
    console.print(_summary(tb, shown, 1.0 / unit_factor(shown)))
    console.print(f"{tb.duration:.0f} s at {fs:.4g} Hz; white noise {math.degrees(float(tb.noise_std.mean())):.3g} "
                  "deg/s per sample; orders chosen by leave-one-temperature-segment-out error", highlight=False)
    if tb.accel is None:
        return
    unit = "g" if rec.accel_source_units == "g" else "m/s^2"
    title = (f"accelerometer: change of the offsets from {tb.tref:.2f} degC (zero there: one orientation gives the "
             f"change, not the offset) = sum X_n (T - {tb.tref:.2f})^n")
    console.print(_summary(tb.accel, unit, 1.0 / gravity if unit == "g" else 1.0, title))
