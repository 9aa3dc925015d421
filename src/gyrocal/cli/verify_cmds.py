"""Commands ``verify`` and ``compare``: proof on the bench.

``verify`` repeats the validation of the servo method of Wang et al. (Tables IV-V,
Figs. 7-10): the calibrated gyro against a reference gyro that recorded the same motion
on its own clock and mount. ``compare`` sets calibrations of one unit side by side in
units of their 1-sigma; with ``--tolerance`` it is a production check (exit 0 within,
1 not, 2 bad input).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..choices import OutOfRange, TableModel
from ..errors import InputError
from ._options import given
from ._outputs import check_output, refuse_swapped
from ._reading import READING, ReadingFlags, prefixed_params, read_from_flags, required_units
from .app import app, console, warn

__all__ = ["compare", "verify"]

REF = ReadingFlags("ref-")
#: Files ``verify`` writes into its folder (rewritten on every run).
OUTPUTS = ("verify.json", "summary.md", "before.png", "after.png", "errors.png")
#: Its figures: removed when a run does not draw them, so that none is left from an earlier run.
FIGURES = OUTPUTS[2:]
EXAMPLE_TEST = "example_servo_repeat.csv"  # tools/make_example.py: the testing period
EXAMPLE_REFERENCE = "example_servo_reference.csv"


def _stretch(text: str | None) -> tuple[float, float] | None:
    """``T0:T1`` [s on the test clock] as numbers."""
    if text is None:
        return None
    try:
        lo, hi = (float(x) for x in text.split(":"))
    except ValueError:
        raise InputError(f"{{param}} must be two times in seconds as T0:T1, got {text!r}", param="stretch") from None
    if not lo < hi:
        raise InputError(f"{{param}} must run forward (T0 < T1), got {text!r}", param="stretch")
    return lo, hi


def _read_test(path: Path, cal, units, columns, skip_rows, sample_rate, topic, saturation, no_unit_check, imu):
    """The test log: rates in any rate unit (they are physical), or counts for a counts calibration,
    with its sensitivity when it has one (so the raw rates before calibration are known)."""
    from ..units import parse_input_unit

    unit = cal.input_units if units is None else parse_input_unit(units, "units")
    sensitivity = getattr(cal, "sensitivity", None)
    if unit == "counts" and cal.input_units != "counts":
        raise InputError(f"the calibration applies to rates in {cal.input_units}, not to raw counts", param="units",
                         hint=f"give {{param}} {cal.input_units} (or any rate unit) for the test log")
    if unit != "counts" and cal.input_units == "counts" and sensitivity is None:
        raise InputError("the calibration works on raw counts without a sensitivity", param="units",
                         hint="read the test log as {param} counts")
    return read_from_flags(path, units=unit, columns=columns, skip_rows=skip_rows, sample_rate=sample_rate,
                           sensitivity=sensitivity if unit == "counts" else None,
                           output_units=cal.output_units if unit == "counts" and sensitivity else None, topic=topic,
                           saturation=saturation, no_unit_check=no_unit_check, imu=imu)


def _read_reference(path: Path, units, columns, skip_rows, sample_rate, sensitivity, topic, saturation, no_unit_check):
    """The reference log in rates; its flags carry the prefix ``--ref-`` in every message."""
    with prefixed_params("ref_"):
        unit = required_units(units)
        if unit == "counts" and sensitivity is None:
            raise InputError("the reference log is in counts; its rates are needed", param="sensitivity",
                             hint="give {param} in LSB per deg/s")
        return read_from_flags(path, units=unit, columns=columns, skip_rows=skip_rows, sample_rate=sample_rate,
                               sensitivity=sensitivity, topic=topic, saturation=saturation,
                               no_unit_check=no_unit_check)


def _print_report(report) -> None:
    from rich.table import Table

    from ..verify.report import AXES
    from ..verify.summary import format_pm

    v, s, unit = report.metrics.values, report.metrics.std, report.units
    table = Table(title=f"MSE against the reference, ({unit})^2, as in Table V of the servo method of Wang et al.")
    # short headers over their meaning, so the table fits 80 columns
    for col in ("axis", "before\ncalibration", "after\ncalibration", "reduction\n%", "after, net of\nref. floor"):
        table.add_column(col, justify="right", no_wrap=True)
    for j, ax in enumerate(AXES):
        table.add_row(ax, format_pm(v["mse_before"][j], s["mse_before"][j]), format_pm(v["mse_after"][j], s["mse_after"][j]),
                      format_pm(v["reduction_pct"][j], s["reduction_pct"][j]),
                      format_pm(v["mse_after_net"][j], s["mse_after_net"][j]))
    console.print(table)
    a = report.alignment
    drift = format_pm(a.clock_drift_ppm, a.std[1], "ppm") if a.drift_fitted else "held at 0 ppm"
    console.print(f"clocks: time_offset_s {format_pm(a.time_offset_s, a.std[0], 's')}, clock_drift_ppm {drift}; "
                  f"mounting rotation {format_pm(a.rotation_deg, a.rotation_deg_std, 'deg')}; "
                  f"{a.n_samples} samples over {a.overlap_s:.1f} s compared", highlight=False, soft_wrap=True)


def _write_outputs(folder: Path, result, stretch, figures: bool) -> list[Path]:
    """Write the verify job's files into `folder`, all or none: each goes to a temporary beside its target
    and every one moves into place only once all are written. Figures an earlier run left there and this
    run does not draw (``--no-figures``, or no raw readings for before.png) are removed then, so the folder
    never mixes two runs; only gyrocal's own figure names are touched."""
    import contextlib

    from .._atomic import atomic_path, write_text_atomic
    from .._jsonfile import write_json
    from ..verify.summary import summary_markdown

    report, series = result.value
    writers = {"verify.json": lambda path: write_json(path, result.document),
               "summary.md": lambda path: write_text_atomic(path, summary_markdown(report))}
    if figures:  # a stretch outside the logs is refused before anything is written
        from ..plotting import save_figure
        from ..plotting.verify import check_stretch

        check_stretch(series.t, stretch)
        for name, draw in result.figures.items():  # before (when the raw readings are known), after, errors
            writers[f"{name}.png"] = lambda path, draw=draw: save_figure(draw(), path)
    folder.mkdir(parents=True, exist_ok=True)
    with contextlib.ExitStack() as stack:
        for name, write in writers.items():
            write(stack.enter_context(atomic_path(folder / name)))
    for name in FIGURES:
        if name not in writers:
            (folder / name).unlink(missing_ok=True)
    return [folder / name for name in writers]


