"""Command ``accept``: judge a result file against acceptance limits, with a guard band."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from ._outputs import check_output
from ._station import STATION, StationFlags, print_verdict, store_result
from .app import app, console

__all__ = ["accept"]


def _read_result(path: Path) -> dict:
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"result file {path} not found") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{path} is not a gyrocal result file (JSON): {exc}") from None
    if not isinstance(doc, dict) or not str(doc.get("format", "")).startswith("gyrocal."):
        raise InputError(f"{path} is not a gyrocal result file (no 'format' field naming a gyrocal kind)")
    return doc


@app.command()
def accept(
    result: Annotated[Path, typer.Argument(help="Result file: a calibration, noise or temperature JSON.")],
    limits: Annotated[Path, typer.Option("--limits", help="Acceptance limits (TOML).", metavar="FILE")],
    output: Annotated[Optional[Path], typer.Option(
        "-o", "--output", help="Write the result with its acceptance section (default: none).")] = None,
    store: STATION.Store = None,
    force: Annotated[bool, typer.Option("--force", help="Replace an output that holds another file.")] = False,
) -> None:
    """Judge a result against limits: value +- guard x sigma inside each bound; exit 0 pass, 1 fail."""
    from ..station.accept import accept as judge
    from ..station.limits import read_limits

    bounds = read_limits(limits)
    doc = _read_result(result)
    acceptance = judge(doc, bounds)
    doc = {**doc, "acceptance": acceptance.to_document()}
    serial = (doc.get("unit") or {}).get("serial")
    if store is not None and serial is None:
        raise InputError(f"{result} names no unit (no 'unit' section): the store keeps records per unit; "
                         "calibrate with --unit SERIAL")
    check_output(output, inputs=(result, limits), force=force)
    if output is not None:
        from .._jsonfile import write_json

        write_json(output, doc)
    flags = StationFlags(unit=serial, store=store)
    record = store_result(doc, flags, acceptance.verdict, kind="acceptance", job="accept", args=str(limits),
                          inputs=(result,))
    print_verdict(console, doc)
    if record is not None:
        console.print(f"stored as record {record} in {store}", highlight=False)
    if not acceptance.passed:
        raise typer.Exit(1)
