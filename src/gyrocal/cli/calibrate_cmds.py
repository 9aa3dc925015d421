"""Commands ``calibrate``, ``segments``, ``apply`` and ``export``: a thin layer over the library.

User units live here and only here: ``--speed`` is in the data's rate unit per
second, ``--angle`` in degrees, ``--noise-std`` in the data's unit; the library
gets rad/s and radians.

The commands' own checks raise :class:`~gyrocal.errors.InputError`, so they reach the
user through the same error boundary as library errors (``run``: one line, exit 2).
"""

from __future__ import annotations

import json
import math
from enum import Enum
from importlib import resources
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from ..calibration import Calibration, to_document
from ..errors import GyrocalError, InputError
from ..segmentation import describe_found
from ..units import from_rad_s, parse_input_unit, parse_rate_unit, unit_factor
from ..windows import Window
from ._outputs import check_output, same_document, same_text, starts_with
from .app import app, console, warn, warnings_as_lines
from .thermal_cmds import OutOfRangePolicy as OutOfRange

EXAMPLE = "example_servo.csv"
EXAMPLE_TRUTH = "example_servo.truth.json"
EXAMPLE_SPEED = 60.0  # deg/s, seed 000's servo protocol


class MethodName(str, Enum):
    first_moment = "first-moment"
    algorithm1 = "algorithm1"
    lm = "lm"


class ThermalModel(str, Enum):
    lagrange = "lagrange"
    smooth = "smooth"


class SaturationName(str, Enum):
    error = "error"
    drop = "drop"
    ignore = "ignore"


class ExportFormatName(str, Enum):
    json = "json"
    yaml = "yaml"
    c_header = "c-header"


# Reading flags, shared by calibrate, segments and apply.
Units = Annotated[str | None, typer.Option("--units", help="Unit of the gyro columns: rad/s, deg/s or counts.")]
Columns = Annotated[str | None, typer.Option(
    "--columns", help="Map gyrocal names to the file's, e.g. gx=gyroX,gy=gyroY,gz=gyroZ[,t=time,temp=T].")]
SampleRate = Annotated[float | None, typer.Option(
    "--sample-rate", help="Nominal sample rate [Hz]; needed when the file has no time column.")]
Sensitivity = Annotated[float | None, typer.Option(
    "--sensitivity", help="For --units counts: LSB per --output-units rate unit.")]
OutputUnits = Annotated[str | None, typer.Option(
    "--output-units", help="Unit of corrected rates, rad/s or deg/s (default: the data's; deg/s for counts).")]
Saturation = Annotated[SaturationName, typer.Option(
    "--saturation", help="Samples stuck at full scale: refuse (error), drop them, or ignore.")]
NoUnitCheck = Annotated[bool, typer.Option(
    "--no-unit-check", help="Accept rates that look like another unit (e.g. 4000 'rad/s').")]
Topic = Annotated[str | None, typer.Option("--topic", help="sensor_msgs/Imu topic in a ROS 1/ROS 2/MCAP bag.")]
WindowsFile = Annotated[Path | None, typer.Option(
    "--windows", help="Windows file (JSON/CSV list, or imucal's section list) that replaces detection.")]
Speed = Annotated[float | None, typer.Option(
    "--speed", help="Known constant turn rate, in the data's rate unit (deg/s with --units deg/s).")]
Angle = Annotated[float | None, typer.Option(
    "--angle", help="Known angle of each turn, in degrees (e.g. 360); the speed may vary.")]
PlotPath = Annotated[Path | None, typer.Option("--plot", help="Write a picture (.png, .pdf or .svg).")]
Output = Annotated[Path | None, typer.Option("-o", "--output", help="Output file.")]
Force = Annotated[bool, typer.Option("--force", help="Replace an output that holds a different calibration.")]
_APPLIED = "corrected by gyrocal"  # first line of an apply output: a later apply may replace it


def _required_units(units: str | None) -> str:
    if units is None:
        raise InputError("--units is required: rad/s, deg/s or counts (the unit of the gyro columns)")
    return parse_input_unit(units, "--units")


def _rate_unit(units: str, output_units: str | None) -> str:
    """The rate unit of user-facing numbers: --speed, corrected rates (deg/s for counts by default)."""
    if output_units is not None:
        return parse_rate_unit(output_units, "--output-units")
    return "deg/s" if units == "counts" else units


