"""A virtual device: a simulated session served on a pseudo-terminal (or a local TCP socket), with faults.

``gyrocal capture`` reads it like a board on a USB serial port: the pseudo-terminal is put in
raw mode, so every byte passes unchanged. Faults on request: dropped bytes, corrupted bytes
(CRC errors), a stall (the device stops sending for a while, then goes on) and a disconnect
(the link is cut part way).

Closing a pseudo-terminal discards what the reader has not read yet, so the device closes the
link only when nothing can be lost. A session that ends with the end-of-session marker (an end
frame, or the text line ``# end of session``) is over when the reader, having read the marker,
closes the port: the device waits for that hang-up. A stream cut short (the disconnect fault,
or data without the marker) has no marker to wait for; there the device waits until the
reader's input queue has stayed empty for a while (the kernel hands written bytes to that
queue a little later), which is exact on an idle machine and very likely on a loaded one.

pyserial empties the input queue when it opens a port, so a device that starts before the
reader would lose its first bytes. Tests start the device once the reader has the port open
(:meth:`VirtualDevice.release`); for people (``gyrocal simulate --device``) the device repeats
its hello until it sees the reader take bytes or empty the queue, and only then starts.
"""

from __future__ import annotations

import fcntl
import os
import pty
import select
import socket
import struct
import termios
import threading
import time
import tty
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal, Self

import numpy as np

from ..errors import InputError
from .frames import End, FrameDecoder, Hello, encode, encode_samples
from .simulated import DeviceSession
from .text import END_LINE, text_lines

__all__ = ["Faults", "VirtualDevice", "damage", "device_bytes", "parse_faults", "preamble", "text_lines"]

Wire = Literal["frames", "text"]


@dataclass(frozen=True)
class Faults:
    """Faults of the link.

    Parameters
    ----------
    drop : float
        Probability that a byte is lost.
    corrupt : float
        Probability that a byte has one bit flipped.
    stall_at : float, optional
        Where the device stops sending, as a fraction of the stream (0..1).
    stall_s : float
        How long it stops [s].
    disconnect_at : float, optional
        Where the link is cut, as a fraction of the stream (0..1).
    seed : int
        Seed of the generator that picks the damaged bytes.
    """

    drop: float = 0.0
    corrupt: float = 0.0
    stall_at: float | None = None
    stall_s: float = 2.0
    disconnect_at: float | None = None
    seed: int = 0

    def __post_init__(self):
        for name in ("drop", "corrupt", "stall_at", "disconnect_at"):
            v = getattr(self, name)
            if v is not None and not 0 <= v <= 1:
                raise InputError(f"the {name} fault must be a fraction in [0, 1], got {v!r}", param="faults", value=v)
        if not self.stall_s >= 0:
            raise InputError(f"a stall must last >= 0 s, got {self.stall_s!r}", param="faults", value=self.stall_s)


def parse_faults(spec: str | None, seed: int = 0) -> Faults:
    """Faults from ``"drop=1e-4,corrupt=1e-4,stall=0.5:2,disconnect=0.8"`` (the ``--faults`` syntax)."""
    kw: dict = {"seed": seed}
    for item in filter(None, (p.strip() for p in (spec or "").split(","))):
        key, _, value = item.partition("=")
        try:
            if key == "stall":
                at, _, secs = value.partition(":")
                kw["stall_at"], kw["stall_s"] = float(at), float(secs or 2.0)
            elif key in ("drop", "corrupt"):
                kw[key] = float(value)
            elif key == "disconnect":
                kw["disconnect_at"] = float(value)
            else:
                raise ValueError(key)
        except ValueError:
            raise InputError(f"{{param}} entry {item!r} is not understood", param="faults", value=spec,
                             hint="write e.g. {param} drop=1e-4,corrupt=1e-4,stall=0.5:2,disconnect=0.8 (drop and "
                                  "corrupt per byte; stall and disconnect where, as a fraction of the stream)") from None
    return Faults(**kw)


@dataclass(frozen=True)
class Damage:
    """Which bytes of the stream the faults removed or changed (indices into the undamaged stream)."""

    dropped: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    corrupted: np.ndarray = field(default_factory=lambda: np.zeros(0, int))


def damage(data: bytes, faults: Faults) -> tuple[bytes, Damage]:
    """Apply the byte faults (drop, corrupt) to `data`; the stall and disconnect happen while serving."""
    if not (faults.drop or faults.corrupt):
        return data, Damage()
    rng = np.random.default_rng(faults.seed)
    buf = np.frombuffer(data, np.uint8).copy()
    corrupted = np.flatnonzero(rng.random(len(buf)) < faults.corrupt)
    buf[corrupted] ^= (1 << rng.integers(0, 8, len(corrupted))).astype(np.uint8)
    dropped = np.flatnonzero(rng.random(len(buf)) < faults.drop)
    keep = np.ones(len(buf), bool)
    keep[dropped] = False
    return buf[keep].tobytes(), Damage(dropped, corrupted)


