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


@app.command()
def certificate(
    unit: Annotated[str, typer.Argument(help="A result file with a 'unit' section, or a serial number with --store.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Certificate to write: .html or .pdf.")],
    store: STATION.Store = None,
    force: Annotated[bool, typer.Option("--force", help="Replace an existing certificate.")] = False,
) -> None:
    """Write a unit's calibration certificate (HTML or PDF): identity, results with 1-sigma, limits, verdicts."""
    from ..station.certificate import write_certificate

    if store is None:
        doc, record = _read_result(Path(unit)), f"file {Path(unit).name}"
        inputs = (Path(unit),)
    else:
        doc, record = _latest_calibration(store, unit)
        inputs = ()
    check_output(output, flag="--output", inputs=inputs, force=force,
                 replaceable=lambda path: path.suffix.lower() in (".html", ".htm", ".pdf"))
    write_certificate(doc, output, record)
    verdict = (doc.get("acceptance") or {}).get("verdict")
    console.print(f"wrote {output}: {doc['unit']['serial']} " + (verdict.upper() if verdict else "(no limits applied)"),
                  highlight=False)


def _latest_calibration(url: str, serial: str) -> tuple[dict, str]:
    from ..station.identity import check_serial
    from ..store import is_calibration_kind, open_store

    serial = check_serial(serial, "SERIAL")
    with open_store(url) as st:
        records = [r for r in st.history(serial) if is_calibration_kind(r.kind)]
    if not records:
        raise InputError(f"the store {url} holds no calibration of unit {serial!r}; calibrate it with --unit {serial} "
                         f"--store {url}")
    r = records[0]
    return r.document, f"record {r.id} of {url}, {r.created:%Y-%m-%dT%H:%M:%SZ}"