def _read(path: Path, units: str, columns, sample_rate, sensitivity, output_units, topic,
          saturation: SaturationName = SaturationName.error, no_unit_check: bool = False):
    from ..io import read_recording

    return read_recording(path, units=units, columns=columns, sample_rate=sample_rate, sensitivity=sensitivity,
                          output_units=output_units, topic=topic, check_units=not no_unit_check,
                          saturation=saturation.value)


def _reference(speed: float | None, angle: float | None, rate_unit: str) -> tuple[str, float | None, float | None]:
    """``(reference, speed [rad/s], angle [rad])`` from the user's flags."""
    if speed is not None and angle is not None:
        raise InputError(f"give --speed or --angle, not both (got --speed {speed:g} and --angle {angle:g})")
    for name, value in (("--speed", speed), ("--angle", angle)):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise InputError(f"{name} must be a positive number, got {value:g}")
    if speed is not None:
        return "speed", speed * unit_factor(rate_unit), None
    return "angle", None, math.radians(360.0 if angle is None else angle)


def _noise_to_internal(noise_std: float | None, units: str, rate_unit: str, sensitivity: float | None) -> float | None:
    """--noise-std [the data's unit] in the recording's internal unit."""
    if noise_std is None:
        return None
    if not (math.isfinite(noise_std) and noise_std > 0):
        raise InputError(f"--noise-std must be a positive number, got {noise_std:g}")
    if units != "counts":
        return noise_std * unit_factor(units)
    return noise_std if sensitivity is None else noise_std / sensitivity * unit_factor(rate_unit)


def _density_to_internal(noise_density: str, noise_std: float | None, rec):
    """--noise-density (rad/s/sqrt(Hz), per axis) as per-sample noise [rad/s] at the recording's rate."""
    from ..noise import noise_density_arg

    if noise_std is not None:
        raise InputError("give --noise-std or --noise-density, not both")
    if rec.units == "counts":
        raise InputError("--noise-density needs physical units; give --sensitivity with --units counts")
    return noise_density_arg(noise_density) * math.sqrt(rec.sample_rate)


def _windows_from_file(path: Path | None, rec):
    if path is None:
        return None
    from ..io import read_windows

    return read_windows(path, sample_rate=rec.sample_rate, t0=float(rec.t[0]), n_samples=len(rec))


def _example_paths() -> tuple[Path, Path]:
    data = resources.files("gyrocal") / "data"
    return Path(str(data / EXAMPLE)), Path(str(data / EXAMPLE_TRUTH))


def _params_table(run, truth: Calibration | None = None):
    """Rich tables: seed 000 k, b in user units with 1-sigma (and the truth, for the example),
    and the canonical correction."""
    from rich.markup import escape
    from rich.table import Table

    cal = run.calibration
    table = Table()
    for col in ("parameter", "estimate", "1-sigma") + (("truth", "error / sigma") if truth is not None else ()):
        table.add_column(col, justify="left" if col == "parameter" else "right")
    true_values = None
    if truth is not None:
        matrix, offset = truth.correction
        true_values = list(np.diag(matrix)) + list(-offset)  # seed 000: k, and b = -offset
    for i, (name, value, sigma, unit) in enumerate(run.parameters()):
        row = [escape(f"{name} [{unit}]"), f"{value:.6g}", "n/a" if math.isnan(sigma) else f"{sigma:.2g}"]
        if true_values is not None:
            true = float(true_values[i])
            row += [f"{true:.6g}", f"{(value - true) / sigma:+.2f}" if sigma > 0 else "n/a"]
        table.add_row(*row)
    matrix, offset = cal.correction
    canon = Table()
    for label in ("matrix", "", "", "offset"):
        canon.add_column(label, justify="right")
    for r in range(3):
        canon.add_row(*[f"{v:.6g}" for v in matrix[r]], f"{offset[r]:.6g}")
    return table, canon


