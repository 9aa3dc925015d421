"""Commands ``calibrate`` and ``segments``: a thin layer over the library.

User units live in this layer (:mod:`gyrocal.cli._references`): ``--speed`` is in the
data's rate unit per second, ``--angle`` in degrees, ``--noise-std`` in the data's unit;
the library gets rad/s and radians.

The commands' own checks raise :class:`~gyrocal.errors.InputError`, so they reach the
user through the same error boundary as library errors (``run``: one line, exit 2).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..choices import Method
from ..errors import GyrocalError, InputError
from ._options import AcceptImplausible, in_unit, noise_density_option
from ._outputs import check_output, same_document
from ._reading import READING, read_from_flags, required_units
from ._references import density_to_internal, noise_to_internal, rate_unit_of, reference_of
from ._station import StationFlags, conclude, finish, station_flags, write_and_store
from .app import app, console, message, warn

__all__ = ["calibrate", "segments"]

EXAMPLE = "example_servo.csv"
EXAMPLE_TRUTH = "example_servo.truth.json"
EXAMPLE_SPEED = 60.0  # deg/s, the servo protocol of Wang et al.


WindowsFile = Annotated[Optional[Path], typer.Option(
    "--windows", help="Windows file (JSON/CSV list, or imucal's section list) that replaces detection "
    "(default: detected).")]
Speed = Annotated[Optional[str], typer.Option(
    "--speed", help="Known constant turn rate, in the data's rate unit unless a unit is written (deg/s with --units "
    "deg/s; --output-units for counts), e.g. 60deg/s or 1.05rad/s (default: none, --angle 360).")]
Angle = Annotated[Optional[float], typer.Option(
    "--angle", help="Known angle of each turn, in degrees; the speed may vary (default: 360 unless --speed).")]
AngleSd = Annotated[Optional[float], typer.Option(
    "--angle-sd", help="Accuracy (1-sigma) of each turn's angle, in degrees: a robot's or turntable's "
    "specification, carried into the 1-sigma (default: none, only what the data show).")]
SpeedSd = Annotated[Optional[str], typer.Option(
    "--speed-sd", help="Accuracy (1-sigma) of the known speed, in the data's rate unit unless a unit is written, as "
    "--speed: one error common to every plateau, so the three k move together (default: none).")]
PlotPath = Annotated[Optional[Path], typer.Option(
    "--plot", help="Write a picture (.png, .pdf or .svg) (default: none).")]
Output = Annotated[Optional[Path], typer.Option(
    "-o", "--output", help="Calibration file to write (default: none; the parameters are printed).")]
Force = Annotated[bool, typer.Option("--force", help="Replace an output that holds a different calibration.")]


def _speed(text: str | None, rate_unit: str) -> float | None:
    """--speed as a number in the data's rate unit: a bare number is in it (its range is checked later), and
    one written with its unit (60deg/s, 1.05rad/s) is converted."""
    if text is None:
        return None
    try:
        return float(text)
    except ValueError:
        return in_unit("--speed", text, rate_unit)


def _windows_from_file(path: Optional[Path], rec):
    if path is None:
        return None
    from ..io import read_windows

    return read_windows(path, sample_rate=rec.sample_rate, t0=float(rec.t[0]), n_samples=len(rec),
                        t=rec.t if rec.has_time else None)


def _example_paths() -> tuple[Path, Path]:
    data = Path(__file__).resolve().parents[1] / "data"  # installed as files, never zipped
    return data / EXAMPLE, data / EXAMPLE_TRUTH


def _params_table(run, truth=None):
    """Rich tables: k, b (the servo method of Wang et al.) in user units with 1-sigma (and the truth,
    for the example), and the canonical correction."""
    from rich.markup import escape
    from rich.table import Table

    cal = run.calibration
    matrix, offset = cal.correction
    table = Table()
    # b is added to the reading (Wang et al., eq. 1): the offset beside it is what the gyro reads at rest
    for col in ("parameter", "estimate", "1-sigma", f"at rest\n[{cal.input_units}]") + (
            ("truth", "error\n/ sigma") if truth is not None else ()):
        table.add_column(escape(col), justify="left" if col == "parameter" else "right", no_wrap=True)
    true_values = None
    if truth is not None:
        from ..pipeline import parameter_rows

        true_values = [value for _, value, _, _ in parameter_rows(truth)]
    for i, (name, value, sigma, unit) in enumerate(run.parameters()):
        rest = f"{offset[i - 3]:+.6g}" if i >= 3 else ""
        row = [escape(f"{name} [{unit}]"), f"{value:.6g}", "n/a" if math.isnan(sigma) else f"{sigma:.2g}", rest]
        if true_values is not None:
            true = float(true_values[i])
            row += [f"{true:.6g}", f"{(value - true) / sigma:+.2f}" if sigma > 0 else "n/a"]
        table.add_row(*row)
    canon = Table()
    for label in ("matrix", "", "", "offset"):
        canon.add_column(label, justify="right", no_wrap=True)
    for r in range(3):
        canon.add_row(*[f"{v:.6g}" for v in matrix[r]], f"{offset[r]:.6g}")
    return table, canon


def _print_calibration(run, truth=None) -> None:
    import numpy as np

    from ..segmentation import describe_found

    cal = run.calibration
    table, canon = _params_table(run, truth)
    ref = run.reference_text(cal.output_units)
    console.print(f"{cal.method}, {ref}: g = diag(k) (m + b), the servo method of Wang et al., eq. 1",
                  highlight=False, soft_wrap=True)
    console.print(table)
    if cal.input_units == "counts" and cal.sensitivity is not None:
        k = np.asarray(cal.model.params[:3])
        console.print(f"k is relative to --sensitivity {cal.sensitivity:g} LSB per {cal.output_units}: the measured "
                      f"sensitivity is {', '.join(f'{cal.sensitivity / v:.5g}' for v in k)} LSB per "
                      f"{cal.output_units} (x, y, z)", highlight=False, soft_wrap=True)
    console.print(f"correction w_true = matrix @ (raw - offset), raw in {cal.input_units}, "
                  f"w_true in {cal.output_units}", highlight=False)
    console.print(canon)
    if cal.noise_std is not None:
        noise = cal.noise_std / cal.input_scale
        console.print(f"per-sample noise behind the 1-sigma: {', '.join(f'{v:.3g}' for v in noise)} {cal.input_units}",
                      highlight=False, soft_wrap=True)
    if (note := run.scale_bias_note()) is not None:
        console.print(f"note: {note} (--method first-moment)", highlight=False, soft_wrap=True)
    n_rot = sum(w.get("kind") == "rotation" for w in cal.windows)
    console.print(f"windows used: {n_rot} rotation, {len(cal.windows) - n_rot} static; found: "
                  f"{describe_found(run.segmentation.windows, run.segmentation.ignored)}", highlight=False, soft_wrap=True)
    _print_checks(run)


def _print_checks(run) -> None:
    """What the self-checks found: time base, fit quality with the largest residuals, notes, warnings."""
    for line in run.time_base.describe() if run.time_base is not None else ():
        console.print(line, highlight=False, soft_wrap=True, markup=False)
    q = run.quality
    if q is None:
        return
    console.print(q.summary(), highlight=False, soft_wrap=True, markup=False)
    if q.dof > 0:
        size = [(sum(v * v for v in z) ** 0.5, i) for i, z in enumerate(q.residuals)]
        top = sorted(size, reverse=True)[:5]
        console.print("  largest residuals [noise sigma]: " + ", ".join(
            f"window {i} ({q.labels[i]}) {' '.join(f'{v:+.2f}' for v in q.residuals[i])}" for _, i in top)
            + f" ({len(size)} windows; all in the file's fit.residuals)", highlight=False, soft_wrap=True, markup=False)
    for note in run.notes:
        console.print(f"note: {note}", highlight=False, soft_wrap=True, markup=False)
    for line in run.warnings:
        warn(line)


def _truth_calibration(path: Path, cal):
    """The example's true model in the units of `cal`, from its truth sidecar."""
    from ..results.calibration import Calibration
    from ..results.files import load
    from ..simulation.truth import SimulationTruth

    truth = load(path, SimulationTruth)
    return Calibration(model=truth.model, input_units=cal.input_units, output_units=cal.output_units,
                       sensitivity=cal.sensitivity)


