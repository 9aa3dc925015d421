"""Command ``batch``: every row of a manifest through its command, on a process pool, into one store.

Each row runs the very command a user would type (``gyrocal calibrate FILE ARGS --unit SERIAL --store
URL ...``) inside a worker process: the command parses the row's flags into the job of that name
(:func:`gyrocal.jobs.run_job`, one job interface for every kind of calibration) and stamps, writes and
stores its result with the station's calls, with the job's own refusals, verdicts and atomic writes. A row already stored (same input SHA-256, job and args) is
skipped, and counts with the outcome it had; a refused row is recorded with its reason.
"""

from __future__ import annotations

import contextlib
import io
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from ._station import STATION
from .app import app, console

__all__ = ["batch"]


@dataclass(frozen=True)
class Outcome:
    row: object
    status: str  # pass, fail, done (no limits), refused, skipped-<status>
    reason: str = ""
    failed: tuple[str, ...] = ()


def _ignore_interrupt() -> None:
    """Workers finish the row they are on when Ctrl-C comes: the batch itself stops handing out rows."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _run_row(argv: list[str], job: str, args: str) -> tuple[int, str]:
    """Run one command in this (worker) process: its exit code and the last line it wrote to stderr."""
    from ._station import batch_job
    from .app import run

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), batch_job(job, args):
        code = run(argv)
    lines = [line for line in err.getvalue().splitlines() if line.strip()]
    return code, lines[-1].removeprefix("error: ") if lines else ""


def _outcome_of_record(row, record) -> Outcome:
    if record.kind == "refusal":
        return Outcome(row, "skipped-refused", (record.document or {}).get("reason", ""))
    status = record.verdict or "done"
    return Outcome(row, f"skipped-{status}", failed=_failed(record.document))


def _failed(doc: dict) -> tuple[str, ...]:
    criteria = (doc.get("acceptance") or {}).get("criteria", [])
    return tuple(c["name"] for c in criteria if c["verdict"] != "pass")


def _refusal(store, row, sha: str | None, reason: str, with_limits: bool) -> None:
    from ..station.identity import iso_utc, utc_now

    doc = {"format": "gyrocal.refusal", "version": 1, "job": row.job, "file": row.file.name, "args": row.args,
           "reason": reason, "unit": {"serial": row.serial, **row.identity, "created": iso_utc(utc_now())}}
    store.add(row.serial, "refusal", doc, station=row.identity.get("station"), operator=row.identity.get("operator"),
              verdict="fail" if with_limits else None, input_sha256=sha, job=row.job, args=row.args)


def _refused_before(store, row) -> bool:
    return any(r.kind == "refusal" and r.job == row.job and r.args == row.args and r.input_sha256 is None
               for r in store.history(row.serial))


def _plan(rows, store) -> tuple[list, list[Outcome], dict]:
    """Rows to run, and the outcomes of those already stored (or whose file is missing)."""
    from ..station.identity import sha256_of

    todo, done, shas = [], [], {}
    for row in rows:
        if not row.file.is_file():
            done.append(Outcome(row, "refused", f"file {row.file} not found"))
            continue
        shas[row.line] = sha = sha256_of(row.file)
        previous = store.find(sha, row.job, row.args)
        if previous is not None:
            done.append(_outcome_of_record(row, previous))
        else:
            todo.append(row)
    return todo, done, shas


def _argv(row, url: str, limits: Optional[Path], out_dir: Path, sha: str) -> list[str]:
    from ..station.manifest import JOBS

    argv = row.argv() + ["--store", url, JOBS[row.job], str(out_dir / f"{row.serial}.{row.job}.{sha[:12]}.json")]
    return argv + (["--limits", str(limits)] if limits is not None else [])


def _run(todo, shas, url, limits, out_dir, jobs: int, store) -> list[Outcome]:
    from rich.progress import Progress

    outcomes = []
    import multiprocessing

    # spawned, not forked: a worker must not inherit this process's open store connections
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=jobs, mp_context=context, initializer=_ignore_interrupt) as pool, \
            Progress(console=console, transient=True) as bar:
        task = bar.add_task("calibrating", total=len(todo))
        futures = {pool.submit(_run_row, _argv(r, url, limits, out_dir, shas[r.line]), r.job, r.args): r
                   for r in todo}
        try:
            for future in as_completed(futures):
                row = futures[future]
                code, line = future.result()
                outcomes.append(_finished(row, code, line, out_dir, shas[row.line], store, limits is not None))
                bar.advance(task)
        except KeyboardInterrupt:
            bar.stop()
            pool.shutdown(wait=True, cancel_futures=True)  # the rows being run finish and store themselves
            raise InputError(f"interrupted: {len(outcomes)} of {len(todo)} new row(s) were done, and the ones "
                             "running finished and are stored; nothing was left half written; run the batch again "
                             "to do the rest") from None
    return outcomes


def _finished(row, code: int, line: str, out_dir: Path, sha: str, store, with_limits: bool) -> Outcome:
    if code == 2 or code not in (0, 1):
        _refusal(store, row, sha, line or f"exit code {code}", with_limits)
        return Outcome(row, "refused", line)
    import json

    doc = json.loads((out_dir / f"{row.serial}.{row.job}.{sha[:12]}.json").read_text(encoding="utf-8"))
    verdict = (doc.get("acceptance") or {}).get("verdict")
    return Outcome(row, verdict or "done", failed=_failed(doc))


def _summary(outcomes: list[Outcome]) -> None:
    from collections import Counter

    from rich.table import Table

    status = [o.status.removeprefix("skipped-") for o in outcomes]
    skipped = sum(o.status.startswith("skipped-") for o in outcomes)
    table = Table(title=f"batch: {len(outcomes)} row(s)")
    for col in ("processed", "passed", "failed", "refused", "calibrated (no limits)", "skipped (stored before)"):
        table.add_column(col, justify="right")
    table.add_row(str(len(outcomes) - skipped), str(status.count("pass")), str(status.count("fail")),
                  str(status.count("refused")), str(status.count("done")), str(skipped))
    console.print(table)
    by_criterion = Counter(name for o in outcomes for name in o.failed)
    if by_criterion:
        console.print("failures by criterion: " + ", ".join(f"{n} {c}" for n, c in by_criterion.most_common()),
                      highlight=False)
    for o in outcomes:
        if o.status.endswith("refused"):
            console.print(f"refused: line {o.row.line} {o.row.serial} ({o.row.file.name}): {o.reason}",
                          highlight=False, markup=False, soft_wrap=True)


@app.command()
def batch(
    manifest: Annotated[Path, typer.Argument(help="CSV with columns file, serial, job, args (and identity columns).")],
    store: Annotated[str, typer.Option("--store", help="The store every result goes to (SQLite path or URL).",
                                       metavar="URL")],
    limits: STATION.Limits = None,
    jobs: Annotated[int, typer.Option("-j", "--jobs", help="Worker processes.", min=1)] = 1,
    output_dir: Annotated[Optional[Path], typer.Option(
        "-o", "--output", "--output-dir", help="Folder of the result files (default: 'results' beside the "
        "manifest); --output-dir is its old name.")] = None,
) -> None:
    """Run a manifest of units through their calibration jobs into a store; exit 0 all passed, 1 any failed."""
    from ..station.limits import read_limits
    from ..station.manifest import read_manifest
    from ..store import open_store

    rows = read_manifest(manifest)
    if limits is not None:
        read_limits(limits)
    out_dir = output_dir if output_dir is not None else manifest.parent / "results"
    out_dir.mkdir(parents=True, exist_ok=True)
    with open_store(store) as st:
        todo, outcomes, shas = _plan(rows, st)
        for o in outcomes:
            if o.status == "refused" and not _refused_before(st, o.row):  # a missing file, recorded once
                _refusal(st, o.row, None, o.reason, limits is not None)
        if len(outcomes) > sum(o.status == "refused" for o in outcomes):
            console.print(f"{sum(o.status.startswith('skipped') for o in outcomes)} row(s) already in the store "
                          "(same input, job and args): skipped", highlight=False)
        outcomes += _run(todo, shas, store, limits, out_dir.resolve(), jobs, st)
    outcomes.sort(key=lambda o: o.row.line)
    _summary(outcomes)
    bad = [o for o in outcomes if o.status.removeprefix("skipped-") in ("fail", "refused")]
    if bad:
        raise typer.Exit(1)