def _example(test: Path | None, reference: Path | None) -> tuple[Path, Path]:
    """The bundled testing period of the example and its reference log."""
    from importlib import resources

    if test is not None or reference is not None:
        raise InputError("give TEST and --reference, or --example for the bundled pair, not both")
    data = resources.files("gyrocal") / "data"
    return Path(str(data / EXAMPLE_TEST)), Path(str(data / EXAMPLE_REFERENCE))


@app.command()
def verify(
    ctx: typer.Context,
    calibration: Annotated[Path, typer.Argument(help="A gyrocal calibration or thermal calibration file.")],
    test: Annotated[Optional[Path], typer.Argument(
        help="Log of the calibrated gyro (raw readings) during the motion (required unless --example).")] = None,
    reference: Annotated[Optional[Path], typer.Option(
        "--reference", help="Log of the reference gyro during the same motion (required unless --example).")] = None,
    output: Annotated[Path, typer.Option("-o", "--output", help="Folder for verify.json, summary.md and figures.")]
    = Path("verify"),
    units: READING.UnitsOfCalibration = None,
    columns: READING.Columns = None,
    skip_rows: READING.SkipRows = None,
    sample_rate: READING.SampleRate = None,
    topic: READING.Topic = None,
    saturation: READING.Saturation = "error",
    no_unit_check: READING.NoUnitCheck = False,
    imu: READING.Imu = None,
    ref_units: REF.Units = None,
    ref_columns: REF.Columns = None,
    ref_skip_rows: REF.SkipRows = None,
    ref_sample_rate: REF.SampleRate = None,
    ref_sensitivity: REF.SensitivityDegS = None,
    ref_topic: REF.Topic = None,
    ref_saturation: REF.Saturation = "error",
    ref_no_unit_check: REF.NoUnitCheck = False,
    model: Annotated[TableModel, typer.Option("--model", help="Thermal files: evaluation in temperature.")]
    = "lagrange",
    out_of_range: Annotated[OutOfRange, typer.Option(
        "--out-of-range", help="Thermal files: temperatures outside the calibrated range.")] = "refuse",
    no_drift: Annotated[bool, typer.Option(
        "--no-drift", help="Hold the clock drift at 0 (both logs stamped by one clock).")] = False,
    stretch: Annotated[Optional[str], typer.Option(
        "--stretch", help="Time span of the figures, T0:T1 [s on the test clock] (default: all, or the busiest "
                          "minute of a long log).")] = None,
    figures: Annotated[bool, typer.Option("--figures/--no-figures", help="Draw before.png, after.png, errors.png.")]
    = True,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the bootstrap.", min=0)] = 0,
    replicates: Annotated[int, typer.Option("--replicates", help="Bootstrap replicates.", min=50)] = 1000,
    example: Annotated[bool, typer.Option(
        "--example", help="Use the bundled testing period of the example (the servo method of Wang et al.'s "
                          "MPU9250, repeating its turns) and its reference log (deg/s, 100 Hz, own clock).")] = False,
) -> None:
    """Check a calibration against a reference gyro that recorded the same motion (two clocks, two mounts)."""
    from ..jobs import run_job
    from ..results.files import load_correction

    if example:
        test, reference = _example(test, reference)
        units, ref_units = units or "deg/s", ref_units or "deg/s"
        console.print(f"example: {test.name} with the reference {reference.name}\n  same as: gyrocal verify "
                      f"{calibration} {test} --reference {reference} --ref-units deg/s -o {output}", highlight=False,
                      soft_wrap=True)
    if test is not None:
        refuse_swapped(calibration, test, command="verify", usage="calibration file comes")
    if test is None or reference is None:
        raise InputError("give the test log and --reference REF (or --example for the bundled pair)")
    check_output(output, folder=True, inputs=(calibration, test, reference))
    if test.exists() and reference.exists() and test.samefile(reference):
        raise InputError(f"--reference {reference} is the test log itself; give the reference gyro's own log of the "
                         "same motion")
    span = _stretch(stretch)
    cal = load_correction(calibration)
    rec = _read_test(test, cal, units, columns, skip_rows, sample_rate, topic, saturation, no_unit_check, imu)
    ref = _read_reference(reference, ref_units, ref_columns, ref_skip_rows, ref_sample_rate, ref_sensitivity,
                          ref_topic, ref_saturation, ref_no_unit_check)
    options = {name: value for name, value in (("model", model), ("out_of_range", out_of_range)) if given(ctx, name)}
    inputs = {"calibration": calibration.name, "test": test.name, "reference": reference.name}
    result = run_job("verify", calibration=cal, test=rec, reference=ref, seed=seed, fit_drift=not no_drift,
                     replicates=replicates, names=inputs, apply_options=options, stretch=span)
    written = _write_outputs(output, result, span, figures)
    _print_report(result.value[0])
    for line in result.warnings:
        warn(line)
    console.print("wrote " + ", ".join(str(p) for p in written), highlight=False, soft_wrap=True)