@app.command()
@station_flags
def calibrate(
    recording: Annotated[Optional[Path], typer.Argument(help="Recording: CSV, Parquet, or a ROS/MCAP bag.")] = None,
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
    time_units: READING.TimeUnits = None,
    nan: READING.Nan = "error",
    speed: Speed = None,
    angle: Angle = None,
    angle_sd: AngleSd = None,
    speed_sd: SpeedSd = None,
    windows: WindowsFile = None,
    method: Annotated[Method, typer.Option("--method", help="Estimator.")] = "first-moment",
    noise_std: Annotated[Optional[str], typer.Option(
        "--noise-std", help="Per-sample noise instead of the one measured, in the data's unit unless a unit is "
        "written, e.g. 0.05deg/s (default: measured).")] = None,
    noise_density: noise_density_option("the one measured in the still parts") = None,
    output: Output = None,
    plot: PlotPath = None,
    force: Force = False,
    accept_implausible: AcceptImplausible = False,
    example: Annotated[bool, typer.Option(
        "--example", help="Run on the bundled simulated MPU9250 servo recording (deg/s, --speed 60 unless "
        "--angle or --windows).")] = False,
    flags: StationFlags = StationFlags(),
) -> None:
    """Estimate scale and bias from a recording of turns; print them with 1-sigma; write the calibration file."""
    # long function: the command's steps in order (flags, reading, fit, outputs, station), each a call of its own
    from ..jobs import run_job

    truth_path = None
    if example:
        if recording is not None:
            raise InputError(f"give a recording or --example, not both (got {recording})")
        recording, truth_path = _example_paths()
        units = units or "deg/s"
        if speed is None and angle is None and windows is None:
            speed = f"{EXAMPLE_SPEED:g}"
        intro = (f"example: {recording}\n  same as: gyrocal calibrate {recording} --units deg/s "
                 + (f"--speed {speed}" if speed is not None else f"--angle {360 if angle is None else angle:g}"))
    if recording is None:
        raise InputError("give a recording to calibrate (or --example for the bundled one)")
    units, read_notes = required_units(units), []
    rate_unit = rate_unit_of(units, output_units)
    speed, speed_sd = _speed(speed, rate_unit), _speed(speed_sd, rate_unit)
    reference, speed_rad, angle_rad, ref_sd = reference_of(speed, angle, rate_unit, speed_sd=speed_sd,
                                                           angle_sd=angle_sd)
    if ref_sd is not None and method != "first-moment":
        raise InputError(f"--{reference}-sd applies to the default method (first-moment), not --method {method}")
    rec = read_from_flags(recording, units=units, columns=columns, skip_rows=skip_rows, sample_rate=sample_rate,
                          sensitivity=sensitivity, output_units=output_units, topic=topic, saturation=saturation,
                          no_unit_check=no_unit_check, imu=imu, time_units=time_units, nan=nan, notes=read_notes)
    noise = noise_to_internal(noise_std, units, rate_unit, sensitivity)
    if noise_density is not None:
        noise = density_to_internal(noise_density, noise_std, rec)
    result = run_job("calibrate", recording=rec, sources=(Path(recording),), windows=windows, speed=speed_rad,
                     angle=angle_rad, method=method, noise_std=noise, output_units=rate_unit, reference_sd=ref_sd,
                     accept_implausible=accept_implausible, notes=tuple(read_notes))
    if result.implausible is not None:
        warn(result.implausible)
    run = result.value
    result, verdict = finish(result, flags)
    check_output(output, inputs=result.inputs, force=force, replaceable=same_document(result.document),
                 holds="a different calibration or another file")
    check_output(plot, flag="--plot", inputs=result.inputs + (output,), outputs=(output,), force=True)
    # files first: a reader that closes stdout early (| head) must not cost the outputs
    if plot is not None:
        from ..plotting import save_figure

        save_figure(result.figures["calibration"](), plot)
    record = write_and_store(result, flags, output, verdict)
    if example:
        console.print(intro, highlight=False, soft_wrap=True)
    _print_calibration(run, None if truth_path is None else _truth_calibration(truth_path, run.calibration))
    if output is not None:
        console.print(f"wrote {output}" + (f" and {plot}" if plot is not None else ""), highlight=False)
    conclude(console, result, flags, record, verdict)


