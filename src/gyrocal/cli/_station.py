"""The station's flags, shared by every command that writes a result: identity, limits, store.

A command takes them with :func:`station_flags` (``--unit`` ... ``--store``, checked before its body
runs), runs its job (:mod:`gyrocal.jobs`) and ends in three calls on the job's result: :func:`finish`
gives the result document its ``unit`` section and its acceptance, :func:`write_and_store` writes it atomically (when the command has an output file) and
adds it to the store, and :func:`conclude` says where it went and the verdict, with the exit code
(0 pass or no limits, 1 fail). Library imports happen inside the functions, so ``gyrocal --help``
stays fast.
"""

from __future__ import annotations

import contextlib
import functools
import inspect
from contextvars import ContextVar
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError

__all__ = ["STATION", "StationFlags", "conclude", "finish", "print_verdict", "station_flags", "store_result",
           "write_and_store"]

_PANEL = "Production station"
#: (job, args) of a batch row being run: recorded with the result, so that a rerun of the batch finds it
BATCH_JOB: ContextVar[tuple[str, str] | None] = ContextVar("batch_job", default=None)


@contextlib.contextmanager
def batch_job(job: str, args: str):
    """Record the results made inside as the batch job `job` with flags `args`."""
    token = BATCH_JOB.set((job, args))
    try:
        yield
    finally:
        BATCH_JOB.reset(token)


def _opt(flag: str, text: str, metavar: str = "TEXT"):
    return typer.Option(flag, help=text, rich_help_panel=_PANEL, metavar=metavar)


class STATION:
    """Annotated option types; a command takes them as parameters and passes them to :class:`StationFlags`."""

    Unit = Annotated[Optional[str], _opt("--unit", "Serial number of the unit: recorded in the file's 'unit' "
                                         "section with the inputs' SHA-256, the software and the time (default: "
                                         "none).", "SERIAL")]
    Part = Annotated[Optional[str], _opt("--part", "Part number of the unit (default: none).")]
    Revision = Annotated[Optional[str], _opt("--revision", "Hardware revision of the unit (default: none).")]
    Station = Annotated[Optional[str], _opt("--station", "Calibration station's name (default: none).")]
    Operator = Annotated[Optional[str], _opt("--operator", "Who ran the calibration (default: none).")]
    Fixture = Annotated[Optional[str], _opt("--fixture", "Fixture or turntable used (default: none).")]
    Procedure = Annotated[Optional[str], _opt("--procedure", "Procedure as NAME@VERSION (default: none).",
                                              "NAME@VERSION")]
    Limits = Annotated[Optional[Path], _opt("--limits", "Acceptance limits (TOML): each value +- guard x sigma "
                                            "must lie inside its bounds; exit 1 when any fails (default: none).",
                                            "FILE")]
    Store = Annotated[Optional[str], _opt("--store", "Calibration store: an SQLite file (a path or "
                                          "sqlite:///path) or postgresql://user@host:port/db; the result is "
                                          "added as a new record (default: none).", "URL")]


@dataclass(frozen=True)
class StationFlags:
    """What a command was given of :class:`STATION`'s flags."""

    unit: str | None = None
    part: str | None = None
    revision: str | None = None
    station: str | None = None
    operator: str | None = None
    fixture: str | None = None
    procedure: str | None = None
    limits: Path | None = None
    store: str | None = None

    def check(self) -> None:
        """Refuse what cannot work before any reading or fitting is done."""
        if self.unit is None and any(v is not None for v in (self.part, self.revision, self.fixture, self.procedure)):
            raise InputError("--part, --revision, --fixture and --procedure describe a unit: give its --unit SERIAL too")
        if self.store is not None and self.unit is None:
            raise InputError("--store keeps records per unit: give --unit SERIAL too")
        self.identity()  # checks the serial and the procedure now, not after the fit
        if self.limits is not None:
            from ..station.limits import read_limits

            read_limits(self.limits)
        if self.store is not None:  # unreachable, or of a newer schema: say so before the work, not after
            with _open(self.store):
                pass

    def identity(self):
        if self.unit is None:
            return None
        from ..station.identity import Identity

        return Identity(self.unit, self.part, self.revision, self.station, self.operator, self.fixture,
                        self.procedure)


#: Parameter name -> option type, in the order of :class:`StationFlags`' fields.
_PARAMETERS = {"unit": STATION.Unit, "part": STATION.Part, "revision": STATION.Revision, "station": STATION.Station,
               "operator": STATION.Operator, "fixture": STATION.Fixture, "procedure": STATION.Procedure,
               "limits": STATION.Limits, "store": STATION.Store}


def station_flags(command):
    """Give a command the station's flags: its command line takes ``--unit`` ... ``--store`` (after its own
    options), and it is called with ``flags=`` the :class:`StationFlags` they make, already checked.

    The command declares a last parameter ``flags: StationFlags = StationFlags()``; typer sees the
    nine options in its place.
    """
    own = inspect.signature(command, eval_str=True)
    if "flags" not in own.parameters:
        raise TypeError(f"{command.__name__} takes no 'flags' parameter for the station's flags")
    extra = [inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=None, annotation=kind)
             for name, kind in _PARAMETERS.items()]
    params = [p for p in own.parameters.values() if p.name != "flags"] + extra

    @functools.wraps(command)
    def with_flags(*args, **kwargs):
        flags = StationFlags(**{name: kwargs.pop(name, None) for name in _PARAMETERS})
        flags.check()
        return command(*args, flags=flags, **kwargs)

    with_flags.__signature__ = own.replace(parameters=params)
    with_flags.__annotations__ = {p.name: p.annotation for p in params} | {"return": own.return_annotation}
    return with_flags


