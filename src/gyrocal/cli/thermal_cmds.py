"""Commands ``thermal`` and ``thermal-report``: the full-temperature-range method from the command line.

User units live here: ``--full-scale`` is in the data's unit; temperatures in degC.
Library warnings (saturated steps, clamped temperatures) are printed as one line each.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..choices import OutOfRange
from ..errors import InputError
from ._options import AcceptImplausible, in_unit
from ._outputs import check_output, refuse_swapped, same_document
from ._reading import READING
from ._station import StationFlags, conclude, finish, station_flags, write_and_store
from .app import app, console, warn, warnings_as_lines

__all__ = ["thermal", "thermal_report"]


Units = Annotated[str, typer.Option("--units", help="Unit of the gyro and table_rate columns (required).",
                                    metavar="<rad/s|deg/s|counts>")]
Settle = Annotated[float, typer.Option("--settle", help="Time dropped at the start of every step (s).")]
FullScale = Annotated[Optional[str], typer.Option(
    "--full-scale", help="Gyro range, in the data's rate unit unless a unit is written (--units counts: counts, or "
    "e.g. 250deg/s); steps with samples at it are left out (with a warning) "
    "(default: saturation found as runs of identical extreme readings).")]
TempTol = Annotated[float, typer.Option(
    "--temp-tolerance", help="Spread allowed inside a step, and closest distinct temperature points (degC).")]


def _units(units: str, output_units: str | None, sensitivity: float | None) -> tuple[str, str]:
    """(input unit of the table, output unit) for the command's flags."""
    from ..units import parse_input_unit, parse_rate_unit

    u = parse_input_unit(units, "units")
    if u == "counts":
        if sensitivity is None or output_units is None:
            raise InputError("--units counts needs --sensitivity and --output-units (the physical unit of the counts)")
        return parse_rate_unit(output_units, "output_units"), parse_rate_unit(output_units, "output_units")
    return u, parse_rate_unit(output_units or u, "output_units")


def _full_scale(text: str | None, units: str, rate_unit: str, sensitivity: float | None) -> float | None:
    """--full-scale in rad/s (checked as the user typed it, in the data's unit unless a unit is written)."""
    from .._validation import positive
    from ..units import parse_input_unit, unit_factor

    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:  # written with its unit
        return positive("full_scale", in_unit("--full-scale", text, "rad/s"))
    value = positive("full_scale", value)
    if parse_input_unit(units) == "counts":
        return value / sensitivity * unit_factor(rate_unit)
    return value * unit_factor(units)


def _read(path: Path, units: str, columns, sample_rate, sensitivity, output_units, skip_rows=None):
    from ..io import read_session

    return read_session(path, units=units, columns=columns, sample_rate=sample_rate, sensitivity=sensitivity,
                        output_units=output_units, saturation="ignore", skip_rows=skip_rows)


