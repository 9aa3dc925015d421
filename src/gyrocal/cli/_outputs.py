"""Checks made before any output is written, so that a refused run writes nothing and destroys nothing."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, Iterable

from ..errors import InputError


def check_output(
    path: Path | None,
    *,
    flag: str = "-o",
    inputs: Iterable[Path | None] = (),
    outputs: Iterable[Path | None] = (),
    force: bool = False,
    replaceable: Callable[[Path], bool] = lambda _: False,
    holds: str = "something else",
    folder: bool = False,
) -> None:
    """Refuse an output that is an input, another of the run's `outputs`, under a file, of the wrong
    kind (file or `folder`), or an existing file that `replaceable` does not accept (same content, or
    a regenerable gyrocal output) unless `force`. Writers of many files into a `folder` replace only
    their own names in it."""
    if path is None:
        return
    for other in outputs:
        if other is not None and os.path.abspath(other) == os.path.abspath(path):
            raise InputError(f"{flag} {path} is also where this command writes another output; give each output "
                             "its own file name")
    parent = next((p for p in path.parents if p.exists()), None)
    if parent is not None and not parent.is_dir():
        raise InputError(f"{flag} {path}: {parent} is a file, not a folder; choose another path")
    if not path.exists():
        return
    if folder:
        if not path.is_dir():
            raise InputError(f"{flag} {path} is a file; give a folder for the outputs")
        return
    if path.is_dir():
        raise InputError(f"{flag} {path} is a folder; give a file name inside it")
    for source in inputs:
        if source is not None and Path(source).exists() and path.samefile(source):
            raise InputError(f"{flag} {path} is also an input of this command; write the result to another file")
    if not force and not replaceable(path):
        raise InputError(f"{flag} {path} already exists and holds {holds}; pass --force to replace it")


def starts_with(prefix: str) -> Callable[[Path], bool]:
    """A `replaceable` test: the file's first line starts with `prefix` (an earlier gyrocal output)."""

    def test(path: Path) -> bool:
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                return f.readline().startswith(prefix)
        except OSError:
            return False

    return test


def same_text(text: str) -> Callable[[Path], bool]:
    """A `replaceable` test: the file already holds exactly `text`."""

    def test(path: Path) -> bool:
        try:
            return path.read_text(encoding="utf-8") == text
        except (OSError, UnicodeDecodeError):
            return False

    return test


def _json_object(path: Path) -> dict | None:
    """The JSON object in `path`, or None when it holds anything else."""
    from ..jobs.result import json_object

    return json_object(path)


def same_document(doc: dict) -> Callable[[Path], bool]:
    """A `replaceable` test: the file is JSON holding `doc` (apart from which gyrocal wrote it)."""
    from ..jobs.result import same_document as same

    return same(doc)


def json_format(fmt: str) -> Callable[[Path], bool]:
    """A `replaceable` test: the file is a JSON object of gyrocal format `fmt` (an earlier output)."""
    return lambda path: (doc := _json_object(path)) is not None and doc.get("format") == fmt


def gyrocal_format(path: Path) -> str | None:
    """The ``format`` of a gyrocal JSON file (``"gyrocal.calibration"``, ...), or None for anything else.

    Reads the whole file only when it starts like a JSON object, so a large recording costs nothing.
    """
    try:
        with open(path, "rb") as f:
            if not f.read(64).lstrip().startswith(b"{"):
                return None
    except OSError:
        return None
    fmt = (_json_object(path) or {}).get("format")
    return fmt if isinstance(fmt, str) and fmt.startswith("gyrocal.") else None


def refuse_swapped(first: Path, second: Path, *, command: str, usage: str) -> None:
    """Refuse two arguments given the wrong way round: `first` should be the gyrocal file."""
    if first.is_file() and second.is_file() and gyrocal_format(first) is None and gyrocal_format(second) is not None:
        raise InputError(f"{first.name} is not a gyrocal file but {second.name} is ({gyrocal_format(second)}): "
                         f"the arguments look swapped; the {usage} first",
                         hint=f"gyrocal {command} {second} {first} ...")