def device_bytes(session: DeviceSession, wire: Wire = "frames", encoder: Literal["c", "python"] = "c") -> bytes:
    """What a device sends for `session`: text lines, or gyrocal frames from the C library (the example
    firmware: samples, turns, its own calibration and corrected samples) or from Python (samples only);
    6-axis frames when the session has an accelerometer. Every stream ends with the end-of-session marker."""
    if wire == "text":
        return text_lines(session)
    if wire != "frames":
        raise InputError(f"{{param}} must be 'frames' or 'text', got {wire!r}", param="wire", value=wire)
    accel_sens = int(session.accel_sensitivity or 0)
    if encoder == "c":
        from .c_device import firmware_stream

        return firmware_stream(session.raw, session.t_us, session.temp, sample_rate=session.sample_rate,
                               sensitivity=session.sensitivity, accel=session.accel, accel_sensitivity=accel_sens)
    hello = Hello(session.sample_rate, session.sensitivity, "deg/s", session.temp is not None, firmware="gyrocal-sim",
                  accel_sensitivity=accel_sens or None)
    samples = encode_samples(np.arange(len(session)), session.t_us, session.raw, session.temp, session.accel)
    return encode(hello) + samples + encode(End(len(session)))


def preamble(data: bytes) -> bytes:
    """What a device repeats until a reader listens: its hello frame, or an empty line for text."""
    frames = FrameDecoder().feed(data[:64])
    return encode(frames[0]) if frames and isinstance(frames[0], Hello) else b"\r\n"


def _ends_session(data: bytes) -> bool:
    """Whether `data` ends with the end-of-session marker (an end frame, or the text line)."""
    if data.rstrip().endswith(END_LINE.encode()):
        return True
    tail = FrameDecoder().feed(data[-(End.FORMAT.size + 6):])
    return bool(tail) and isinstance(tail[-1], End)