def _print_calibration(run, truth: Calibration | None = None) -> None:
    cal = run.calibration
    table, canon = _params_table(run, truth)
    ref = (f"speed {from_rad_s(run.reference_value, cal.output_units):g} {cal.output_units}"
           if run.reference == "speed" else f"angle {math.degrees(run.reference_value):g} deg per turn")
    console.print(f"{cal.method}, {ref}: g = diag(k) (m + b), seed 000 eq. 1", highlight=False)
    console.print(table)
    console.print(f"correction w_true = matrix @ (raw - offset), raw in {cal.input_units}, "
                  f"w_true in {cal.output_units}", highlight=False)
    console.print(canon)
    if cal.noise_std is not None:
        noise = cal.noise_std / cal.input_scale
        console.print(f"per-sample noise behind the 1-sigma: {', '.join(f'{v:.3g}' for v in noise)} {cal.input_units}",
                      highlight=False, soft_wrap=True)
    if (note := run.scale_bias_note()) is not None:
        console.print("note: " + note.replace("method first-moment", "--method first-moment"), highlight=False,
                      soft_wrap=True)
    n_rot = sum(w.get("kind") == "rotation" for w in cal.windows)
    console.print(f"windows used: {n_rot} rotation, {len(cal.windows) - n_rot} static; found: "
                  f"{describe_found(run.segmentation.windows, run.segmentation.ignored)}", highlight=False, soft_wrap=True)


def _truth_calibration(path: Path, cal: Calibration) -> Calibration | None:
    """The example's true model in the units of `cal`, from its truth sidecar."""
    from ..models import ScaleBias

    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        model = ScaleBias(k=doc["k"], b=doc["b"])
    except (OSError, ValueError, KeyError):
        return None
    return Calibration(model=model, input_units=cal.input_units, output_units=cal.output_units)


@app.command()
def calibrate(
    recording: Annotated[Path | None, typer.Argument(help="Recording: CSV, Parquet, or a ROS/MCAP bag.")] = None,
    units: Units = None,
    columns: Columns = None,
    sample_rate: SampleRate = None,
    sensitivity: Sensitivity = None,
    output_units: OutputUnits = None,
    topic: Topic = None,
    saturation: Saturation = SaturationName.error,
    no_unit_check: NoUnitCheck = False,
    speed: Speed = None,
    angle: Angle = None,
    windows: WindowsFile = None,
    method: Annotated[MethodName, typer.Option("--method", help="Estimator.")] = MethodName.first_moment,
    noise_std: Annotated[float | None, typer.Option(
        "--noise-std", help="Per-sample noise, in the data's unit, instead of the one measured.")] = None,
    noise_density: Annotated[str | None, typer.Option(
        "--noise-density", help="Noise density instead of the one measured: a number [rad/s/sqrt(Hz)], "
        "'N deg/s/rtHz', or a noise JSON from 'gyrocal noise --json'.")] = None,
    output: Output = None,
    plot: PlotPath = None,
    force: Force = False,
    example: Annotated[bool, typer.Option(
        "--example", help="Run on the bundled simulated MPU9250 servo recording (60 deg/s).")] = False,
) -> None:
    """Estimate scale and bias from a recording of turns; print them with 1-sigma; write the calibration file."""
    from ..pipeline import calibrate as run_calibration

    truth_path = None
    if example:
        if recording is not None:
            raise InputError(f"give a recording or --example, not both (got {recording})")
        recording, truth_path = _example_paths()
        units = units or "deg/s"
        if speed is None and angle is None and windows is None:
            speed = EXAMPLE_SPEED
        intro = (f"example: {recording}\n  same as: gyrocal calibrate {recording} --units deg/s "
                 + (f"--speed {speed:g}" if speed is not None else f"--angle {360 if angle is None else angle:g}"))
    if recording is None:
        raise InputError("give a recording to calibrate (or --example for the bundled one)")
    units = _required_units(units)
    rate_unit = _rate_unit(units, output_units)
    reference, speed_rad, angle_rad = _reference(speed, angle, rate_unit)
    rec = _read(recording, units, columns, sample_rate, sensitivity, output_units, topic, saturation, no_unit_check)
    win = _windows_from_file(windows, rec)
    noise = _noise_to_internal(noise_std, units, rate_unit, sensitivity)
    if noise_density is not None:
        noise = _density_to_internal(noise_density, noise_std, rec)
    run = run_calibration(rec, speed=speed_rad, angle=angle_rad, method=method.value, windows=win, noise_std=noise,
                          output_units=rate_unit)
    cal = run.calibration
    doc = to_document(cal)
    inputs = (Path(recording), windows)
    check_output(output, inputs=inputs, force=force, replaceable=same_document(doc),
                 holds="a different calibration or another file")
    check_output(plot, flag="--plot", inputs=inputs + (output,), force=True)
    # files first: a reader that closes stdout early (| head) must not cost the outputs
    if plot is not None:
        _save_plot(plot, rec, _windows_of(cal), cal, speed_rad, f"{Path(recording).name}: {reference} reference")
    if output is not None:
        from .._jsonfile import write_json

        write_json(output, doc)
    if example:
        console.print(intro, highlight=False, soft_wrap=True)
    _print_calibration(run, None if truth_path is None else _truth_calibration(truth_path, cal))
    if output is not None:
        console.print(f"wrote {output}" + (f" and {plot}" if plot is not None else ""), highlight=False)


