"""A batch manifest: one row per unit and recording, read from CSV and checked before anything runs.

Columns ``file``, ``serial``, ``job`` (calibrate, imu, thermal, thermal-bias, noise) and ``args``
(that job's flags as one string, e.g. ``--units deg/s --speed 60``), plus optional identity
columns (part, revision, station, operator, fixture, procedure). Paths are relative to the
manifest's folder.
"""

from __future__ import annotations

import csv
import shlex
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from .identity import check_serial

__all__ = ["IDENTITY_COLUMNS", "JOBS", "Row", "read_manifest"]

#: Job (a name of :data:`gyrocal.jobs.JOBS` whose command takes the station's flags) -> the flag its result
#: file is written with.
JOBS = {"calibrate": "-o", "imu": "-o", "thermal": "-o", "thermal-bias": "-o", "noise": "-o"}
REQUIRED = ("file", "serial", "job", "args")
IDENTITY_COLUMNS = ("part", "revision", "station", "operator", "fixture", "procedure")
# flags the batch sets itself: a row's args must not set them too
_OWN = ("--unit", "--store", "--limits", "-o", "--output", "--json", *(f"--{c}" for c in IDENTITY_COLUMNS))


@dataclass(frozen=True)
class Row:
    """One job of a batch: which file, which unit, which command with which flags."""

    line: int
    file: Path
    serial: str
    job: str
    args: str  # normalised: the flags joined by single spaces, as stored for rerun checks
    identity: dict

    def argv(self) -> list[str]:
        """The command line of the job, without its output and station flags."""
        out = [self.job, str(self.file), *shlex.split(self.args)]
        for key, value in self.identity.items():
            out += [f"--{key}", value]
        return out + ["--unit", self.serial]


def _row(line: int, raw: dict, folder: Path, where: str) -> Row:
    job = (raw.get("job") or "").strip()
    if job not in JOBS:
        raise InputError(f"{where} line {line}: unknown job {job!r}; a manifest runs {', '.join(JOBS)}")
    name = (raw.get("file") or "").strip()
    if not name:
        raise InputError(f"{where} line {line}: the 'file' column is empty")
    try:
        args = shlex.split(raw.get("args") or "")
    except ValueError as exc:
        raise InputError(f"{where} line {line}: its args cannot be split into flags ({exc})") from None
    own = sorted({a.split("=", 1)[0] for a in args} & set(_OWN))
    if own:
        raise InputError(f"{where} line {line}: args sets {own[0]}, which the batch sets itself (give identity in "
                         "its own column, and --store, --limits to the batch)")
    identity = {c: raw[c].strip() for c in IDENTITY_COLUMNS if (raw.get(c) or "").strip()}
    serial = check_serial(raw.get("serial") or "", f"{where} line {line}: serial")
    return Row(line, (folder / name).resolve(), serial, job, " ".join(shlex.quote(a) for a in args), identity)


def read_manifest(path: str | Path) -> list[Row]:
    """Every row of a manifest, checked; any mistake is named with its line."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise InputError(f"manifest {path} not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"manifest {path} cannot be read: {exc}") from None
    reader = csv.DictReader(text.splitlines())
    columns = [c.strip() for c in reader.fieldnames or []]
    missing = [c for c in REQUIRED if c not in columns]
    if missing:
        raise InputError(f"manifest {path} lacks the column(s) {', '.join(missing)}; it needs "
                         f"{', '.join(REQUIRED)} (and optionally {', '.join(IDENTITY_COLUMNS)})")
    unknown = [c for c in columns if c not in REQUIRED + IDENTITY_COLUMNS]
    if unknown:
        raise InputError(f"manifest {path}: unknown column {unknown[0]!r}; known: "
                         f"{', '.join(REQUIRED + IDENTITY_COLUMNS)}")
    reader.fieldnames = columns
    rows = [_row(i + 2, raw, path.parent, str(path)) for i, raw in enumerate(reader)]
    if not rows:
        raise InputError(f"manifest {path} has no rows")
    return rows
