"""The verification report as Markdown, laid out like the servo method of Wang et al.'s Table V."""

from __future__ import annotations

import math

import numpy as np

from .report import AXES, VerifyReport

__all__ = ["format_pm", "summary_markdown"]


def format_pm(value: float, std: float, unit: str = "") -> str:
    """``value ± std`` with the 1-sigma to two significant digits and the value to match."""
    suffix = f" {unit}" if unit else ""
    if not math.isfinite(value):
        return "n/a"
    if not (math.isfinite(std) and std > 0):
        return f"{value:.4g}{suffix}"
    decimals = max(0, 1 - math.floor(math.log10(std)))
    if decimals > 12:
        return f"{value:.4g} ± {std:.2g}{suffix}"
    return f"{value:.{decimals}f} ± {std:.{decimals}f}{suffix}"


def _axis_table(report: VerifyReport) -> list[str]:
    v, s, unit = report.metrics.values, report.metrics.std, report.units
    lines = [(f"| Axis | Error before calibration, MSE ({unit})² | Error after calibration, MSE ({unit})² | "
             "Reduction |"), "|---|---|---|---|"]
    for j, ax in enumerate(AXES):
        lines.append(f"| {ax} | {format_pm(v['mse_before'][j], s['mse_before'][j])} | "
                     f"{format_pm(v['mse_after'][j], s['mse_after'][j])} | "
                     f"{format_pm(v['reduction_pct'][j], s['reduction_pct'][j], '%')} |")
    return lines


def _detail_table(report: VerifyReport) -> list[str]:
    v, s, unit = report.metrics.values, report.metrics.std, report.units
    cols = (("rmse_before", f"RMSE before ({unit})"), ("rmse_after", f"RMSE after ({unit})"),
            ("p99_before", f"99th pct. before ({unit})"), ("p99_after", f"99th pct. after ({unit})"),
            ("reference_floor", f"reference floor, MSE ({unit})²"),
            ("mse_after_net", f"MSE after, net of floor ({unit})²"))
    lines = ["| Axis | " + " | ".join(title for _, title in cols) + " |", "|---" * (len(cols) + 1) + "|"]
    for j, ax in enumerate(AXES):
        lines.append(f"| {ax} | " + " | ".join(format_pm(v[k][j], s[k][j]) for k, _ in cols) + " |")
    return lines


def _alignment_table(report: VerifyReport) -> list[str]:
    a = report.alignment
    std = a.std
    drift = format_pm(a.clock_drift_ppm, std[1], "ppm") if a.drift_fitted else "0 ppm (held)"
    small = np.degrees(std[2:])
    rows = [
        ("time offset `time_offset_s`", format_pm(a.time_offset_s, std[0], "s")),
        ("clock drift `clock_drift_ppm`", drift),
        ("offset at the test log's centre", format_pm(a.offset_at_centre_s, a.offset_at_centre_std_s, "s")),
        ("mounting rotation angle", format_pm(a.rotation_deg, a.rotation_deg_std, "deg")),
        ("mounting rotation 1-sigma about test x, y, z", ", ".join(f"{x:.2g}" for x in small) + " deg"),
        ("rate-magnitude correlation", f"{a.correlation_peak:.3f}"),
        ("samples compared", f"{a.n_samples} over {a.overlap_s:.1f} s"),
    ]
    lines = ["| | |", "|---|---|"] + [f"| {name} | {value} |" for name, value in rows]
    matrix = "; ".join("[" + ", ".join(f"{x:+.5f}" for x in row) + "]" for row in a.mounting_rotation)
    lines += ["", f"`mounting_rotation` (reference frame to test frame): [{matrix}]"]
    return lines


def summary_markdown(report: VerifyReport, title: str = "Verification against a reference gyro") -> str:
    """The report as a Markdown page: Table V of the paper first, then the detail."""
    inputs = report.inputs
    what = ""
    if {"calibration", "test", "reference"} <= set(inputs):
        what = (f"`{inputs['calibration']}` applied to `{inputs['test']}`, compared with the reference "
                f"`{inputs['reference']}` at the test log's own sample times. ")
    noise = ", ".join(format_pm(x, e) for x, e in zip(report.reference_noise, report.reference_noise_std))
    test_noise = ", ".join(f"{x:.3g}" for x in report.test_noise)
    out = [f"# {title}", "",
           what + "Clocks: `t_test = t_ref * (1 + clock_drift_ppm * 1e-6) + time_offset_s`; "
           "frames: `w_test = mounting_rotation @ w_ref`. Every ± is one standard deviation.", "",
           "## MSE between the gyro and the reference (as in Table V of the servo method of Wang et al.)", ""]
    out += _axis_table(report)
    out += ["", "## Per axis", ""] + _detail_table(report)
    out += ["", ("The reference floor is the MSE its own white noise adds after interpolation; it is in every MSE "
            "above, before and after calibration."), "", "## Alignment", ""] + _alignment_table(report)
    out += ["", "## Noise", "",
            f"- reference, per reference axis: {noise} {report.units}",
            f"- test after calibration, per test axis: {test_noise} {report.units}",
            (f"- 1-sigma of the error figures: block bootstrap, {report.metrics.replicates} replicates of "
            f"{report.metrics.blocks} blocks of {report.metrics.block} samples (seed {report.seed})")]
    if report.warnings:
        out += ["", "## Warnings", ""] + [f"- {w}" for w in report.warnings]
    return "\n".join(out) + "\n"