def _print_comparison(comparison) -> None:
    from rich.table import Table

    from ..verify.summary import format_pm

    table = Table()
    table.add_column("parameter", no_wrap=True)
    table.add_column("unit", no_wrap=True)
    for label in comparison.labels:
        table.add_column(label, justify="right", no_wrap=True)
    for label in comparison.labels[1:]:
        table.add_column(f"z {label}", justify="right", no_wrap=True)
    for i, name in enumerate(comparison.names):
        cells = [format_pm(comparison.values[f, i], comparison.std[f, i]) for f in range(len(comparison.labels))]
        zs = [f"{z:+.2f}" if math.isfinite(z) else "-" for z in comparison.z[:, i]]
        table.add_row(name, comparison.units[i], *cells, *zs)
    console.print(table)
    console.print("z: difference from the first file over the combined 1-sigma sqrt(s1^2 + s2^2)", highlight=False)


@app.command()
def compare(
    files: Annotated[list[Path], typer.Argument(help="Two or more calibration files (or thermal files) of one unit.")],
    tolerance: Annotated[Optional[float], typer.Option(
        "--tolerance", help="Production check: exit 0 when every parameter of every file is within this many "
                            "combined 1-sigma of the first file, 1 when not (default: none; print the comparison, exit 0).",
        min=0.0)] = None,
) -> None:
    """Compare calibrations of one unit (power cycles, days, rigs) in units of their combined 1-sigma."""
    from ..results.files import load
    from ..verify.compare import compare_calibrations

    if len(files) < 2:
        raise InputError("compare needs at least two files: the first is the one the others are compared with")
    labels = [str(p) if [q.name for q in files].count(p.name) > 1 else p.name for p in files]
    comparison = compare_calibrations([load(p) for p in files], labels)
    _print_comparison(comparison)
    verdicts = comparison.verdicts(tolerance)
    for line in verdicts:
        console.print(line, highlight=False, soft_wrap=True)
    if tolerance is not None and not comparison.within(tolerance).all():
        raise typer.Exit(code=1)
