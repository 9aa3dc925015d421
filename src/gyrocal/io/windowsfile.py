"""Windows files: rotation and static spans chosen by hand, overriding detection.

Three layouts are read:

* imucal's section list, as imucal writes it:
  ``{"x_p": {"start": 540, "end": 1271}, ..., "x_rot": {"start": 6770, "end": 7093}}``.
  Names ending in ``_rot`` are rotations about the axis of their first letter; the others
  are static. ``end`` is exclusive; the name becomes the label.
* a JSON list of records, or an object with a ``"windows"`` list (such as a calibration
  file): ``{"start", "stop" | "end", "kind", "angle_deg"?, "axis"?, "sign"?, "label"?}``
  in sample indices, or ``t_start, t_stop`` (or ``"unit": "s"``) in seconds.
* a CSV table with the same columns, one window per row.

Times become indices through the recording's own time column when it is given (`t`): a
window ``[t_start, t_stop]`` holds the samples stamped inside it, so packet gaps and a sample
rate off its nominal value move nothing. Without a time column they become
``round((t - t0) * sample_rate)``. Stop stays exclusive.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from pathlib import Path

import numpy as np

from .._validation import positive
from ..errors import FileFormatError, InputError
from ..segmentation.windows import Window

__all__ = ["read_windows"]

_KINDS = {"rotation": "rotation", "rot": "rotation", "turn": "rotation", "static": "static", "still": "static", "rest": "static"}


def read_windows(path: str | os.PathLike, *, sample_rate: float, t0: float = 0.0, n_samples: int | None = None,
                 t=None) -> list[Window]:
    """Read a windows file into windows sorted by start.

    Parameters
    ----------
    path : path-like
        ``.json`` (imucal section list, or records) or ``.csv``.
    sample_rate : float
        Sampling rate [Hz], to turn times into sample indices.
    t0 : float
        Time of sample 0 [s] (``Recording.t[0]`` for a recording with a time column).
    n_samples : int, optional
        Length of the recording; every window must end inside it.
    t : array_like, shape (n_samples,), optional
        The recording's sample times [s] (its time column). Times in the file are then looked up
        in it, so a gap in the log (samples never delivered) does not shift the windows after it.

    Raises
    ------
    FileFormatError
        The file cannot be read, or a record is malformed or out of range (named by label or position).
    """
    path = Path(path)
    fs = positive("sample_rate", sample_rate)
    if not path.is_file():
        raise FileFormatError(f"windows file {str(path)!r} does not exist")
    text = path.read_text(encoding="utf-8-sig", errors="replace")
    if path.suffix.lower() == ".json" or text.lstrip()[:1] in ("{", "["):
        records = _json_records(text, path.name)
    else:
        records = _csv_records(text, path.name)
    if not records:
        raise FileFormatError(f"{path.name}: holds no windows")
    clock = _Clock(fs, float(t0), None if t is None else np.asarray(t, dtype=float))
    windows = [_window(rec, i, clock, path.name) for i, rec in enumerate(records)]
    if n_samples is not None:
        for w in windows:
            if w.stop > n_samples:
                raise FileFormatError(
                    f"{path.name}: window {w.label or w.start} ends at sample {w.stop}, past the recording's {n_samples} samples; "
                    "check the sample rate and that the file belongs to this recording"
                )
    return sorted(windows, key=lambda w: w.start)


def _json_records(text: str, source: str) -> list[dict]:
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise FileFormatError(f"{source}: not valid JSON ({exc})") from None
    if isinstance(doc, dict) and isinstance(doc.get("windows"), list):
        doc = doc["windows"]
    if isinstance(doc, list):
        if not all(isinstance(r, dict) for r in doc):
            raise FileFormatError(f"{source}: a windows list must hold objects with start/stop and kind")
        return doc
    if isinstance(doc, dict) and all(isinstance(v, dict) for v in doc.values()):
        return [_imucal_record(name, span) for name, span in doc.items()]
    raise FileFormatError(f"{source}: expected imucal's section list, a list of windows, or an object with 'windows'")


def _imucal_record(name: str, span: dict) -> dict:
    rotation = name.lower().endswith("_rot")
    axis = name[0].lower() if rotation and name[:1].lower() in ("x", "y", "z") else None
    return {"label": name, "kind": "rotation" if rotation else "static", "axis": axis, **span}


def _csv_records(text: str, source: str) -> list[dict]:
    from .csvfile import WHITESPACE, sniff

    lines = text.splitlines()
    try:
        h, delimiter = sniff(lines, source)
    except InputError as exc:
        raise FileFormatError(str(exc)) from None
    body = "\n".join(line for line in lines[h:] if line.strip())
    rows = [r.split() for r in body.splitlines()] if delimiter is WHITESPACE else list(csv.reader(io.StringIO(body), delimiter=delimiter))
    header = [c.strip().lower() for c in rows[0]]
    return [{k: v.strip() for k, v in zip(header, row) if v.strip() != ""} for row in rows[1:]]


def _number(rec: dict, key: str, where: str) -> float:
    try:
        value = float(rec[key])
    except (TypeError, ValueError):
        raise FileFormatError(f"{where}: field '{key}' must be a number, got {rec[key]!r}", key) from None
    if not math.isfinite(value):
        raise FileFormatError(f"{where}: field '{key}' must be finite, got {rec[key]!r}", key)
    return value


class _Clock:
    """Seconds to sample indices: through the time column when there is one, else the nominal rate."""

    def __init__(self, fs: float, t0: float, t: np.ndarray | None):
        self.fs, self.t0, self.t = fs, t0, t

    def index(self, value: float) -> int:
        """The first sample stamped at or after `value` (within half a period, as rounding would)."""
        t = self.t
        if t is None or len(t) < 2:
            return round((value - self.t0) * self.fs)
        half = 0.5 / self.fs
        if value > t[-1] + 1.5 / self.fs:  # past the log: an index past its end, for the caller's range check
            return len(t) + max(1, round((value - t[-1]) * self.fs))
        return int(np.searchsorted(t, value - half))


def _index(rec: dict, keys: tuple[str, ...], where: str, clock: _Clock) -> int:
    seconds = str(rec.get("unit", "")).strip().lower() in ("s", "sec", "seconds")
    for key in keys:
        if key in rec:
            value = _number(rec, key, where)
            if key.startswith("t_") or seconds:
                return clock.index(value)
            if value != int(value):
                raise FileFormatError(f"{where}: field '{key}' is a sample index and must be whole, got {rec[key]!r}", key)
            return int(value)
    raise FileFormatError(f"{where}: needs one of the fields {', '.join(keys)}", keys[0])


def _window(rec: dict, i: int, clock: _Clock, source: str) -> Window:
    rec = {str(k).strip().lower(): v for k, v in rec.items()}
    label = str(rec.get("label") or rec.get("name") or "")
    where = f"{source}: window {label or '#' + str(i + 1)}"
    start = _index(rec, ("start", "t_start"), where, clock)
    stop = _index(rec, ("stop", "end", "t_stop", "t_end"), where, clock)
    kind = _KINDS.get(str(rec.get("kind", "")).strip().lower())
    if kind is None:
        raise FileFormatError(f"{where}: field 'kind' is {rec.get('kind')!r}; use 'rotation' or 'static'", "kind")
    axis, sign = rec.get("axis"), int(_number(rec, "sign", where)) if rec.get("sign") not in (None, "") else 0
    if isinstance(axis, str) and axis.strip():
        axis = axis.strip().lower()
        if axis[:1] in "+-" and len(axis) == 2:
            sign, axis = (1 if axis[0] == "+" else -1), axis[1]
        if axis not in ("x", "y", "z"):
            raise FileFormatError(f"{where}: field 'axis' is {rec['axis']!r}; use x, y or z (optionally signed, -z)", "axis")
    else:
        axis = None
    angle = math.radians(_number(rec, "angle_deg", where)) if rec.get("angle_deg") not in (None, "") else math.nan
    rate = _number(rec, "rate", where) if rec.get("rate") not in (None, "") else math.nan
    if kind == "rotation" and angle == 0:
        raise FileFormatError(f"{where}: field 'angle_deg' is 0; give the size of the turn in degrees (or leave it "
                              "out to use --angle)", "angle_deg")
    if start < 0 or stop <= start:
        raise FileFormatError(f"{where}: needs 0 <= start < stop, got {start}:{stop}", "start")
    if kind == "static":
        axis, sign = None, 0
    return Window(start=start, stop=stop, kind=kind, axis=axis, sign=sign, angle=angle, rate=rate, label=label)
