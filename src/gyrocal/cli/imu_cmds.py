"""Command ``imu``: calibrate a whole IMU (gyro and accelerometer) from a hand session."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..choices import AccelModel, AccelOutputUnit, ImuGyroModel
from ..constants import STANDARD_GRAVITY
from ._imu_report import print_imu_run
from ._options import AcceptImplausible
from ._outputs import check_output, same_document
from ._reading import READING, read_from_flags, required_units
from ._station import StationFlags, conclude, finish, station_flags, write_and_store
from .app import app, console, warn

__all__ = ["imu"]


@app.command()
@station_flags
def imu(
    recording: Annotated[Path, typer.Argument(help="Hand session log with gyro and accelerometer columns.")],
    units: READING.Units = None,
    columns: READING.Columns = None,
    skip_rows: READING.SkipRows = None,
    sample_rate: READING.SampleRate = None,
    sensitivity: READING.Sensitivity = None,
    output_units: READING.OutputUnits = None,
    topic: READING.Topic = None,
    saturation: READING.Saturation = "error",
    no_unit_check: READING.NoUnitCheck = False,
    imu: READING.Imu = None,
    accel_units: READING.AccelUnits = None,
    accel_sensitivity: READING.AccelSensitivity = None,
    gravity: READING.Gravity = STANDARD_GRAVITY,
    accel_log: Annotated[Optional[Path], typer.Option(
        "--accel-log", help="The accelerometer's own log, when it is not in the gyro's (imu_tk keeps the two apart) "
        "(default: none, ax ay az are in the recording).")] = None,
    accel_columns: Annotated[Optional[str], typer.Option(
        "--accel-columns", help="With --accel-log: its columns, e.g. t=1,ax=2,ay=3,az=4 (default: columns named "
        "ax, ay, az).")] = None,
    windows: Annotated[Optional[Path], typer.Option(
        "--windows", help="Still poses (and turns) chosen by hand; imucal's section list makes a Ferraris "
        "session (default: none, the poses are detected).")] = None,
    accel_model: Annotated[AccelModel, typer.Option(
        "--accel-model", help="Accelerometer model; auto: the largest the poses determine.")] = "auto",
    gyro_model: Annotated[ImuGyroModel, typer.Option(
        "--gyro-model", help="Gyro model; auto: the largest the turns determine.")] = "auto",
    g_sensitivity: Annotated[bool, typer.Option(
        "--g-sensitivity", help="Also fit the gyro's sensitivity to acceleration, where the poses determine it.")]
    = False,
    min_static: Annotated[float, typer.Option(
        "--min-static", help="Shortest still pose kept [s].")] = 1.0,
    threshold: Annotated[Optional[float], typer.Option(
        "--threshold", help="Multiplier of the stillness thresholds measured at rest, e.g. 100 for poses held by "
        "hand (default: several are tried and the accelerometer fit picks one).")] = None,
    temp_lag: Annotated[Optional[float], typer.Option(
        "--temp-lag", help="A chamber log: time constant of a temperature sensor that lags the die [s]; each "
        "plateau's temperature is moved to the die's, mean + lag x its drift rate (default: none, as read).")]
    = None,
    accel_output_units: Annotated[AccelOutputUnit, typer.Option(
        "--accel-output-units", help="Unit of corrected accelerations.")] = "m/s^2",
    output: Annotated[Optional[Path], typer.Option(
        "-o", "--output", help="Calibration file to write (default: none, print only).")] = None,
    plot: Annotated[Optional[Path], typer.Option(
        "--plot", help="Picture of the poses on the sphere and each turn's misfit (.png, .pdf, .svg) "
        "(default: none).")] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace an output that holds another calibration.")]
    = False,
    accept_implausible: AcceptImplausible = False,
    flags: StationFlags = StationFlags(),
) -> None:
    """Calibrate gyro and accelerometer together from still poses and hand turns (no turntable needed)."""
    from .._validation import positive
    from ..errors import InputError

    units = required_units(units)
    if accel_units is None:
        raise InputError("{param} is required: m/s^2, g or counts (the unit of the accelerometer columns)",
                         param="accel_units")
    if accel_columns is not None and accel_log is None:
        raise InputError("--accel-columns is for --accel-log; map the recording's own columns with --columns ax=...")
    check_output(plot, flag="--plot", inputs=(recording, windows, output, accel_log), outputs=(output,), force=True)
    rec = read_from_flags(recording, units=units, columns=columns, skip_rows=skip_rows, sample_rate=sample_rate,
                          sensitivity=sensitivity, output_units=output_units, topic=topic, saturation=saturation,
                          no_unit_check=no_unit_check, imu=imu, accel_units=None if accel_log else accel_units,
                          accel_sensitivity=None if accel_log else accel_sensitivity, gravity=gravity,
                          need_accel=accel_log is None)
    if accel_log is not None:
        from ..io import attach_accelerometer

        rec = attach_accelerometer(rec, accel_log, accel_units=accel_units, columns=accel_columns, skip_rows=skip_rows,
                                   sample_rate=sample_rate, accel_sensitivity=accel_sensitivity, gravity=gravity)

    from ..jobs import run_job

    result = run_job("imu", recording=rec, sources=(recording, accel_log), windows=windows, gravity=gravity,
                     accel_model=accel_model, gyro_model=gyro_model, g_sensitivity=g_sensitivity,
                     min_static=min_static, output_units=output_units, accel_output_units=accel_output_units,
                     threshold=threshold, accept_implausible=accept_implausible,
                     sensor_lag=None if temp_lag is None else positive("temp_lag", temp_lag))
    if result.implausible is not None:
        warn(result.implausible)
    run = result.value
    result, verdict = finish(result, flags)
    check_output(output, inputs=result.inputs, force=force, replaceable=same_document(result.document),
                 holds="a different calibration or another file")
    if plot is not None:
        from ..plotting import save_figure

        save_figure(result.figures["poses"](), plot)
    record = write_and_store(result, flags, output, verdict)
    for line in run.time_base.describe():
        console.print(line, highlight=False, soft_wrap=True, markup=False)
    print_imu_run(run)
    for line in run.warnings:
        warn(line)
    if output is not None:
        console.print(f"wrote {output}" + (f" and {plot}" if plot is not None else ""), highlight=False)
    conclude(console, result, flags, record, verdict)