def _windows_of(cal: Calibration) -> list[Window]:
    """The windows a calibration used, back from its file records."""
    out = []
    for d in cal.windows:
        angle = d.get("angle_deg")
        out.append(Window(int(d["start"]), int(d["stop"]), d["kind"], d.get("axis"), int(d.get("sign") or 0),
                          math.nan if angle is None else math.radians(angle),
                          math.nan if d.get("rate") is None else float(d["rate"]), str(d.get("label") or "")))
    return out


def _save_plot(path: Path, rec, windows, cal, speed_rad, title: str) -> None:
    from ..plotting._mpl import save_figure
    from ..plotting.calibration import calibration_figure

    save_figure(calibration_figure(rec, windows, cal, speed=speed_rad, title=title), path)


@app.command()
def segments(
    recording: Annotated[Path, typer.Argument(help="Recording: CSV, Parquet, or a ROS/MCAP bag.")],
    units: Units = None,
    columns: Columns = None,
    sample_rate: SampleRate = None,
    sensitivity: Sensitivity = None,
    output_units: OutputUnits = None,
    topic: Topic = None,
    saturation: Saturation = SaturationName.error,
    no_unit_check: NoUnitCheck = False,
    speed: Speed = None,
    angle: Angle = None,
    windows: WindowsFile = None,
    plot: PlotPath = None,
) -> None:
    """Show the rotation and static windows detected (or read from --windows) and what was ignored and why."""
    from rich.markup import escape
    from rich.table import Table

    units = _required_units(units)
    rate_unit = _rate_unit(units, output_units)
    reference, speed_rad, angle_rad = _reference(speed, angle, rate_unit)
    check_output(plot, flag="--plot", inputs=(recording, windows), force=True)
    rec = _read(recording, units, columns, sample_rate, sensitivity, output_units, topic, saturation, no_unit_check)
    given = _windows_from_file(windows, rec)
    ignored: list = []
    if given is not None:
        found, source = given, f"from {windows}"
    else:
        from ..segmentation import segment

        # Show what was found even when it is not enough to calibrate; warn after the table.
        seg = segment(rec, reference=reference, speed=speed_rad, angle=angle_rad or 2 * math.pi, require=False)
        found, ignored, source = list(seg.windows), list(seg.ignored), "detected"
    disp = "counts" if rec.units == "counts" else rate_unit
    console.print(f"{len(found)} windows {source} in {recording.name} ({len(rec)} samples, {rec.sample_rate:.4g} Hz)",
                  highlight=False, markup=False)
    table = Table()
    for col in ("#", "kind", "turn", "start", "stop", "t0 [s]", "length [s]", "angle [deg]", f"mean rate [{disp}]"):
        table.add_column(escape(col), justify="right" if col not in ("kind", "turn") else "left")
    for i, w in enumerate(found):
        turn = "" if w.kind == "static" else f"{'+' if w.sign > 0 else '-' if w.sign < 0 else ''}{w.axis or '?'}"
        rate = "" if math.isnan(w.rate) else f"{_rate_display(w.rate, rec, disp):.4g}"
        ang = "" if math.isnan(w.angle) else f"{math.degrees(w.angle):.1f}"
        table.add_row(str(i), w.kind, turn, str(w.start), str(w.stop), f"{rec.t[w.start]:.2f}",
                      f"{(w.stop - w.start) / rec.sample_rate:.2f}", ang, rate)
    console.print(table)
    if ignored:
        console.print(f"{len(ignored)} ignored:")
        skipped = Table()
        for col in ("start", "stop", "why"):
            skipped.add_column(col)
        for w, why in ignored:
            skipped.add_row(str(w.start), str(w.stop), why)
        console.print(skipped)
    else:
        console.print("nothing ignored")
    if given is None:
        try:
            seg.require()
        except GyrocalError as exc:
            warn(str(exc))
    if plot is not None:
        from ..plotting._mpl import save_figure
        from ..plotting.calibration import calibration_figure

        save_figure(calibration_figure(rec, found, title=f"{recording.name}: windows {source}"), plot)
        console.print(f"wrote {plot}", highlight=False)


