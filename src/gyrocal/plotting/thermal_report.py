"""The evaluation report of a thermal table (the full-temperature-range method): CSV and Markdown
tables and figures in one folder. It writes files, so it lives outside the method package.

Files written (units: the calibration's output unit unless told):

* ``summary.csv`` / ``summary.md``: mean and RMS error per rotating axis and gyro axis
  for the uncompensated, traditional, Lagrange and smooth compensations (Tables 3-4),
  and the Lagrange-versus-smooth leave-one-temperature-out comparison;
* ``by_temperature.csv``: RMS error at each test temperature per method;
* ``steps.csv``: every test step's error per method and gyro axis;
* ``loto.csv``: the leave-one-temperature-out comparison per Kg element;
* ``coefficients.png``, ``error_vs_rate.png``, ``error_vs_temperature.png`` (needs matplotlib).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .._atomic import write_text_atomic
from ..thermal.evaluate import METHODS, Evaluation, loto_comparison
from ..thermal.model import ThermalCalibration

__all__ = ["markdown_table", "write_report"]


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def markdown_table(rows: list[dict], columns: list[str] | None = None) -> str:
    """A GitHub Markdown table of `rows` (numbers to 4 significant digits)."""
    if not rows:
        return "_no rows_\n"
    cols = columns or list(rows[0])
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(_fmt(r[c]) for c in cols) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def _write_rows(path: Path, rows: list[dict]) -> None:
    from ..io import write_csv

    if rows:
        write_csv(path, {k: np.array([r[k] for r in rows]) for k in rows[0]})


#: The figures a report draws (removed from the folder by a report without figures).
FIGURES = ("coefficients.png", "error_vs_rate.png", "error_vs_temperature.png")


def write_report(cal: ThermalCalibration, evaluation: Evaluation, out_dir: str | os.PathLike, *,
                 units: str | None = None, figures: bool = True, truth=None) -> list[Path]:
    """Write the tables (and figures) of an evaluation into `out_dir`; returns the paths written."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    unit = units or cal.output_units
    summary = evaluation.summary(unit)
    loto = loto_comparison(cal)
    written = []
    for name, rows in (("summary.csv", summary), ("by_temperature.csv", evaluation.by_temperature(unit)),
                       ("steps.csv", evaluation.step_rows(unit)), ("loto.csv", loto)):
        if rows:
            _write_rows(out / name, rows)
            written.append(out / name)
        else:  # a table an earlier report left would not belong to this one
            (out / name).unlink(missing_ok=True)
    rms_cols = ["rotating_axis", "gyro_axis"] + [f"{m}_rms" for m in METHODS] + ["lagrange_rms_reduction_pct"]
    mean_cols = ["rotating_axis", "gyro_axis"] + [f"{m}_mean" for m in METHODS]
    lo, hi = cal.range
    text = [
        "# Thermal calibration report\n",
        (f"Calibrated range {lo:g} to {hi:g} degC at {len(cal.temps)} points; traditional baseline: the point at "
        f"{cal.temps[cal.reference_index]:g} degC (nearest {cal.reference_temp:g} degC). Test: "
        f"{len(evaluation.steps)} steps at {np.min(evaluation.steps.temp):.1f} to {np.max(evaluation.steps.temp):.1f} "
        f"degC. Errors are step means minus the table rate, in {unit}.\n"),
        "## RMS error (the full-temperature-range method, Table 4)\n", markdown_table(summary, rms_cols),
        "\n## Mean error (the full-temperature-range method, Table 3)\n", markdown_table(summary, mean_cols),
    ]
    if loto:
        text += ["\n## Lagrange against smooth: leave-one-temperature-out error (internal units: K, rad/s)\n",
                 markdown_table(loto)]
    write_text_atomic(out / "summary.md", "\n".join(text))
    written.append(out / "summary.md")
    if figures:
        written += _figures(cal, evaluation, out, unit, truth)
    else:
        for name in FIGURES:  # an earlier run's figures would not match these tables
            (out / name).unlink(missing_ok=True)
    return written


def _figures(cal, evaluation, out: Path, unit: str, truth) -> list[Path]:
    from . import save_figure
    from .thermal import plot_coefficients, plot_error_vs_rate, plot_error_vs_temperature

    paths = []
    for name, drawn in (("coefficients.png", plot_coefficients(cal, units=unit, truth=truth)),
                        ("error_vs_rate.png", plot_error_vs_rate(evaluation, units=unit)),
                        ("error_vs_temperature.png", plot_error_vs_temperature(evaluation, units=unit))):
        save_figure(drawn["figure"], out / name)
        paths.append(out / name)
    return paths
