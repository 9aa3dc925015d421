"""What every job returns (:class:`JobResult`) and what every job is (:class:`Job`).

Standard library only at module level: the atomic writer (which loads numpy) is imported by ``save``.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, ClassVar, Mapping

from ..errors import InputError

__all__ = ["Job", "JobResult", "json_object", "same_document"]


def _kept(doc: dict) -> dict:
    """`doc` apart from which gyrocal wrote it and when its unit's result was made."""
    out = {k: v for k, v in doc.items() if k != "created_by"}
    if isinstance(out.get("unit"), dict):  # the same unit's result, made again at another time
        out["unit"] = {k: v for k, v in out["unit"].items() if k not in ("created", "software")}
    return out


def json_object(path: Path) -> dict | None:
    """The JSON object in `path`, or None when it holds anything else."""
    import json

    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    return doc if isinstance(doc, dict) else None


def same_document(doc: dict) -> Callable[[Path], bool]:
    """A test of an existing file: it is JSON holding `doc` (apart from which gyrocal wrote it, and when)."""
    mine = _kept(doc)
    return lambda path: (old := json_object(path)) is not None and _kept(old) == mine


@dataclass(frozen=True)
class JobResult:
    """One job's result, alike for every job.

    ``kind`` is the store's kind of the document (calibration, imu, thermal, thermal-bias, noise, verify),
    ``job`` the job's name; ``document`` is the dict a command writes to its file; ``warnings`` and
    ``notes`` are what the run found, as lines; ``quality`` the fit quality summary (None for a job
    without a fit of observations); ``figures`` name -> a callable that draws that matplotlib figure
    (drawn only when called); ``inputs`` the files it read (hashed into a unit's section); ``value`` the
    library's own result (``CalibrationRun``, ``ImuRun`` ...) for the command's detailed printing;
    ``implausible`` the diagnosis written into the document with ``accept_implausible``.
    """

    kind: str
    job: str
    document: dict
    warnings: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    quality: Any = None
    figures: Mapping[str, Callable[[], Any]] = field(default_factory=dict)
    inputs: tuple[Path, ...] = ()
    value: Any = None
    implausible: str | None = None
    device_id: int | None = None

    def summary(self) -> list[str]:
        """Lines for printing: what was made, the fit quality, the notes and warnings."""
        fmt = self.document.get("format", self.kind)
        lines = [f"{self.job}: {fmt} from {', '.join(p.name for p in self.inputs) or 'memory'}"]
        if self.quality is not None and hasattr(self.quality, "summary"):
            lines.append(self.quality.summary())
        lines += [f"note: {n}" for n in self.notes]
        lines += [f"warning: {w}" for w in self.warnings]
        return lines

    def with_document(self, doc: dict) -> JobResult:
        """The same result with `doc` (stamped by the station) as its document."""
        return dataclasses.replace(self, document=doc)

    def save(self, path: str | os.PathLike, *, force: bool = False) -> Path:
        """Write the document to `path` atomically (a failed write leaves no file and the old one intact).

        Refused, before anything is written, when `path` is a folder, one of the inputs, or an existing file
        that holds another document (unless `force`). NaN and infinity are refused by the JSON writer.
        """
        from .._jsonfile import write_json

        path = Path(path)
        if path.is_dir():
            raise InputError(f"{path} is a folder; give a file name inside it")
        if path.exists():
            if any(Path(p).exists() and path.samefile(p) for p in self.inputs):
                raise InputError(f"{path} is also an input of this job; write the result to another file")
            if not force and not same_document(self.document)(path):
                raise InputError(f"{path} already exists and holds another document; pass force=True to replace it")
        try:
            write_json(path, self.document)
        except ValueError as exc:  # NaN or infinity: not JSON
            raise InputError(f"{self.job}: the result cannot be written as JSON ({exc})") from None
        return path


class Job:
    """A job: a frozen dataclass of its typed inputs, whose :meth:`run` makes one :class:`JobResult`.

    Subclasses set ``name`` (the registry's, the command's) and ``kind`` (the store's) and refuse bad
    inputs with :class:`~gyrocal.errors.InputError` (the library's own errors are ``GyrocalError`` too).
    """

    name: ClassVar[str] = ""
    kind: ClassVar[str] = ""

    def run(self) -> JobResult:
        raise NotImplementedError


def judge(doc: dict, diagnosis: str | None, accept: bool) -> tuple[dict, str | None]:
    """`doc` and the warning line it now carries: refused when `diagnosis` says it is implausible, unless
    `accept`, when the diagnosis goes among its warnings (the file's own, the fit's, or the settings')."""
    if diagnosis is None:
        return doc, None
    if not accept:
        raise InputError(f"implausible result, nothing written: {diagnosis}", param="accept_implausible",
                         hint="if every declaration is right, give {param} to write it with this warning in the file")
    text = f"written with --accept-implausible: {diagnosis}"
    fit = doc.get("fit")
    if isinstance(doc.get("warnings"), list):  # the file's own warnings (thermal-bias)
        return {**doc, "warnings": doc["warnings"] + [text]}, text
    if isinstance(fit, dict):  # a calibration's fit section
        return {**doc, "fit": {**fit, "warnings": list(fit.get("warnings") or []) + [text]}}, text
    return {**doc, "settings": {**(doc.get("settings") or {}), "warnings": [text]}}, text


def read_input(recording, reading: Mapping, notes: list):
    """`recording` itself when it is already read, else read from its path with the `reading` options."""
    if isinstance(recording, (str, os.PathLike)):
        from ..io import read_recording

        return read_recording(Path(recording), **dict(reading), notes=notes)
    return recording


def paths(*items) -> tuple[Path, ...]:
    """The paths among `items` (a recording already read names no file)."""
    return tuple(Path(p) for p in items if isinstance(p, (str, os.PathLike)))