class VirtualDevice:
    """Serve `data` on a pseudo-terminal (``transport="pty"``) or a local TCP port (``"tcp"``).

    Parameters
    ----------
    data : bytes
        The stream (already damaged by :func:`damage` if wanted).
    faults : Faults
        Its stall and disconnect are applied while serving.
    byte_rate : float, optional
        Pace [bytes/s] (the baud rate over 10 for 8N1); default as fast as the reader takes them.
    wait_for : {"release", "reader"}
        When sending starts: on :meth:`release` (a test calls it once the reader has the port open:
        pyserial discards what is waiting when it opens a port), or once a reader has opened the
        pseudo-terminal (the device repeats :func:`preamble` until the reader takes bytes or empties
        the queue; for people, not for tests).
    drain_timeout : float
        Longest wait for the reader to take everything or to hang up [s].
    answer : callable(bytes) -> bytes, optional
        What the device answers to bytes the host sends (``CStorage``: the write-back), on a
        pseudo-terminal; without it the device never reads what the host sends.
    """

    def __init__(self, data: bytes, *, faults: Faults = Faults(), byte_rate: float | None = None,
                 transport: Literal["pty", "tcp"] = "pty", chunk: int = 256, drain_timeout: float = 60.0,
                 wait_for: Literal["release", "reader"] = "release", answer: Callable[[bytes], bytes] | None = None):
        self.data, self.faults, self.byte_rate, self.transport = data, faults, byte_rate, transport
        self.answer = answer
        self.wait_for = wait_for
        self._go = threading.Event()
        self.paused = threading.Event()  # set once the reader has taken everything sent before the stall
        self._resume = threading.Event()
        self.chunk, self.drain_timeout = chunk, drain_timeout
        self.sent = 0
        self.done = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    # -- life cycle ------------------------------------------------------------------------------------------

    def start(self) -> str:
        """Start serving; returns the port to give ``gyrocal capture --port``."""
        if self.transport == "pty":
            self._master, self._slave = pty.openpty()
            tty.setraw(self._slave)  # no echo, no newline translation: binary passes unchanged
            port = self._path = os.ttyname(self._slave)
            target = self._serve_pty
        else:
            self._server = socket.create_server(("127.0.0.1", 0))
            port = f"socket://127.0.0.1:{self._server.getsockname()[1]}"
            target = self._serve_tcp
        self._thread = threading.Thread(target=target, name="gyrocal-virtual-device", daemon=True)
        self._thread.start()
        return port

    def release(self) -> None:
        """Start sending (the reader has opened the port)."""
        self._go.set()

    def resume(self) -> None:
        """End the stall now."""
        self._resume.set()

    def _wait_to_start(self) -> None:
        if self.wait_for == "reader" and self.transport == "pty":
            self._wait_for_reader()
        while not (self._go.is_set() or self._stop.is_set()):
            self._go.wait(0.2)

    def _wait_for_reader(self, cap: int = 2048) -> None:
        """Repeat the preamble until the reader's queue shrinks: it read bytes, or pyserial emptied it on
        opening the port. Either way the emptying is over, and nothing sent from now on is lost."""
        pre, written, most = preamble(self.data), 0, 0
        while not self._stop.is_set():
            if written < cap and select.select([], [self._master], [], 0)[1]:
                written += os.write(self._master, pre)
            queued = self._unread()
            if queued < most:
                self._go.set()
                return
            most = max(most, queued)
            self._stop.wait(0.02)

    def wait(self, timeout: float | None = None) -> bool:
        """Wait until the device has sent everything and closed the link."""
        return self.done.wait(timeout)

    def close(self) -> None:
        self._stop.set()
        self._resume.set()
        if self._thread is not None:
            self._thread.join(5.0)

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # -- serving ---------------------------------------------------------------------------------------------

    def _plan(self) -> tuple[int, int | None]:
        n = len(self.data)
        cut = n if self.faults.disconnect_at is None else int(self.faults.disconnect_at * n)
        stall = None if self.faults.stall_at is None else int(self.faults.stall_at * n)
        return cut, stall

    def _pieces(self):
        """The stream in pieces, paced, with the stall and the cut."""
        cut, stall = self._plan()
        t0 = time.monotonic()
        pos = 0
        while pos < cut and not self._stop.is_set():
            if stall is not None and pos == stall:
                if self.transport == "pty":
                    self._drain()
                self.paused.set()
                self._resume.wait(self.faults.stall_s)
                t0 += self.faults.stall_s  # pace on from here, no burst to catch up
                stall = None
                continue
            end = min(pos + self.chunk, cut)
            if stall is not None and pos < stall < end:
                end = stall
            if self.byte_rate:
                ahead = t0 + end / self.byte_rate - time.monotonic()
                if ahead > 0:
                    self._stop.wait(ahead)
            yield self.data[pos:end]
            pos = end

    def _serve_pty(self) -> None:
        try:
            self._wait_to_start()
            # from now on only the reader holds the port open, so its hang-up shows on the master
            os.close(self._slave)
            self._slave = None
            for piece in self._pieces():
                view = memoryview(piece)
                while view and not self._stop.is_set():
                    if self._hung_up():
                        return  # the reader has gone (its capture ended): nobody to send to
                    readable, writable, _ = select.select(self._listen(), [self._master], [], 0.2)
                    if readable:
                        self._take_input()
                    if writable:
                        n = os.write(self._master, view)
                        view = view[n:]
                        self.sent += n
            if self.sent == len(self.data) and _ends_session(self.data):
                self._hang_up_wait()
            else:
                self._drain()
        finally:
            os.close(self._master)
            if self._slave is not None:
                os.close(self._slave)
            self.done.set()

    def _hung_up(self, timeout_ms: int = 0) -> bool:
        poll = select.poll()
        poll.register(self._master, select.POLLHUP)
        return bool(poll.poll(timeout_ms))

    def _listen(self) -> list[int]:
        return [self._master] if self.answer is not None else []

    def _take_input(self) -> None:
        """Read what the host sent and send the answer (the host writes back a calibration)."""
        try:
            reply = self.answer(os.read(self._master, 4096))
            if reply:
                os.write(self._master, reply)
        except OSError:  # the reader hung up meanwhile
            pass

    def _hang_up_wait(self) -> None:
        """Wait until the reader, having read the end-of-session marker, closes the port; answer it meanwhile."""
        deadline = time.monotonic() + self.drain_timeout
        while not self._stop.is_set() and time.monotonic() < deadline:
            if self._hung_up(200):
                return
            if self._listen() and select.select(self._listen(), [], [], 0)[0]:
                self._take_input()

    def _unread(self) -> int:
        """Bytes sent that the reader has not read yet (its input queue; the port is opened for a moment when
        the device no longer holds it, which does not disturb the reader)."""
        fd = self._slave if self._slave is not None else os.open(self._path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        try:
            return struct.unpack("i", fcntl.ioctl(fd, termios.FIONREAD, struct.pack("i", 0)))[0]
        finally:
            if fd != self._slave:
                os.close(fd)

    def _drain(self, quiet: float = 0.5) -> None:
        """Wait until the reader has taken every byte sent: closing a pty discards unread input.

        The kernel hands written bytes to the reader's queue a little later (a work queue), so the
        queue must stay empty for `quiet` seconds, not only once.
        """
        deadline = time.monotonic() + self.drain_timeout
        empty_since = None
        while time.monotonic() < deadline and not self._stop.is_set():
            now = time.monotonic()
            if self._hung_up():
                return
            if self._unread():
                empty_since = None
            elif empty_since is None:
                empty_since = now
            elif now - empty_since >= quiet:
                return
            self._stop.wait(0.01)

    def _serve_tcp(self) -> None:
        try:
            self._server.settimeout(self.drain_timeout)
            conn, _ = self._server.accept()
            with conn:
                self._wait_to_start()
                for piece in self._pieces():
                    conn.sendall(piece)
                    self.sent += len(piece)
                conn.shutdown(socket.SHUT_WR)  # a clean end: the reader gets every byte, then end of stream
                conn.settimeout(self.drain_timeout)
                while conn.recv(4096):
                    pass
        except OSError:
            pass
        finally:
            self._server.close()
            self.done.set()