def _is_result(doc) -> bool:
    """`doc` is a job's result (:class:`gyrocal.jobs.result.JobResult`), not a bare document."""
    return hasattr(doc, "document") and hasattr(doc, "kind")


def finish(doc, flags: StationFlags, *, inputs=None, device_id: int | None = None):
    """Stamp a job's result (or a bare document) with the unit, as found / as left (with --store) and the
    acceptance; the stamped result (or document) and the verdict.

    A job's result gives its own inputs and device id. The caller writes the returned document
    (atomically) before the store is written, so a stored record always has its file; the verdict is
    None without limits.
    """
    if _is_result(doc):
        stamped, verdict = finish(doc.document, flags, inputs=doc.inputs if inputs is None else inputs,
                                  device_id=doc.device_id if device_id is None else device_id)
        return doc.with_document(stamped), verdict
    files = [Path(p) for p in inputs if p is not None]
    identity = flags.identity()
    if identity is not None:
        from ..station.identity import unit_section

        doc = {**doc, "unit": unit_section(identity, files, device_id=device_id)}
    if flags.store is not None:
        doc = _with_as_found(doc, flags)
    verdict = None
    if flags.limits is not None:
        from ..station.accept import accept
        from ..station.limits import read_limits

        acceptance = accept(doc, read_limits(flags.limits))
        doc = {**doc, "acceptance": acceptance.to_document()}
        verdict = acceptance.verdict
    return doc, verdict


def _open(url: str):
    from ..store import open_store

    return open_store(url)


def _with_as_found(doc: dict, flags: StationFlags) -> dict:
    """`doc` with ``as_found``/``as_left`` when the store holds a calibration of the unit in force now."""
    from ..station.asfound import as_found_and_left

    with _open(flags.store) as store:
        previous = store.in_force(flags.unit)
    if previous is None:
        return doc
    parts = as_found_and_left(doc, previous.document, record=previous.id,
                              created=previous.created.strftime("%Y-%m-%dT%H:%M:%SZ"))
    return doc if parts is None else {**doc, "as_found": parts[0], "as_left": parts[1]}


def store_result(doc: dict, flags: StationFlags, verdict: str | None, *, kind: str, job: str, args: str,
                 inputs) -> int | None:
    """Add the finished document to the store as a new record; its id, or None without --store."""
    if flags.store is None:
        return None
    from ..station.identity import sha256_of

    unit = doc.get("unit") or {}
    hashes = [sha256_of(p) for p in inputs if p is not None]
    from datetime import datetime

    created = datetime.fromisoformat(unit["created"].replace("Z", "+00:00")) if unit.get("created") else None
    job, args = BATCH_JOB.get() or (job, args)
    with _open(flags.store) as store:
        return store.add(unit.get("serial") or flags.unit, kind, doc, created=created, station=flags.station,
                         operator=flags.operator, verdict=verdict,
                         input_sha256=hashes[0] if len(hashes) == 1 else hashes, job=job, args=args)


def write_and_store(doc, flags: StationFlags, output: Path | None, verdict: str | None, *, inputs=None,
                    kind: str | None = None, job: str | None = None, args: str = "") -> int | None:
    """Write the finished job's result (or bare document) to `output` atomically (None: nothing on disk),
    then add it to the store; a job's result gives its own inputs, kind and job name.

    The file comes first, so a stored record always has its file; the record id, or None without --store.
    """
    if _is_result(doc):
        inputs = doc.inputs if inputs is None else inputs
        kind, job, doc = kind or doc.kind, job or doc.job, doc.document
    if output is not None:
        from .._jsonfile import write_json

        write_json(output, doc)
    return store_result(doc, flags, verdict, kind=kind, job=job, args=args, inputs=inputs)


def conclude(console, doc, flags: StationFlags, record: int | None, verdict: str | None) -> None:
    """A command's last lines (of a job's result, or a bare document): where the record went, the acceptance;
    exit 1 when it failed."""
    doc = doc.document if _is_result(doc) else doc
    if record is not None:
        console.print(f"stored as record {record} in {flags.store}", highlight=False)
    print_verdict(console, doc)
    if verdict == "fail":
        raise typer.Exit(1)


def print_verdict(console, doc: dict) -> None:
    """The acceptance table, then one line a test engineer reads from across the bench."""
    acc = doc.get("acceptance")
    if acc is None:
        return
    from rich.table import Table

    table = Table(title="acceptance (value +- guard x sigma inside the bounds)")
    for col in ("criterion", "value", "1-sigma", "low", "high", "unit", "margin", "verdict"):
        table.add_column(col, justify="left" if col in ("criterion", "unit", "verdict") else "right", no_wrap=True)
    for c in acc["criteria"]:
        def num(x):
            return "-" if x is None else f"{x:.6g}"
        table.add_row(c["name"], num(c["value"]), num(c["sigma"]), num(c["low"]), num(c["high"]), c["unit"],
                      num(c["margin"]), c["verdict"].upper())
    console.print(table)
    if acc["not_applicable"]:
        console.print(f"not in this result: {', '.join(acc['not_applicable'])}", highlight=False)
    failed = [c["name"] for c in acc["criteria"] if c["verdict"] != "pass"]
    serial = (doc.get("unit") or {}).get("serial")
    who = f"{serial}: " if serial else ""
    console.print(f"{who}{'PASS' if not failed else 'FAIL (' + ', '.join(failed) + ')'}", highlight=False)
