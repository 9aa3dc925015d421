"""Atomic file output: a failed run leaves no half-written file and destroys nothing.

A run stopped by Ctrl-C, by SIGTERM (``kill``, a job scheduler, ``timeout``) or by SIGHUP (a
closed terminal) is a failed run too: while a temporary file is open, those signals raise
:class:`Terminated` in the main thread, the temporary is removed on the way out, and the
process then dies of the same signal, as it would have without gyrocal's help.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from pathlib import Path
from typing import Iterator

__all__ = ["atomic_folder", "atomic_path", "write_text_atomic", "Terminated"]

_SIGNALS = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name))


class Terminated(BaseException):
    """A terminating signal arrived while an atomic write was open (a BaseException, like
    KeyboardInterrupt, so that no ``except Exception`` swallows it)."""

    def __init__(self, signum: int):
        super().__init__(f"terminated by signal {signum}")
        self.signum = signum


def _raise(signum, frame):
    raise Terminated(signum)


@contextlib.contextmanager
def _cleanup_on_signals() -> Iterator[None]:
    """Turn SIGTERM/SIGHUP into :class:`Terminated` inside the block, where their default action
    (die at once) would leave a temporary file behind; then die of the signal all the same.

    Only the main thread may set handlers, and a handler the program set itself is left alone.
    """
    mine = []
    if threading.current_thread() is threading.main_thread():
        mine = [s for s in _SIGNALS if signal.getsignal(s) is signal.SIG_DFL]
        for s in mine:
            signal.signal(s, _raise)
    try:
        yield
    except Terminated as exc:
        if exc.signum not in mine:
            raise  # an outer block installed the handler: it re-sends the signal
        for s in mine:
            signal.signal(s, signal.SIG_DFL)
        mine = []
        os.kill(os.getpid(), exc.signum)
        raise  # where the signal does not kill at once
    finally:
        for s in mine:
            signal.signal(s, signal.SIG_DFL)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside `path`; move it into place only if the block succeeds.

    Writers that need a file name (matplotlib, pyarrow) write to the yielded path.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    with _cleanup_on_signals():
        tmp_path = _new_temporary(target)
        try:
            yield tmp_path
            os.replace(tmp_path, target)
        finally:
            if tmp_path.exists():
                tmp_path.unlink()


def _new_temporary(target: Path) -> Path:
    # Not mkstemp: it makes the file private (0600). O_EXCL keeps the name ours, and the kernel
    # applies the umask to 0666 as for any new file; a replaced file keeps its own mode.
    while True:
        tmp_path = target.parent / f".{target.name}.{os.urandom(4).hex()}.tmp{target.suffix}"
        try:
            os.close(os.open(tmp_path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
            break
        except FileExistsError:
            continue
    if target.exists():
        os.chmod(tmp_path, target.stat().st_mode & 0o7777)
    return tmp_path


def write_text_atomic(path: str | os.PathLike, text: str) -> None:
    """Write `text` to `path` atomically (UTF-8)."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


@contextlib.contextmanager
def atomic_folder(path: str | os.PathLike) -> Iterator[Path]:
    """Yield an empty temporary folder beside `path`; when the block succeeds, move each file written in it
    into `path` (created if need be), replacing only those names there, the ones named ``*.md`` last.

    A block that fails (or a terminating signal) leaves `path` as it was and no temporary behind.
    """
    import shutil

    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    with _cleanup_on_signals():
        while True:
            tmp = target.parent / f".{target.name}.{os.urandom(4).hex()}.tmp"
            try:
                tmp.mkdir()
                break
            except FileExistsError:
                continue
        try:
            yield tmp
            target.mkdir(exist_ok=True)
            for item in sorted(tmp.iterdir(), key=lambda p: (p.suffix == ".md", p.name)):
                os.replace(item, target / item.name)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