@app.command("thermal")
@station_flags
def thermal(
    session: Annotated[Path, typer.Argument(help="Session: one CSV/Parquet/bag with every temperature point, or a folder.")],
    units: Units,
    output: Annotated[Path, typer.Option("-o", "--output", help="Thermal calibration file to write (JSON).")],
    output_units: READING.OutputUnits = None,
    columns: READING.Columns = None,
    skip_rows: READING.SkipRows = None,
    sample_rate: READING.SampleRate = None,
    sensitivity: READING.SensitivityNeeded = None,
    settle: Settle = 2.0,
    full_scale: FullScale = None,
    temp_tolerance: TempTol = 2.0,
    ref_temp: Annotated[float, typer.Option("--ref-temp", help="Temperature of the traditional baseline (degC).")] = 25.0,
    max_order: Annotated[int, typer.Option("--max-order", help="Highest polynomial order of the smooth model.")] = 3,
    temp_tau: Annotated[float, typer.Option(
        "--temp-tau", help="Time constant for smoothing per-sample temperature when compensating (s).")] = 20.0,
    force: Annotated[bool, typer.Option("--force", help="Replace an -o file that holds a different calibration.")]
    = False,
    accept_implausible: AcceptImplausible = False,
    flags: StationFlags = StationFlags(),
) -> None:
    """Fit a temperature table (the full-temperature-range method) from a turntable session."""
    from ..jobs import run_job

    in_u, out_u = _units(units, output_units, sensitivity)
    check_output(output, inputs=(session,), force=True)  # what needs no fit: fail fast, before fitting
    with warnings_as_lines():
        recs, names = _read(session, units, columns, sample_rate, sensitivity, output_units, skip_rows)
        result = run_job("thermal", session=recs, names=tuple(names), units=units, input_units=in_u,
                         output_units=out_u, settle=settle, full_scale=_full_scale(full_scale, units, out_u, sensitivity),
                         temp_tolerance=temp_tolerance, reference_temp=ref_temp, max_order=max_order,
                         temp_tau=temp_tau, accept_implausible=accept_implausible)
    if result.implausible is not None:
        warn(result.implausible)
    cal, fit = result.value
    inputs = [session / name for name in names] if session.is_dir() else [session]  # a folder: each file read
    result, verdict = finish(result, flags, inputs=inputs)
    check_output(output, inputs=(session,), force=force, replaceable=same_document(result.document),
                 holds="a different calibration or another file")
    record = write_and_store(result, flags, output, verdict, inputs=inputs)
    _print_table(cal, fit)
    console.print(f"wrote {output}")
    conclude(console, result, flags, record, verdict)


def _print_table(cal, fit) -> None:
    import numpy as np
    from rich.box import SIMPLE
    from rich.markup import escape
    from rich.table import Table

    from ..units import unit_factor

    user = cal.kg_user
    std = cal.to_user(cal.std)  # 1-sigma in the table's units; below, the largest of each group of terms
    groups = (std[:, :3].max(axis=1), std[:, 3:9].max(axis=1), std[:, 9:].max(axis=1))
    # two tables, so that each fits 80 columns (piped output, small terminals)
    style = dict(box=SIMPLE, padding=(0, 1), collapse_padding=True, show_edge=False)
    table = Table(title=escape(f"Kg per temperature (B and resid in [{cal.input_units}])"), **style)
    sds = Table(title=escape(f"largest 1-sigma per temperature (sd B in [{cal.input_units}])"),
                caption="sd K / sd mis / sd B: of Kxx..Kzz / of the 6 misalignments / of Bx..Bz", **style)
    for t_, cols in ((table, ("T degC", "Kxx", "Kyy", "Kzz", "Bx", "By", "Bz", "resid")),
                     (sds, ("T degC", "sd K", "sd mis", "sd B"))):
        for col in cols:
            t_.add_column(escape(col), justify="right", no_wrap=True, min_width=7)
    for i, t in enumerate(cal.temps):
        k = user[i]
        table.add_row(f"{t:.1f}", *(f"{k[j]:.5f}" for j in (0, 1, 2)),
                      *(f"{k[j]:.4f}" for j in (9, 10, 11)),
                      f"{np.max(cal.residual_rms[i]) / unit_factor(cal.input_units):.2g}")
        sds.add_row(f"{t:.1f}", *(f"{g[i]:.1e}" for g in groups))
    console.print(table)
    console.print(sds)
    console.print(f"{len(fit.steps)} steps; smooth model orders (Kg order): "
                  + " ".join(map(str, cal.smooth.orders.tolist())))


def _load_table(path: Path, load_thermal):
    """The gyro thermal table of `path`, or an IMU thermal calibration (``gyrocal imu`` on a chamber log:
    a calibration with ``accelerometer.thermal``); other files are refused with the table's error."""
    from ..errors import FileFormatError, GyrocalError

    try:
        return load_thermal(path)
    except FileFormatError:
        from ..results.files import load_correction

        try:
            other = load_correction(path)
        except (GyrocalError, OSError, ValueError):  # the first error is the one to show
            other = None
        if (getattr(other, "accelerometer", None) or {}).get("thermal") is not None:
            return other
        raise


