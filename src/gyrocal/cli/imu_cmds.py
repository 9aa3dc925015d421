"""Command ``imu``: calibrate a whole IMU (gyro and accelerometer) from a hand session."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..choices import AccelModel, AccelOutputUnit, ImuGyroModel
from ._outputs import check_output, same_document
from ._reading import READING, read_from_flags, required_units
from .app import app, console, warn

__all__ = ["imu"]

#: Full-scale settings of common MEMS parts: LSB per deg/s and LSB per g (MPU-6050/9250, ICM-20xxx).
GYRO_SETTINGS = {131.0: "±250 °/s", 65.5: "±500 °/s", 32.8: "±1000 °/s", 16.4: "±2000 °/s"}
ACCEL_SETTINGS = {16384.0: "±2 g", 8192.0: "±4 g", 4096.0: "±8 g", 2048.0: "±16 g"}


def _nearest(value: float, settings: dict[float, str]) -> str:
    best = min(settings, key=lambda s: abs(math.log(value / s)))
    off = value / best - 1
    return f"{settings[best]} ({best:g} LSB) is {off:+.1%} away" if abs(off) < 0.15 else "no common setting within 15 %"


def _print_accel(run) -> None:
    from ..imu.run import accel_scale

    a, part = run.result.accel, run.calibration.accelerometer
    units = part["units"]
    matrix, offset = part["correction"]["matrix"], part["correction"]["offset"]
    c_in = accel_scale(units["input"], units["sensitivity"], units["gravity"])
    console.print(f"accelerometer: {a.model} model, a_true = matrix @ (raw - offset), raw in {units['input']}, "
                  f"a_true in {units['output']}; |a_true| = {units['gravity']:g} m/s^2 at rest", highlight=False,
                  soft_wrap=True)
    for line in a.choice:
        console.print(f"  model: {line}", highlight=False, soft_wrap=True, markup=False)
    std = dict(zip(a.param_names, a.std))
    d_out = 1.0 if units["output"] == "m/s^2" else units["gravity"]
    sigma = [[std.get(f"A_{r}{c}", 0.0) * c_in / d_out for c in "xyz"] for r in "xyz"]
    console.print(_matrix_table(matrix, sigma, offset, [std[f"o_{r}"] / c_in for r in "xyz"], units["input"]))
    axes = a.sensor_axes()
    sens = ", ".join(f"{k[-1]} {axes[k][0]:.6g} ±{axes[k][1]:.2g}" for k in ("sens_x", "sens_y", "sens_z"))
    angles = ", ".join(f"{k[-2:]} {axes[k][0]:.4f} ±{axes[k][1]:.2g}" for k in ("angle_xy", "angle_xz", "angle_yz"))
    console.print(f"  sensor axes (frame-free): reading per m/s^2 along each axis {sens}; angles between axes [deg] "
                  f"{angles}", highlight=False, soft_wrap=True, markup=False)
    if units["input"] == "counts" and units["sensitivity"] is None:
        lsb = [axes[f"sens_{k}"][0] * units["gravity"] for k in "xyz"]
        console.print("  implied sensitivity: " + ", ".join(f"{v:.5g} LSB/g" for v in lsb) + "; nearest setting: "
                      + _nearest(float(sum(lsb) / 3), ACCEL_SETTINGS), highlight=False, soft_wrap=True)
    console.print(f"  fit: {_summary(a.fit)}", highlight=False, soft_wrap=True, markup=False)


def _matrix_table(matrix, matrix_std, offset, offset_std, input_units: str):
    """Rows x, y, z: the correction matrix and offset, each entry with its 1-sigma."""
    from rich import box
    from rich.markup import escape
    from rich.table import Table

    table = Table(box=box.SIMPLE_HEAD, pad_edge=False)
    for col in ("axis", "matrix x", "matrix y", "matrix z", escape(f"offset [{input_units}]")):
        table.add_column(col, justify="right")
    for r, axis in enumerate("xyz"):
        table.add_row(axis, *(f"{matrix[r][c]:.6g}" for c in range(3)), f"{offset[r]:.6g}")
        table.add_row("±1σ", *(f"{matrix_std[r][c]:.2g}" if matrix_std[r][c] > 0 else "" for c in range(3)),
                      f"{offset_std[r]:.2g}", style="dim")
    return table


def _summary(q) -> str:
    if q.dof == 0:
        return f"chi2 {q.chi2:.3g}, no spare equations"
    scaled = ", 1-sigma scaled by it" if q.covariance_scaled else ""
    return f"chi2 {q.chi2:.4g} for {q.dof} dof (p = {q.p_value:.2g}), Birge ratio {q.birge_ratio:.3g}{scaled}"


def _print_gyro(run) -> None:
    import numpy as np

    g, cal = run.result.gyro, run.calibration
    matrix, offset = cal.correction
    c, d = cal.input_scale, {"rad/s": 1.0, "deg/s": math.pi / 180}[cal.output_units]
    console.print(f"gyro: {g.model} model, w_true = matrix @ (raw - offset), raw in {cal.input_units}, w_true in "
                  f"{cal.output_units}", highlight=False, soft_wrap=True)
    for line in g.choice:
        console.print(f"  model: {line}", highlight=False, soft_wrap=True, markup=False)
    n = 9 if g.model == "affine" else 3
    a_std = np.zeros((3, 3))
    a_std[(np.ones((3, 3), bool) if n == 9 else np.eye(3, dtype=bool))] = g.std[:n]
    console.print(_matrix_table(matrix, a_std * c / d, offset, g.std[n:n + 3] / c, cal.input_units))
    if g.g_sensitivity is not None:
        gs = g.g_sensitivity / c
        console.print(f"  g-sensitivity [{cal.input_units} per m/s^2]: "
                      + "; ".join(" ".join(f"{v:.3g}" for v in row) for row in gs)
                      + f" (1-sigma up to {g.std[-9:].max() / c:.2g})", highlight=False, soft_wrap=True)
    if cal.input_units == "counts" and cal.sensitivity is None:
        lsb = 1.0 / np.diag(g.matrix) * math.pi / 180
        console.print("  implied sensitivity: " + ", ".join(f"{v:.5g} LSB/(deg/s)" for v in lsb) + "; nearest "
                      "setting: " + _nearest(float(np.mean(lsb)), GYRO_SETTINGS), highlight=False, soft_wrap=True)
    factors = ", ".join(f"{k} {v:.3g}" for k, v in g.noise_factors.items())
    console.print(f"  fit: {_summary(g.fit)}; scatter over the noise model: {factors}", highlight=False,
                  soft_wrap=True, markup=False)
    _print_pairs(g)


def _print_pairs(g) -> None:
    import numpy as np

    pairs = list(g.checks)
    if not pairs:
        return
    worst = max(pairs, key=lambda c: c.chi2)
    misfit = np.array([c.residual_deg for c in pairs])
    bad = [c.label for c in pairs if c.disagrees]
    console.print(f"  turns between poses: {len(pairs)}; misfit median {np.median(misfit):.2g} deg, largest "
                  f"{worst.residual_deg:.2g} deg ({worst.label}); "
                  + (f"disagreeing: {', '.join(bad)}" if bad else "none disagrees")
                  + (f"; left out: {', '.join(g.left_out)}" if g.left_out else ""), highlight=False, soft_wrap=True,
                  markup=False)


def _print_poses(run) -> None:
    r = run.result
    cov = r.coverage
    where = " ".join(f"{v:+.2f}" for v in cov.empty_cap_centre)
    source = "from --windows" if r.detection is None else "detected"
    console.print(f"{len(r.statics)} still poses {source} ({cov.poses} distinct orientations), a {r.kind} session; "
                  f"they cover the sphere with spread {cov.spread:.2f} of 1, largest empty cap {cov.empty_cap_deg:.0f}"
                  f" deg around ({where})", highlight=False, soft_wrap=True)


@app.command()
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
    accel_units: READING.AccelUnits = None,
    accel_sensitivity: READING.AccelSensitivity = None,
    gravity: READING.Gravity = 9.80665,
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
    accel_output_units: Annotated[AccelOutputUnit, typer.Option(
        "--accel-output-units", help="Unit of corrected accelerations.")] = "m/s^2",
    output: Annotated[Optional[Path], typer.Option(
        "-o", "--output", help="Calibration file to write (default: none, print only).")] = None,
    plot: Annotated[Optional[Path], typer.Option(
        "--plot", help="Picture of the poses on the sphere and each turn's misfit (.png, .pdf, .svg) "
        "(default: none).")] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace an output that holds another calibration.")]
    = False,
) -> None:
    """Calibrate gyro and accelerometer together from still poses and hand turns (no turntable needed)."""
    from ..errors import InputError
    from ..imu.run import calibrate_recording

    units = required_units(units)
    if accel_units is None:
        raise InputError("{param} is required: m/s^2, g or counts (the unit of the accelerometer columns)",
                         param="accel_units")
    if accel_columns is not None and accel_log is None:
        raise InputError("--accel-columns is for --accel-log; map the recording's own columns with --columns ax=...")
    check_output(plot, flag="--plot", inputs=(recording, windows, output, accel_log), force=True)
    rec = read_from_flags(recording, units=units, columns=columns, skip_rows=skip_rows, sample_rate=sample_rate,
                          sensitivity=sensitivity, output_units=output_units, topic=topic, saturation=saturation,
                          no_unit_check=no_unit_check, accel_units=None if accel_log else accel_units,
                          accel_sensitivity=None if accel_log else accel_sensitivity, gravity=gravity,
                          need_accel=accel_log is None)
    if accel_log is not None:
        from ..io import attach_accelerometer

        rec = attach_accelerometer(rec, accel_log, accel_units=accel_units, columns=accel_columns, skip_rows=skip_rows,
                                   sample_rate=sample_rate, accel_sensitivity=accel_sensitivity, gravity=gravity)

    win = None
    if windows is not None:
        from ..io import read_windows

        win = read_windows(windows, sample_rate=rec.sample_rate, t0=float(rec.t[0]), n_samples=len(rec),
                           t=rec.t if rec.has_time else None)
    run = calibrate_recording(rec, windows=win, gravity=gravity, accel_model=accel_model, gyro_model=gyro_model,
                              g_sensitivity=g_sensitivity, min_static=min_static, output_units=output_units,
                              accel_output_units=accel_output_units)
    doc = run.calibration.to_document()
    check_output(output, inputs=(recording, windows, accel_log), force=force, replaceable=same_document(doc),
                 holds="a different calibration or another file")
    if plot is not None:
        from ..plotting import save_figure
        from ..plotting.imu import poses_figure

        save_figure(poses_figure(run.result, title=f"{recording.name}: whole-IMU calibration"), plot)
    if output is not None:
        from ..files import save

        save(run.calibration, output)
    for line in run.time_base.describe():
        console.print(line, highlight=False, soft_wrap=True, markup=False)
    _print_poses(run)
    _print_accel(run)
    _print_gyro(run)
    for line in run.warnings:
        warn(line)
    if output is not None:
        console.print(f"wrote {output}" + (f" and {plot}" if plot is not None else ""), highlight=False)
