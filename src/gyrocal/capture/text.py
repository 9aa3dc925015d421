"""Text lines as an Arduino ``Serial.println`` sends them: ``t,gx,gy,gz[,temp][,ax,ay,az]``.

The first line whose fields are names is the header; columns are found by gyrocal's names
and aliases (as in a CSV file, the accelerometer's ``ax, ay, az`` included), and a time column
named ``t_ms``/``millis`` or ``t_us``/``micros`` is scaled to seconds. Without a header,
``columns`` gives column numbers, counting from 1 (``{"t": 1, "gx": 2, "gy": 3, "gz": 4}``).
A line that is not a sample is skipped and counted, never fatal; lines starting with ``#`` are
messages from the device, and the line ``# end of session`` says the device sends nothing more.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..io.columns import resolve, time_scale
from .frames import End

__all__ = ["END_LINE", "Reading", "TextDecoder", "TextStats", "text_lines"]

#: The line a device sends when the session is over (a recorded or simulated one).
END_LINE = "# end of session"
_ACCEL = ("ax", "ay", "az")

_MAX_LINE = 512  # a longer line is noise (a baud mismatch reads as long garbage)
_SEPARATORS = (",", ";", "\t", " ")


@dataclass(frozen=True)
class Reading:
    """One sample from a text line: ``t`` [s] or None, ``g`` [the data's unit], ``temp`` [degC] or None,
    ``a`` the accelerometer [its unit] or None."""

    t: float | None
    g: tuple[float, float, float]
    temp: float | None = None
    a: tuple[float, float, float] | None = None


@dataclass
class TextStats:
    """What a text decoder saw."""

    bytes: int = 0
    lines: int = 0
    samples: int = 0
    bad_lines: int = 0       # not a sample: wrong field count, non-numbers, too long, not text
    before_header: int = 0   # numeric lines before a header told what the columns are
    messages: list[str] = field(default_factory=list)  # '#' lines and text before the header (last 20)


def _split(line: str) -> list[str]:
    for sep in _SEPARATORS:
        if sep in line:
            return [f.strip() for f in line.split(sep) if sep != " " or f.strip()]
    return [line.strip()]


def _numbers(fields: list[str]) -> list[float] | None:
    try:
        return [float(f) for f in fields]
    except ValueError:
        return None


class TextDecoder:
    """Streaming decoder of text lines: ``feed(bytes) -> list of Reading`` (and an :class:`End` for the
    end-of-session line).

    Parameters
    ----------
    columns : mapping of str to int or str, optional
        Column numbers counting from 1 (no header needed), or names mapping gyrocal's
        names to the header's (as ``--columns`` for files).
    """

    def __init__(self, columns=None):
        self._buf = bytearray()
        self._numbers: dict[str, int] | None = None
        self._names = None
        self._t_scale = 1.0
        self.ended = False
        self.stats = TextStats()
        if columns:
            if all(str(v).strip().isdigit() for v in columns.values()):
                cols = {k: int(v) - 1 for k, v in columns.items()}
                if min(cols.values()) < 0:
                    raise InputError(f"column numbers count from 1, got {columns!r}", param="columns", value=columns)
                self._use(cols, 1.0)
            else:
                self._names = dict(columns)

    @property
    def has_layout(self) -> bool:
        """Whether the decoder knows which field is which (a header came, or columns were given)."""
        return self._numbers is not None

    @property
    def has_time(self) -> bool:
        return self._numbers is not None and "t" in self._numbers

    @property
    def has_temp(self) -> bool:
        return self._numbers is not None and "temp" in self._numbers

    @property
    def has_accel(self) -> bool:
        return self._numbers is not None and "ax" in self._numbers

    def _use(self, cols: dict[str, int], t_scale: float) -> None:
        missing = [c for c in ("gx", "gy", "gz") if c not in cols]
        if missing:
            raise InputError(f"{{param}} gives no column for {', '.join(missing)}", param="columns",
                             hint="map them, e.g. {param} t=1,gx=2,gy=3,gz=4")
        some = [c for c in _ACCEL if c in cols]
        if some and len(some) < 3:
            raise InputError(f"{{param}} gives a column for {', '.join(some)} but not for every accelerometer axis",
                             param="columns", hint="map all three, e.g. {param} ...,ax=5,ay=6,az=7")
        self._numbers, self._t_scale = cols, t_scale
        self._width = max(cols.values()) + 1

    def _message(self, text: str) -> None:
        msgs = self.stats.messages
        msgs.append(text[:200])
        del msgs[:-20]

    def _header(self, fields: list[str]) -> bool:
        for accel in (True, False):  # with the accelerometer's three columns, else without them
            try:
                mapping = resolve(fields, self._names, "the serial header line", accel=accel)
                break
            except InputError:
                continue
        else:
            return False
        cols = {k: fields.index(v) for k, v in mapping.items() if k in ("t", "gx", "gy", "gz", "temp", *_ACCEL)}
        self._use(cols, time_scale(mapping["t"]) if "t" in mapping else 1.0)
        return True

    def _line(self, raw: bytes, out: list) -> None:
        st = self.stats
        st.lines += 1
        try:
            line = raw.decode("ascii").strip()
        except UnicodeDecodeError:
            st.bad_lines += 1
            return
        if not line:
            return
        if line.startswith("#"):
            if line.lower().startswith(END_LINE):
                self.ended = True
                out.append(End(None))  # a text line carries no count
                return
            self._message(line.lstrip("# "))
            return
        fields = _split(line)
        values = _numbers(fields)
        if values is None:
            if not (self._numbers is None and self._header(fields)):
                if self._numbers is None:
                    self._message(line)
                else:
                    st.bad_lines += 1
            return
        if self._numbers is None:
            st.before_header += 1
            return
        if len(values) < self._width or not all(math.isfinite(v) for v in values):
            st.bad_lines += 1
            return
        c = self._numbers
        t = values[c["t"]] * self._t_scale if "t" in c else None
        temp = values[c["temp"]] if "temp" in c else None
        a = (values[c["ax"]], values[c["ay"]], values[c["az"]]) if "ax" in c else None
        out.append(Reading(t, (values[c["gx"]], values[c["gy"]], values[c["gz"]]), temp, a))
        st.samples += 1

    def feed(self, data: bytes) -> list:
        self.stats.bytes += len(data)
        self._buf += data
        out: list = []
        *lines, rest = self._buf.split(b"\n")
        for raw in lines:
            if self.ended:  # nothing after the end counts
                break
            if len(raw) > _MAX_LINE:
                self.stats.lines += 1
                self.stats.bad_lines += 1
            else:
                self._line(bytes(raw), out)
        if len(rest) > _MAX_LINE:  # no newline in sight: garbage, drop it
            self.stats.bad_lines += 1
            rest = b""
        self._buf = bytearray(rest)
        return out

    def finish(self) -> None:
        """The stream ended: a last line without its newline may be cut short, so it is counted, not used."""
        if self._buf.strip():
            self.stats.lines += 1
            self.stats.bad_lines += 1
        self._buf = bytearray()


def text_lines(session) -> bytes:
    """A :class:`~gyrocal.capture.simulated.DeviceSession` as an Arduino sketch prints it with ``Serial.println``:
    ``t_us,gx,gy,gz[,temp][,ax,ay,az]``,
    then the end-of-session line."""
    head = "t_us,gx,gy,gz" + (",temp" if session.temp is not None else "")
    cols = [session.t_us.astype(str), *(session.raw[:, j].astype(str) for j in range(3))]
    if session.temp is not None:
        cols.append(np.char.mod("%.2f", session.temp))
    if session.accel is not None:
        head += ",ax,ay,az"
        cols += [session.accel[:, j].astype(str) for j in range(3)]
    rows = cols[0]
    for c in cols[1:]:
        rows = np.char.add(np.char.add(rows, ","), c)
    return (head + "\r\n" + "\r\n".join(rows.tolist()) + "\r\n" + END_LINE + "\r\n").encode()
