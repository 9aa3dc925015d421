"""What ``gyrocal capture`` shows while it runs, and how it stops: the status line, messages, signals."""

from __future__ import annotations

import signal
import sys
import time

from .app import console


class Stop:
    """SIGINT and SIGTERM set a flag the capture loop reads after each read: no byte read is dropped."""

    def __init__(self):
        self.requested = False
        self._old = {}

    def __enter__(self):
        for sig in (signal.SIGINT, signal.SIGTERM):
            self._old[sig] = signal.signal(sig, self._handle)
        return self

    def _handle(self, signum, frame):
        self.requested = True

    def __exit__(self, *exc):
        for sig, old in self._old.items():
            signal.signal(sig, old)

    def __call__(self) -> bool:
        return self.requested


class Progress:
    """One status line on stderr: redrawn in place on a terminal, every 10 s otherwise."""

    def __init__(self, quiet: bool):
        self.tty = sys.stderr.isatty()
        self.quiet = quiet
        self.last = 0.0

    def show(self, line: str) -> None:
        if self.quiet:
            return
        now = time.monotonic()
        if self.tty:
            sys.stderr.write("\r\x1b[K" + line)
            sys.stderr.flush()
        elif now - self.last >= 10.0:
            sys.stderr.write(line + "\n")
            self.last = now

    def clear(self) -> None:
        if self.tty and not self.quiet:
            sys.stderr.write("\r\x1b[K")


def say(progress: Progress, text: str) -> None:
    progress.clear()
    console.print(text, highlight=False, soft_wrap=True, markup=False)