@app.command("thermal-report")
def thermal_report(
    calibration: Annotated[Path, typer.Argument(help="Thermal calibration file from 'gyrocal thermal', or from "
                                                     "'gyrocal imu' on a chamber log.")],
    test: Annotated[Path, typer.Argument(help="Test recording (or folder) with t, gx, gy, gz, temp, table_rate, axis; "
                                              "for an IMU calibration a pose log with t, gx..az, temp.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Report folder to write.")],
    units: Annotated[Optional[str], typer.Option("--units", help="Unit of the test data (default: the calibration's input unit).",
                                                          metavar="<rad/s|deg/s|counts>")] = None,
    columns: READING.Columns = None,
    skip_rows: READING.SkipRows = None,
    sample_rate: READING.SampleRate = None,
    sensitivity: READING.SensitivityOfCalibration = None,
    settle: Settle = 2.0,
    full_scale: FullScale = None,
    temp_tolerance: TempTol = 2.0,
    out_of_range: Annotated[OutOfRange, typer.Option(
        "--out-of-range", help="Test temperatures outside the calibrated range: refuse, clamp or extrapolate.")
    ] = "refuse",
    figures: Annotated[bool, typer.Option("--figures/--no-figures", help="Draw the PNG figures.")] = True,
    accel_units: Annotated[Optional[str], typer.Option(
        "--accel-units", help="An IMU calibration's test log: unit of ax, ay, az (default: the calibration's "
        "accelerometer input unit).", metavar="<m/s^2|g|counts>")] = None,
) -> None:
    """Compare uncompensated, traditional, Lagrange and smooth compensation on a test recording."""
    from ..plotting.thermal_report import write_report
    from ..results.files import load_thermal
    from ..thermal.evaluate import evaluate

    refuse_swapped(calibration, test, command="thermal-report", usage="thermal file from 'gyrocal thermal' comes")
    check_output(output, inputs=(calibration, test), folder=True)
    cal = _load_table(calibration, load_thermal)
    if getattr(cal, "accelerometer", None) is not None:
        from ._imu_thermal_report import imu_thermal_report

        return imu_thermal_report(cal, test, output, units=units, accel_units=accel_units, columns=columns,
                                  skip_rows=skip_rows, sample_rate=sample_rate, figures=figures)
    if accel_units is not None:
        raise InputError("--accel-units is for an IMU thermal calibration (gyrocal imu); a gyro table's test log "
                         "has no accelerometer")
    units = units or cal.input_units
    with warnings_as_lines():
        recs, _ = _read(test, units, columns, sample_rate, sensitivity, cal.output_units if units == "counts" else None,
                        skip_rows)
        ev = evaluate(cal, recs, settle=settle, temp_tolerance=temp_tolerance, out_of_range=out_of_range,
                      full_scale=_full_scale(full_scale, units, cal.output_units, sensitivity))
        paths = write_report(cal, ev, output, figures=figures)
    from rich.markup import escape
    from rich.table import Table

    table = Table(title=escape(f"RMS error [{cal.output_units}] per rotating axis / gyro axis"))
    for col in ("rot", "gyro", "uncomp.", "traditional", "lagrange", "smooth", "lagrange cut"):
        table.add_column(col, justify="right", no_wrap=True)
    for r in ev.summary(cal.output_units):
        table.add_row(r["rotating_axis"], r["gyro_axis"], *(f"{r[m + '_rms']:.4g}" for m in
                      ("uncompensated", "traditional", "lagrange", "smooth")), f"{r['lagrange_rms_reduction_pct']:.1f} %")
    console.print(table)
    console.print(f"wrote {len(paths)} files to {output}")
