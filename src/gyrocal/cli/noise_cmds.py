"""Command ``noise``: Allan deviation of a log at rest, with the figures' intervals."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..choices import MotionPolicy
from ..constants import STANDARD_GRAVITY
from ..errors import InputError
from ._outputs import check_output, json_format
from ._reading import READING, read_from_flags, required_units
from ._station import StationFlags, conclude, finish, station_flags, write_and_store
from .app import app, console

__all__ = ["noise"]


def _cell(fig, r: int, factor: float, missing: str) -> str:
    """A figure above its interval as percentages: ``5.01e-04`` above ``-0.2/+0.2%``."""
    v = fig.value[r] * factor
    if not math.isfinite(v):
        return missing
    if not (math.isfinite(fig.low[r]) and math.isfinite(fig.high[r])):
        return f"{v:.3g}"
    low, high = 100 * (1 - fig.low[r] * factor / v), 100 * (fig.high[r] * factor / v - 1)
    return f"{v:.3g}\n-{low:.2g}/+{high:.2g}%"


#: Column heads (density, bias instability, random walk) per displayed unit.
_HEADS = {"rad/s": ("rad/s/\u221aHz", "rad/s", "rad/s\u00b2/\u221aHz"),
          "deg/s": ("deg/s/\u221aHz", "deg/s", "deg/s\u00b2/\u221aHz"),
          "m/s^2": ("m/s\u00b2/\u221aHz", "m/s\u00b2", "m/s\u00b3/\u221aHz")}


def _table(title: str, sensor, fs: float, unit: str, factor: float):
    from rich.table import Table

    density, bias, walk = _HEADS[unit]
    table = Table(title=title, caption="each figure above its interval")
    # short names over their units, so the table fits 80 columns without cutting a number
    for col in ("axis", f"density\n{density}", f"\u03c3/sample\n{bias}", f"bias inst.\n{bias}", "at \u03c4\ns",
                f"random walk\n{walk}"):
        table.add_column(col, justify="right", no_wrap=True)
    std = sensor.noise_std(fs) * factor
    tau = sensor.bias_instability.tau
    for r, name in enumerate(("x", "y", "z", "sensor")):
        table.add_row(name, _cell(sensor.density, r, factor, "-"), f"{std[r]:.3g}",
                      _cell(sensor.bias_instability, r, factor, "not reached"),
                      f"{tau[r]:.3g}" if math.isfinite(tau[r]) else "-",
                      _cell(sensor.random_walk, r, factor, "not seen"))
    return table


#: rad/s/sqrt(Hz) -> deg/sqrt(h) and rad/s -> deg/h, a datasheet's units.
_ARW = 180.0 / math.pi * 60.0
_DEG_H = 180.0 / math.pi * 3600.0


def _datasheet(sensor):
    """The gyro's angle random walk [deg/sqrt(h)], bias instability [deg/h] and the density's fitted range."""
    from rich.table import Table

    table = Table(title="gyro in datasheet units", caption="ARW: the -1/2 fit, at 1 s")
    for col in ("axis", "ARW\ndeg/\u221ah", "bias inst.\ndeg/h", "-1/2 fit\n\u03c4 range s"):
        table.add_column(col, justify="right", no_wrap=True)
    d = sensor.density
    for r, name in enumerate(("x", "y", "z", "sensor")):
        fit = f"{d.tau_min[r]:.3g}-{d.tau_max[r]:.3g}" if math.isfinite(d.tau_min[r]) else "-"
        table.add_row(name, _cell(d, r, _ARW, "-"), _cell(sensor.bias_instability, r, _DEG_H, "not reached"), fit)
    return table


@app.command()
@station_flags
def noise(
    recording: Annotated[Path, typer.Argument(
        help="Log at rest: CSV, Parquet, ROS/MCAP bag, PX4 .ulg, ArduPilot .bin.")],
    units: READING.Units = None,
    columns: READING.Columns = None,
    skip_rows: READING.SkipRows = None,
    sample_rate: READING.SampleRate = None,
    sensitivity: READING.SensitivityNeeded = None,
    output_units: READING.OutputUnits = None,
    topic: READING.Topic = None,
    no_unit_check: READING.NoUnitCheck = False,
    accel_units: READING.AccelUnits = None,
    accel_sensitivity: READING.AccelSensitivity = None,
    gravity: READING.Gravity = STANDARD_GRAVITY,
    imu: READING.Imu = None,
    motion: Annotated[MotionPolicy, typer.Option(
        "--motion", help="A log that moves: analyse its longest still stretch (restrict) or refuse it.")] = "restrict",
    plot: Annotated[Optional[Path], typer.Option(
        "--plot", help="Allan deviation plot (.png, .pdf, .svg) (default: none).")] = None,
    json_out: Annotated[Optional[Path], typer.Option(
        "-o", "--output", "--json", help="Write the noise file, gyrocal.noise (default: none); --json is its old "
        "name.")] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace an -o file that is not a noise file.")]
    = False,
    flags: StationFlags = StationFlags(),
) -> None:
    """Allan deviation of a log at rest: noise density, bias instability and random walk, with intervals."""
    from ..noise import FORMAT
    from ..units import parse_rate_unit, unit_factor

    # every output is checked before anything is read, computed or written
    check_output(json_out, flag="-o", inputs=(recording,), force=force, replaceable=json_format(FORMAT))
    check_output(plot, flag="--plot", inputs=(recording, json_out), outputs=(json_out,), force=True)
    if plot is not None:
        from ..plotting import check_figure_path

        check_figure_path(plot)
    unit = required_units(units)
    if unit == "counts" and sensitivity is None:
        raise InputError("noise figures are physical quantities, so raw counts need their sensitivity",
                         param="sensitivity", hint="give {param} (LSB per deg/s, e.g. 131 for a +-250 deg/s "
                                                    "MPU-9250)")
    rec = read_from_flags(recording, units=unit, columns=columns, skip_rows=skip_rows, sample_rate=sample_rate,
                          sensitivity=sensitivity,
                          output_units=output_units, topic=topic, no_unit_check=no_unit_check,
                          accel_units=accel_units, accel_sensitivity=accel_sensitivity, gravity=gravity, imu=imu)
    if rec.accel_units == "counts":
        raise InputError("noise figures are physical quantities, so raw accelerometer counts need their sensitivity",
                         param="accel_sensitivity", hint="give {param} (LSB per g, e.g. 16384 for +-2 g)")
    from ..jobs import run_job

    result, verdict = finish(run_job("noise", recording=rec, sources=(recording,), motion=motion), flags)
    record = write_and_store(result, flags, json_out, verdict)
    report = result.value
    shown = parse_rate_unit(output_units or "deg/s") if unit == "counts" else unit
    fs = report.sample_rate
    head = f"{report.duration:.0f} s at {fs:g} Hz, {100 * report.confidence:.0f} % intervals"
    console.print(_table(f"{recording.name}: gyro, {head}", report.gyro, fs, shown, 1.0 / unit_factor(shown)))
    console.print(_datasheet(report.gyro))
    if report.accel is not None:
        console.print(_table(f"{recording.name}: accelerometer", report.accel, fs, "m/s^2", 1.0))
    if json_out is not None:
        console.print(f"wrote {json_out}")
    if plot is not None:
        from ..plotting import save_figure

        save_figure(result.figures["allan"](), plot)
        console.print(f"wrote {plot}")
    conclude(console, result, flags, record, verdict)
