"""Command ``export``: a calibration file in another format (choices from the exporter registry)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal, Optional

import typer

from ..export import EXPORT_FORMATS
from ._outputs import check_output, same_text
from .app import app, console

__all__ = ["export"]

ExportFormat = Literal[EXPORT_FORMATS]  # type: ignore[valid-type]


@app.command()
def export(
    calibration: Annotated[Path, typer.Argument(help="A gyrocal calibration or thermal calibration file.")],
    format: Annotated[ExportFormat, typer.Option("--format", help="Output format.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Output file.")],
    prefix: Annotated[Optional[str], typer.Option(
        "--prefix", help="c-header: start of every C name (default gyrocal), so one firmware can hold several "
                         "sensors' calibrations.")] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace an output that holds a different calibration.")]
    = False,
) -> None:
    """Write a calibration file as JSON, YAML or a C header for firmware."""
    from .._atomic import write_text_atomic
    from ..export import render

    options = {} if prefix is None else {"prefix": prefix}
    text = render(calibration, format, **options)
    check_output(output, inputs=(calibration,), force=force, replaceable=same_text(text))
    write_text_atomic(output, text)
    console.print(f"wrote {output} ({format})", highlight=False)
