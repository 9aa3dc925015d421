"""Command ``noise``: Allan deviation of a static recording."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from ._outputs import check_output, json_format
from ._reading import READING, read_from_flags
from .app import app, console

__all__ = ["noise"]


@app.command()
def noise(
    recording: Annotated[Path, typer.Argument(help="Static recording: CSV, Parquet or a ROS/MCAP bag.")],
    units: READING.Units = None,
    columns: READING.Columns = None,
    sample_rate: READING.SampleRate = None,
    plot: Annotated[Optional[Path], typer.Option(
        "--plot", help="Allan deviation plot (.png, .pdf, .svg) (default: none).")] = None,
    json_out: Annotated[Optional[Path], typer.Option(
        "--json", help="Write the noise figures as JSON (default: none).")] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace a --json file that is not a noise file.")]
    = False,
) -> None:
    """Allan deviation of a static recording: angle random walk, bias instability, rate random walk."""
    from rich.table import Table

    from ..noise import FORMAT, characterise, save_noise

    check_output(json_out, flag="--json", inputs=(recording,), force=force, replaceable=json_format(FORMAT))
    check_output(plot, flag="--plot", inputs=(recording, json_out), force=True)

    if units is None:
        raise InputError("--units is required (rad/s or deg/s): the Allan deviation is reported in physical units")
    rec = read_from_flags(recording, units=units, columns=columns, sample_rate=sample_rate)
    report = characterise(rec.gyro, rec.sample_rate)
    table = Table(title=f"{recording.name}: {report.duration:.0f} s at {report.sample_rate:g} Hz")
    # Short names over their units, so the table fits 80 columns without cutting a header.
    for col in ("axis", "ARW\ndeg/\u221ah", "density\nrad/s/\u221aHz", "\u03c3/sample\nrad/s", "bias inst.\ndeg/h",
                "at \u03c4\ns", "RRW\ndeg/h/\u221ah"):
        table.add_column(col, justify="right", no_wrap=True)
    def shown(value: float, factor: float, missing: str) -> str:
        return f"{value * factor:.4g}" if math.isfinite(value) else missing

    deg_h = math.degrees(1.0) * 3600
    for a in range(3):
        table.add_row("xyz"[a], shown(report.arw[a], math.degrees(1.0) * 60, "-"), f"{report.arw[a]:.4g}",
                      f"{report.noise_std[a]:.4g}", shown(report.bias_instability[a], deg_h, "not reached"),
                      shown(report.bias_instability_tau[a], 1.0, "-"), shown(report.rrw[a], deg_h * 60, "not seen"))
    console.print(table)
    if json_out is not None:
        save_noise(json_out, report)
        console.print(f"wrote {json_out}")
    if plot is not None:
        from ..plotting import save_figure
        from ..plotting.noise import allan_figure

        save_figure(allan_figure(report, title=recording.name), plot)
        console.print(f"wrote {plot}")
