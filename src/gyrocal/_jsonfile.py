"""Versioned JSON files: atomic writes and field-by-field validation on load."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from ._atomic import write_text_atomic
from .errors import FileFormatError


def write_json(path: str | os.PathLike, doc: dict) -> None:
    """Write `doc` as indented JSON, atomically."""
    write_text_atomic(path, json.dumps(doc, indent=2, allow_nan=False) + "\n")


def _looks_like(p: Path) -> str | None:
    """What a file that is not JSON looks like, from its first bytes: a recording, a log, or None."""
    with open(p, "rb") as f:
        head = f.read(4096)
    if head.startswith(b"ULog"):
        return "a PX4 ULog recording"
    if head[:3] == b"\xa3\x95\x80":
        return "an ArduPilot DataFlash log"
    if head.startswith(b"PAR1"):
        return "a Parquet recording"
    if head.startswith((b"#ROSBAG", b"\x89MCAP")):
        return "a ROS bag"
    text = head.decode("utf-8", "replace")
    lines = [line for line in text.splitlines() if line.strip() and not line.startswith("#")]
    if len(lines) >= 2 and all("," in line or "\t" in line for line in lines[:2]):
        return "a recording (CSV)"
    return None


def read_json(path: str | os.PathLike) -> dict:
    """Read a JSON object, turning every failure into a :class:`FileFormatError`."""
    p = Path(path)
    if p.is_dir():
        raise FileFormatError(f"{p}: a folder, not a file")
    if not p.is_file():
        raise FileFormatError(f"{p}: no such file")
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        what = _looks_like(p)
        if what is not None:
            raise FileFormatError(f"{p}: {what}, not a gyrocal JSON file: give the file a gyrocal command wrote "
                                  "here (gyrocal calibrate/imu/thermal/noise ... -o FILE.json), and the "
                                  "recording where a recording is asked for") from None
        raise FileFormatError(f"{p}: not valid JSON ({exc})") from None
    if not isinstance(doc, dict):
        raise FileFormatError(f"{p}: expected a JSON object at the top level")
    return doc


def check_header(doc: dict, path, fmt: str, versions: tuple[int, ...]) -> int:
    """Check ``format`` and ``version``; return the version."""
    got = doc.get("format")
    if got != fmt:
        raise FileFormatError(f"{path}: field 'format' is {got!r}, expected {fmt!r}", "format")
    version = doc.get("version")
    if type(version) is not int or version not in versions:  # JSON true == 1 and 1.0 == 1 in Python
        raise FileFormatError(
            f"{path}: field 'version' is {version!r}; this gyrocal reads {', '.join(map(str, versions))}", "version"
        )
    return version


def get(doc: dict, dotted: str, path="file") -> Any:
    """The value at a dotted field name, or a :class:`FileFormatError` naming it."""
    node: Any = doc
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            raise FileFormatError(f"{path}: missing field '{dotted}'", dotted)
        node = node[part]
    return node


def get_array(doc: dict, dotted: str, shape: tuple[int, ...], path="file", allow_none: bool = False):
    """A finite float array of `shape` at a dotted field, or a :class:`FileFormatError` naming it."""
    value = get(doc, dotted, path)
    if value is None and allow_none:
        return None
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise FileFormatError(f"{path}: field '{dotted}' must be numbers", dotted) from None
    if arr.shape != shape or not np.all(np.isfinite(arr)):
        raise FileFormatError(f"{path}: field '{dotted}' must be {shape} finite numbers, got shape {arr.shape}", dotted)
    return arr
