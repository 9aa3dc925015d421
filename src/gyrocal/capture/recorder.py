"""The capture loop: read a serial port, decode, record every sample, and report as it goes.

The port is anything pyserial opens (``serial.serial_for_url``): a USB serial device, a
pseudo-terminal, ``socket://host:port``. A capture ends on a duration of data, a number of
samples, the device's end of session (an end frame, or the text line ``# end of session``),
the end of the stream (the link closed or the cable came out), a long silence, or a stop
request (Ctrl-C, SIGTERM: the caller's `stop` callable). Whichever way it ends, everything
decoded is written and the file is put in place (:class:`~gyrocal.capture.store.SampleStore`);
memory holds only recent samples, so a capture may run for hours.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

from ..errors import GyrocalError, InputError, MissingDependencyError
from .device_log import DeviceLog
from .frames import Calibrated, End, FrameDecoder, Hello, ImuSample, Result, Sample, Text, Turn
from .store import SampleStore
from .text import TextDecoder

__all__ = ["Capture", "CaptureResult", "LinkError", "open_port"]

Wire = Literal["auto", "frames", "text"]
Ending = Literal["duration", "samples", "end of session", "end of stream", "stopped", "silence", "guide complete"]


class LinkError(GyrocalError):
    """The serial port could not be opened."""


def open_port(port: str, baud: int, timeout: float = 0.1):
    """Open `port` with pyserial (``serial_for_url``: device paths, pseudo-terminals, ``socket://``)."""
    try:
        import serial
    except ImportError:
        raise MissingDependencyError("capturing from a serial port needs pyserial: pip install 'gyrocal[serial]'") from None
    try:
        return serial.serial_for_url(port, baudrate=int(baud), timeout=timeout)
    except (serial.SerialException, ValueError, OSError) as exc:
        raise LinkError(f"cannot open {port!r}: {exc}", param="port", value=port,
                        hint="check {param} (ls /dev/ttyUSB* /dev/ttyACM*) and that no other program (a serial "
                             "monitor) holds the port") from None


@dataclass
class CaptureResult:
    """What a capture received."""

    path: Any
    store: SampleStore
    ended: str
    wire: str | None
    hello: Hello | None
    device: DeviceLog
    messages: list[str] = field(default_factory=list)  # the last 100
    stalls: list[float] = field(default_factory=list)
    stats: Any = None
    sent: int | None = None  # samples the device says it sent (its end frame)

    @property
    def samples(self) -> int:
        return len(self.store)

    @property
    def turns(self) -> list[Turn]:
        return self.device.turns

    @property
    def results(self) -> list[Result]:
        return self.device.results


class Capture:
    """One capture session.

    Parameters
    ----------
    port : str
        What pyserial opens.
    out : path-like
        The CSV to write.
    baud : int
        [bit/s].
    wire : {"auto", "frames", "text"}
        ``auto`` takes whichever decoder first finds a valid frame or sample line.
    columns : mapping, optional
        Text lines: column numbers (from 1) or names (see :class:`TextDecoder`).
    duration : float, optional
        Stop after this much data [s] (device time; wall time when samples carry none).
    samples : int, optional
        Stop after this many samples.
    silence : float, optional
        Stop after this long without a byte [s].
    stall : float
        Report a silence this long [s] (the capture goes on).
    on_event : callable(kind, payload), optional
        Told of ``open`` (the port is open), ``progress``, ``wire``, ``hello``, ``turn``, ``result``, ``message``, ``stall``, ``resumed``.
    """

    def __init__(self, port: str, out, *, baud: int = 115200, wire: Wire = "auto", columns=None,
                 duration: float | None = None, samples: int | None = None, silence: float | None = None,
                 stall: float = 1.0, on_event: Callable[[str, Any], None] | None = None,
                 header_comment: Callable[[], str] | None = None):
        if wire not in ("auto", "frames", "text"):
            raise InputError(f"{{param}} must be 'auto', 'frames' or 'text', got {wire!r}", param="wire", value=wire)
        for name, v in (("duration", duration), ("samples", samples), ("silence", silence)):
            if v is not None and not v > 0:
                raise InputError(f"{{param}} must be > 0 when given, got {v!r}", param=name, value=v)
        self.port, self.baud, self.wire = port, baud, wire
        self.duration, self.max_samples, self.silence, self.stall = duration, samples, silence, stall
        self.on_event = on_event or (lambda kind, payload: None)
        self._frames = FrameDecoder() if wire in ("auto", "frames") else None
        self._text = TextDecoder(columns) if wire in ("auto", "text") else None
        store = SampleStore(out, header_comment or self._comment)
        self.result = CaptureResult(out, store, "", None, None, DeviceLog(store))
        self._t_wall0: float | None = None
        self.link = None  # the open port after run(keep_open=True), for the write-back

    def close(self) -> None:
        """Close the port kept open by ``run(keep_open=True)``."""
        if self.link is not None:
            self.link.close()
            self.link = None

    def link_stats(self):
        """The decoder's counts so far (frames: CRC errors, lost samples; text: bad lines)."""
        dec = self._frames or self._text
        return None if dec is None else dec.stats

    def _comment(self) -> str:
        h = self.result.hello
        dev = "" if h is None else (f"; device {h.firmware or '?'}, {h.sample_rate:g} Hz, sensitivity "
                                    f"{h.sensitivity:g} counts per {h.rate_unit}")
        return f"captured from {self.port} ({self.result.wire} at {self.baud} baud){dev}"

    # -- decoding --------------------------------------------------------------------------------------------

    def _decode(self, data: bytes) -> list:
        if self.result.wire is None:  # auto: the first decoder to find something wins
            got_f = self._frames.feed(data) if self._frames else []
            got_t = self._text.feed(data) if self._text else []
            if got_f:
                self.result.wire, self._text = "frames", None
            elif got_t:
                self.result.wire, self._frames = "text", None
            else:
                return []
            self.on_event("wire", self.result.wire)
            return got_f or got_t
        return (self._frames or self._text).feed(data)

    def _take(self, items: list) -> bool:
        """Record decoded items; True when a sample limit or the duration is reached."""
        r, store = self.result, self.result.store
        for item in items:
            if isinstance(item, (Sample, ImuSample)):
                t, g, temp, seq, a = item.t_us * 1e-6, item.raw, item.temp, item.seq, getattr(item, "accel", None)
            elif hasattr(item, "g"):  # a text Reading
                t, g, temp, seq, a = item.t, item.g, item.temp, None, item.a
            else:
                self._device_frame(item)
                if r.ended:
                    return True
                continue
            if self.duration is not None and self._beyond(t):
                r.ended = "duration"
                return True
            store.add(t, g, temp, seq, a)
            if self.max_samples is not None and len(store) >= self.max_samples:
                r.ended = "samples"
                return True
        return False

    def _beyond(self, t: float | None) -> bool:
        """Whether a sample at device time `t` [s] lies past the duration (wall time without stamps)."""
        t0 = self.result.store.t0
        if t is not None and t0 is not None:
            return t - t0 >= self.duration
        return t is None and time.monotonic() - self._t_wall0 >= self.duration

    def _device_frame(self, f) -> None:
        r = self.result
        if isinstance(f, Hello):
            if f != r.hello:  # a device may repeat its hello until someone listens
                r.hello = f
                self.on_event("hello", f)
        elif isinstance(f, Turn):
            r.device.turn(f)
            self.on_event("turn", f)
        elif isinstance(f, Result):
            r.device.result(f)
            self.on_event("result", f)
        elif isinstance(f, Calibrated):
            r.device.calibrated(f)
        elif isinstance(f, Text):
            r.messages.append(f.text)
            del r.messages[:-100]
            self.on_event("message", f.text)
        elif isinstance(f, End):
            r.sent = f.samples
            r.ended = "end of session"

    # -- the loop --------------------------------------------------------------------------------------------

    def run(self, stop: Callable[[], bool] = lambda: False,
            each: Callable[[Capture], bool] | None = None,
            keep_from: Callable[[], int | None] | None = None, keep_open: bool = False) -> CaptureResult:
        """Read until an end condition; `each` runs after every read and may end the capture (True);
        `keep_from` says from which sample (absolute index) on `each` still needs the samples in memory;
        `keep_open` leaves the port open in ``link`` (unless the link ended) for :meth:`close` to close:
        reopening a USB serial port resets many boards.

        Whatever ends it, the file holds every sample decoded and is put in place before returning.
        """
        ser = open_port(self.port, self.baud)  # first: without pyserial it says which extra to install
        import serial

        self.on_event("open", self.port)
        r = self.result
        self._t_wall0 = last_data = last_show = time.monotonic()
        stalled = False
        try:
            while not r.ended:
                if stop():
                    r.ended = "stopped"
                    break
                try:
                    # only what is waiting (or one byte): pyserial drops what a read gathered when the link
                    # ends inside that read
                    data = ser.read(ser.in_waiting or 1)
                except (serial.SerialException, OSError):
                    r.ended = "end of stream"
                    break
                now = time.monotonic()
                if data:
                    if stalled:
                        self.on_event("resumed", now - last_data)
                        r.stalls.append(now - last_data)
                        stalled = False
                    last_data = now
                    self._take(self._decode(data))
                elif not stalled and now - last_data >= self.stall:
                    stalled = True
                    self.on_event("stall", now - last_data)
                if self.silence is not None and now - last_data >= self.silence:
                    r.ended = "silence"
                if each is not None and each(self) and not r.ended:
                    r.ended = "guide complete"
                if now - last_show >= 0.5:
                    last_show = now
                    r.store.flush()
                    r.device.settle()
                    r.store.trim(None if keep_from is None else keep_from())
                    self.on_event("progress", self)
        finally:
            if keep_open and r.ended != "end of stream":
                self.link = ser
            else:
                ser.close()
            if self._text is not None and r.ended in ("", "end of stream"):  # a line cut by the link is bad; one
                self._text.finish()                                          # left unread on purpose is not
            r.ended = r.ended or "stopped"
            r.stats = self.link_stats()
            r.device.settle()
            r.path = r.store.finish()
        if stalled:
            r.stalls.append(time.monotonic() - last_data)
        return r
