"""A plain text file's lines a MiB at a time as pyarrow strings over the bytes read, and work on such
blocks on every core, taken in file order (pyarrow's compute kernels release the GIL)."""

from __future__ import annotations

import codecs
import os
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pyarrow as pa

__all__ = ["in_order", "line_blocks", "lines_of"]

_BLOCK = 1 << 20  # bytes of text a block: a few are in flight at a time


def line_blocks(path: Path, skip: int) -> Iterator[memoryview]:
    """The bytes of a plain file's lines after its first `skip`, whole lines a block at a time (see
    :func:`lines_of`). Raises ValueError where a line ends in a bare CR."""
    with open(path, "rb") as f:
        tail = f.read(_BLOCK)
        tail = tail[len(codecs.BOM_UTF8):] if tail.startswith(codecs.BOM_UTF8) else tail
        _newlines_only(tail, tail.rfind(b"\n") + 1 or len(tail))  # before the lines to skip are counted
        pos = 0
        for _ in range(skip):  # the lines above the data
            while (cut := tail.find(b"\n", pos)) < 0 and (more := f.read(_BLOCK)):
                tail += more
            pos = cut + 1 if cut >= 0 else len(tail)
        tail = tail[pos:]
        while True:
            more = f.read(_BLOCK)
            data = tail + more if tail else more
            if not data:
                return
            cut = data.rfind(b"\n") + 1 if more else len(data)  # whole lines; at the end, the rest
            tail = data[cut:]
            if cut:
                _newlines_only(data, cut)
                yield memoryview(data)[:cut]
            if not more:
                return


def _newlines_only(data: bytes, end: int) -> None:
    if data.find(b"\r", 0, end) >= 0 and data.count(b"\r", 0, end) != data.count(b"\r\n", 0, end):
        raise ValueError("a line ends in a bare CR")


def lines_of(buf: memoryview) -> pa.StringArray:
    """The lines of a block as a string array over its bytes (no copy), each with its line end. Raises
    pa.ArrowInvalid on bytes that are not UTF-8."""
    ends = np.flatnonzero(np.frombuffer(buf, dtype=np.uint8) == ord("\n")) + 1
    if not len(ends) or ends[-1] != len(buf):
        ends = np.append(ends, len(buf))
    offsets = np.concatenate(([0], ends)).astype(np.int32)
    lines = pa.StringArray.from_buffers(len(ends), pa.py_buffer(offsets), pa.py_buffer(buf))
    if not buf.obj.isascii():  # ASCII is UTF-8; else a full check
        lines.validate(full=True)
    return lines


def in_order(chunks: Iterable, work: Callable, take: Callable) -> None:
    """``take(work(chunk))`` for each chunk, `work` on every core a few chunks ahead of the one whose
    result `take` receives, in order; each chunk goes once its result is taken."""
    workers = os.cpu_count() or 1
    with ThreadPoolExecutor(workers) as pool:
        pending: deque = deque()
        for chunk in chunks:
            pending.append(pool.submit(work, chunk))
            del chunk
            if len(pending) > workers:
                take(pending.popleft().result())
        while pending:
            take(pending.popleft().result())
