"""Command group ``store``: a unit's history, the calibration in force at a time, and the records of a store."""

from __future__ import annotations

import json
import math
from datetime import datetime, timezone
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from ._options import StoreUrl, iso_time
from ._outputs import check_output
from .app import app, console

__all__ = ["store_app"]

store_app = typer.Typer(help="Query the calibration store: history, the calibration in force, records.",
                        no_args_is_help=True)
app.add_typer(store_app, name="store")

Json = Annotated[bool, typer.Option("--json", help="Print a JSON array of records (with their documents).")]


def _record_json(r) -> dict:
    return {"id": r.id, "serial": r.serial, "kind": r.kind, "created": r.created.strftime("%Y-%m-%dT%H:%M:%SZ"),
            "station": r.station, "operator": r.operator, "input_sha256": r.input_sha256, "verdict": r.verdict,
            "job": r.job, "args": r.args, "document": r.document}


def changes(new: dict, old: dict) -> dict[str, float]:
    """Each parameter's change since `old`, in the 1-sigma of the difference (both calibrations' sigmas)."""
    from ..station.asfound import parameter_values

    a, b = parameter_values(new), parameter_values(old)
    return {n: (a[n][0] - b[n][0]) / math.hypot(a[n][1], b[n][1]) for n in a if n in b}


def _open(url: str):
    from ..store import open_store

    return open_store(url)


def _serial(serial: str) -> str:
    from ..station.identity import check_serial

    return check_serial(serial, "SERIAL")


@store_app.command("history")
def history(serial: Annotated[str, typer.Argument(help="The unit's serial number.")], store: StoreUrl,
            as_json: Json = False) -> None:
    """A unit's records, newest first, with each parameter's change since its previous calibration in sigmas."""
    from ..store import is_calibration_kind

    with _open(store) as st:
        records = st.history(_serial(serial))
    calibrations = [r for r in records if is_calibration_kind(r.kind)]
    previous = {c.id: p for c, p in zip(calibrations, calibrations[1:])}
    if as_json:
        out = [{**_record_json(r), "change_sigma": changes(r.document, previous[r.id].document)
                if r.id in previous else None} for r in records]
        typer.echo(json.dumps(out, indent=1))
        return
    if not records:
        console.print(f"no records of unit {serial} in {store}", highlight=False)
        return
    from rich.table import Table

    table = Table(title=f"unit {serial}: {len(records)} record(s), newest first")
    for col in ("id", "created (UTC)", "kind", "station", "verdict", "change since previous [sigma]"):
        table.add_column(col, no_wrap=col != "change since previous [sigma]")
    for r in records:
        change = changes(r.document, previous[r.id].document) if r.id in previous else {}
        text = " ".join(f"{n} {z:+.1f}" for n, z in change.items()) if change else "-"
        table.add_row(str(r.id), f"{r.created:%Y-%m-%d %H:%M:%S}", r.kind, r.station or "-",
                      (r.verdict or "-").upper(), text)
    console.print(table)


@store_app.command("export")
def export(serial: Annotated[str, typer.Argument(help="The unit's serial number.")], store: StoreUrl,
           output: Annotated[Path, typer.Option("-o", "--output", help="Calibration file to write.")],
           at: Annotated[Optional[str], typer.Option("--at", help="ISO 8601 time (default: now).")] = None,
           force: Annotated[bool, typer.Option("--force", help="Replace an existing file.")] = False) -> None:
    """Write the calibration in force at a time: the newest passing one created at or before it."""
    from .._jsonfile import write_json

    when = iso_time(at, "--at") or datetime.now(timezone.utc)
    with _open(store) as st:
        record = st.in_force(_serial(serial), when)
    if record is None:
        raise InputError(f"unit {serial} has no calibration in force at {when:%Y-%m-%dT%H:%M:%SZ} in {store} "
                         "(none created by then, or none passed its limits); see: gyrocal store history "
                         f"{serial} --store {store}")
    check_output(output, force=force)
    write_json(output, record.document)
    console.print(f"wrote {output}: record {record.id} of {record.created:%Y-%m-%dT%H:%M:%SZ} "
                  f"({record.kind}, verdict {(record.verdict or 'none').upper()})", highlight=False)


@store_app.command("list")
def list_records(store: StoreUrl, since: Annotated[Optional[str], typer.Option(
        "--since", help="Only records created at or after this ISO 8601 time.")] = None,
        verdict: Annotated[Optional[str], typer.Option("--verdict", help="Only records with this verdict: pass or "
                                                       "fail.")] = None,
        as_json: Json = False) -> None:
    """Every record of the store (newest first), or those since a time or with a verdict."""
    if verdict is not None and verdict not in ("pass", "fail"):
        raise InputError(f"--verdict takes pass or fail, got {verdict!r}")
    with _open(store) as st:
        records = st.list(since=iso_time(since, "--since"), verdict=verdict)
    if as_json:
        typer.echo(json.dumps([_record_json(r) for r in records], indent=1))
        return
    from rich.table import Table

    table = Table(title=f"{len(records)} record(s) in {store}")
    for col in ("id", "serial", "created (UTC)", "kind", "station", "verdict"):
        table.add_column(col, no_wrap=True)
    for r in records:
        table.add_row(str(r.id), r.serial, f"{r.created:%Y-%m-%d %H:%M:%S}", r.kind, r.station or "-",
                      (r.verdict or "-").upper())
    console.print(table)