def _rate_display(rate: float, rec, unit: str) -> float:
    """A window's mean rate [internal units] in the display unit."""
    return rate if rec.units == "counts" else float(from_rad_s(rate, unit))


@app.command()
def apply(
    calibration: Annotated[Path, typer.Argument(help="A gyrocal calibration or thermal calibration file.")],
    recording: Annotated[Path, typer.Argument(help="Recording to correct.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Corrected CSV.")],
    units: Units = None,
    columns: Columns = None,
    sample_rate: SampleRate = None,
    topic: Topic = None,
    saturation: Saturation = SaturationName.error,
    no_unit_check: NoUnitCheck = False,
    model: Annotated[ThermalModel, typer.Option("--model", help="Thermal files: interpolation in temperature.")]
    = ThermalModel.lagrange,
    out_of_range: Annotated[OutOfRange, typer.Option(
        "--out-of-range", help="Thermal files: temperatures outside the calibrated range.")] = OutOfRange.refuse,
    force: Annotated[bool, typer.Option("--force", help="Replace an existing output that gyrocal did not write.")]
    = False,
) -> None:
    """Correct a recording; gyro columns are replaced by corrected rates, other columns pass through."""
    from ..export import load_any
    from ..io import write_csv

    check_output(output, inputs=(calibration, recording), force=force, replaceable=starts_with(f"# {_APPLIED}"))
    cal = load_any(calibration)
    expected = cal.input_units
    if units is not None and parse_input_unit(units, "--units") != expected:
        raise InputError(f"--units {units} does not match the calibration's input units {expected}; "
                   f"{calibration} applies to data in {expected}")
    rec = _read(recording, expected, columns, sample_rate, None, None, topic, saturation, no_unit_check)
    if isinstance(cal, Calibration):
        raw = rec.gyro if rec.units == "counts" else from_rad_s(rec.gyro, expected)
        corrected, out_units = cal.apply(raw), cal.output_units
    else:
        corrected, out_units = _apply_thermal(cal, rec, model.value, out_of_range.value), cal.output_units
    cols: dict[str, np.ndarray] = {}
    if rec.has_time:
        cols["t"] = np.asarray(rec.t)
    for i, name in enumerate(("gx", "gy", "gz")):
        cols[name] = corrected[:, i]
    for name in ("temp", "table_rate", "axis"):
        value = getattr(rec, name)
        if value is not None:
            cols[name] = value if name != "table_rate" or rec.units == "counts" else from_rad_s(value, expected)
    for name, value in rec.extra.items():
        cols.setdefault(name, value)
    note = f"{_APPLIED} with {Path(calibration).name}; gx gy gz in {out_units}"
    write_csv(output, cols, header_comment=note)
    console.print(f"wrote {output} ({len(rec)} rows, gx gy gz in {out_units})", highlight=False)


def _apply_thermal(tc, rec, model: str, out_of_range: str) -> np.ndarray:
    """Thermal correction; its warnings become 'warning:' lines, its advice names the CLI flag."""
    from ..errors import OutOfRangeError

    with warnings_as_lines():
        try:
            return tc.apply(rec, model=model, out_of_range=out_of_range)
        except OutOfRangeError as exc:
            raise OutOfRangeError(str(exc).replace("out_of_range=", "--out-of-range ")) from None


@app.command()
def export(
    calibration: Annotated[Path, typer.Argument(help="A gyrocal calibration or thermal calibration file.")],
    format: Annotated[ExportFormatName, typer.Option("--format", help="Output format.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Output file.")],
    force: Force = False,
) -> None:
    """Write a calibration file as JSON, YAML or a C header for firmware."""
    from .._atomic import write_text_atomic
    from ..export import render

    text = render(calibration, format.value)
    check_output(output, inputs=(calibration,), force=force, replaceable=same_text(text))
    write_text_atomic(output, text)
    console.print(f"wrote {output} ({format.value})", highlight=False)