@app.command()
def segments(
    recording: Annotated[Path, typer.Argument(help="Recording: CSV, Parquet, or a ROS/MCAP bag.")],
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
    speed: Speed = None,
    angle: Angle = None,
    windows: WindowsFile = None,
    plot: PlotPath = None,
) -> None:
    """Show the rotation and static windows detected (or read from --windows) and what was ignored and why."""
    # long function: the command's output in the order it is printed (time base, windows, what was ignored)
    from rich.markup import escape
    from rich.table import Table

    units = required_units(units)
    rate_unit = rate_unit_of(units, output_units)
    speed = _speed(speed, rate_unit)
    reference, speed_rad, angle_rad, _ = reference_of(speed, angle, rate_unit)
    check_output(plot, flag="--plot", inputs=(recording, windows), force=True)
    rec = read_from_flags(recording, units=units, columns=columns, skip_rows=skip_rows, sample_rate=sample_rate,
                          sensitivity=sensitivity, output_units=output_units, topic=topic, saturation=saturation,
                          no_unit_check=no_unit_check, imu=imu)
    given = _windows_from_file(windows, rec)
    ignored: list = []
    seg = None
    if given is not None:
        from ..segmentation import given_windows, standstill_level

        found, source, baseline = given, f"from {windows}", standstill_level(rec, given)
        if reference == "angle":  # each turn's declared angle beside its measured one; the contradicted ones left out
            seg = given_windows(rec, given, "angle", None, angle_rad or 2 * math.pi)
            found, ignored = list(seg.windows), list(seg.ignored)
    else:
        from ..segmentation import segment

        # Show what was found even when it is not enough to calibrate; warn after the table.
        seg = segment(rec, reference=reference, speed=speed_rad, angle=angle_rad or 2 * math.pi, require=False)
        found, ignored, source, baseline = list(seg.windows), list(seg.ignored), "detected", seg.baseline
    tb = rec.time_base()
    times = tb.clock_times()
    times = rec.t if times is None else times
    disp = "counts" if rec.units == "counts" else rate_unit
    declared = (f"{speed:g} {rate_unit}" if reference == "speed" else f"{360.0 if angle is None else angle:g} deg")
    console.print(f"{len(found)} windows {source} in {recording.name} ({len(rec)} samples, {rec.sample_rate:.4g} Hz); "
                  f"declared {reference} {declared}; angles and rates below are measured (raw readings, standstill "
                  "level removed, before calibration)", highlight=False, markup=False, soft_wrap=True)
    for line in tb.describe():
        console.print(line, highlight=False, markup=False, soft_wrap=True)
    angle_unit = "counts s" if rec.units == "counts" else "deg"
    table = Table()
    shown = given is not None and reference == "angle"  # a windows file's declared angles, beside the measured
    for col in ("#", "kind", "turn", "start", "stop", "t0 [s]", "length [s]") + (("declared [deg]",) if shown else ()) + (
            f"angle [{angle_unit}]", f"mean rate [{disp}]"):
        table.add_column(escape(col), justify="right" if col not in ("kind", "turn") else "left", no_wrap=True)
    for w in found:
        i = next(j for j, g in enumerate(given) if g.start == w.start) if given is not None else found.index(w)
        table.add_row(str(i), w.kind, _turn(w), str(w.start), str(w.stop), f"{rec.t[w.start]:.2f}",
                      f"{times[w.stop - 1] - times[w.start]:.2f}", *((_declared(w),) if shown else ()),
                      *_measured(rec, w, baseline, times, disp))
    console.print(table)
    if ignored:
        console.print(f"{len(ignored)} ignored:")
        skipped = Table()
        for col in ("start", "stop", "turn", f"angle [{angle_unit}]", f"mean rate [{disp}]", "why"):
            # numbers never wrap; the reason, words, may
            skipped.add_column(escape(col), justify="left" if col in ("turn", "why") else "right", no_wrap=col != "why")
        for w, why in ignored:
            skipped.add_row(str(w.start), str(w.stop), _turn(w), *_measured(rec, w, baseline, times, disp), why)
        console.print(skipped)
    else:
        console.print("nothing ignored")
    try:
        seg is None or seg.require()
    except GyrocalError as exc:
        warn(message(exc))
    for line in () if seg is None else seg.warnings:
        warn(line)
    if plot is not None:
        from ..plotting import save_figure
        from ..plotting.calibration import calibration_figure

        save_figure(calibration_figure(rec, found, title=f"{recording.name}: windows {source}", ignored=ignored), plot)
        console.print(f"wrote {plot}", highlight=False)


def _declared(w) -> str:
    return "" if w.kind == "static" else f"{math.degrees(w.angle):g}"


def _turn(w) -> str:
    return "" if w.kind == "static" else f"{'+' if w.sign > 0 else '-' if w.sign < 0 else ''}{w.axis or '?'}"


def _measured(rec, w, baseline, times, unit: str) -> tuple[str, str]:
    """A rotation window's measured angle and mean rate, as printed (blank for a static window)."""
    from ..segmentation import measure_turn
    from ..units import from_rad_s

    if w.kind == "static":
        return "", ""
    angle, rate = measure_turn(rec, w, baseline, times)
    if rec.units == "counts":
        return f"{angle:.4g}", f"{rate:.4g}"
    return f"{math.degrees(angle):.1f}", f"{float(from_rad_s(rate, unit)):.4g}"
