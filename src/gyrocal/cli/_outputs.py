"""Checks made before any output is written, so that a refused run writes nothing and destroys nothing."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Callable, Iterable

from ..errors import InputError


def check_output(
    path: Path | None,
    *,
    flag: str = "-o",
    inputs: Iterable[Path | None] = (),
    force: bool = False,
    replaceable: Callable[[Path], bool] = lambda _: False,
    holds: str = "something else",
) -> None:
    """Refuse an output that is an input, a folder, under a file, or an existing file that
    `replaceable` does not accept (same content, or a regenerable gyrocal output) unless `force`."""
    if path is None:
        return
    parent = next((p for p in path.parents if p.exists()), None)
    if parent is not None and not parent.is_dir():
        raise InputError(f"{flag} {path}: {parent} is a file, not a folder; choose another path")
    if not path.exists():
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


def same_document(doc: dict) -> Callable[[Path], bool]:
    """A `replaceable` test: the file is JSON holding `doc` (apart from which gyrocal wrote it)."""

    def test(path: Path) -> bool:
        try:
            old = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError):
            return False
        drop = ("created_by",)
        return isinstance(old, dict) and (
            {k: v for k, v in old.items() if k not in drop} == {k: v for k, v in doc.items() if k not in drop})

    return test
