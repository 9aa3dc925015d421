"""A virtual device: a simulated session served on a pseudo-terminal (or a local TCP socket), with faults.

``gyrocal capture`` reads it like a board on a USB serial port: the pseudo-terminal is put in
raw mode, so every byte passes unchanged. Faults on request: dropped bytes, corrupted bytes
(CRC errors), a stall (the device stops sending for a while, then goes on) and a disconnect
(the link is cut part way). Before it closes the link, the device waits until the reader has
taken every byte already sent, so "what was sent before the cut" is exact.
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
from dataclasses import dataclass, field
from typing import Literal, Self

import numpy as np

from ..errors import InputError
from .frames import Hello, encode, encode_samples
from .simulated import DeviceSession

__all__ = ["Faults", "VirtualDevice", "damage", "device_bytes", "parse_faults", "text_lines"]

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


def text_lines(session: DeviceSession) -> bytes:
    """The session as an Arduino sketch prints it with ``Serial.println``: ``t_us,gx,gy,gz[,temp]``."""
    head = "t_us,gx,gy,gz" + (",temp" if session.temp is not None else "")
    cols = [session.t_us.astype(str), *(session.raw[:, j].astype(str) for j in range(3))]
    if session.temp is not None:
        cols.append(np.char.mod("%.2f", session.temp))
    rows = cols[0]
    for c in cols[1:]:
        rows = np.char.add(np.char.add(rows, ","), c)
    return (head + "\r\n" + "\r\n".join(rows.tolist()) + "\r\n").encode()


def device_bytes(session: DeviceSession, wire: Wire = "frames", encoder: Literal["c", "python"] = "c") -> bytes:
    """What a device sends for `session`: text lines, or gyrocal frames from the C library (the example
    firmware: samples, turns, its own calibration and corrected samples) or from Python (samples only)."""
    if wire == "text":
        return text_lines(session)
    if wire != "frames":
        raise InputError(f"{{param}} must be 'frames' or 'text', got {wire!r}", param="wire", value=wire)
    if encoder == "c":
        from .c_device import firmware_stream

        return firmware_stream(session.raw, session.t_us, session.temp, sample_rate=session.sample_rate,
                               sensitivity=session.sensitivity)
    hello = Hello(session.sample_rate, session.sensitivity, "deg/s", session.temp is not None, firmware="gyrocal-sim")
    return encode(hello) + encode_samples(np.arange(len(session)), session.t_us, session.raw, session.temp)


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
        pyserial discards what is waiting when it opens a port), or when a reader opens the
        pseudo-terminal (seen as its settings changing, then ``settle`` seconds for pyserial to
        finish opening; for people, not for tests).
    """

    def __init__(self, data: bytes, *, faults: Faults = Faults(), byte_rate: float | None = None,
                 transport: Literal["pty", "tcp"] = "pty", chunk: int = 256, drain_timeout: float = 60.0,
                 wait_for: Literal["release", "reader"] = "release", settle: float = 0.5):
        self.data, self.faults, self.byte_rate, self.transport = data, faults, byte_rate, transport
        self.wait_for, self.settle = wait_for, settle
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
            port = os.ttyname(self._slave)
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
            mine = termios.tcgetattr(self._slave)
            while not self._stop.is_set() and termios.tcgetattr(self._slave) == mine:
                self._stop.wait(0.05)
            self._stop.wait(self.settle)
            self._go.set()
        while not (self._go.is_set() or self._stop.is_set()):
            self._go.wait(0.2)

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
        self._wait_to_start()
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
            for piece in self._pieces():
                view = memoryview(piece)
                while view and not self._stop.is_set():
                    if select.select([], [self._master], [], 0.2)[1]:
                        n = os.write(self._master, view)
                        view = view[n:]
                        self.sent += n
            self._drain()
        finally:
            os.close(self._master)
            os.close(self._slave)
            self.done.set()

    def _unread(self) -> int:
        buf = fcntl.ioctl(self._slave, termios.FIONREAD, struct.pack("i", 0))
        return struct.unpack("i", buf)[0]

    def _drain(self, quiet: float = 0.5) -> None:
        """Wait until the reader has taken every byte sent: closing a pty discards unread input.

        The kernel hands written bytes to the reader's queue a little later (a work queue), so the
        queue must stay empty for `quiet` seconds, not only once.
        """
        deadline = time.monotonic() + self.drain_timeout
        empty_since = None
        while time.monotonic() < deadline and not self._stop.is_set():
            now = time.monotonic()
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
