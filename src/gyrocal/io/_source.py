"""Compressed text tables: which compression a file uses, and a byte stream of its content.

The compression is read from the file's first bytes, so a ``.csv.gz`` renamed ``.csv`` (or a
gzip file without a suffix) still reads; brotli has no magic number and is known by its
``.br`` suffix only. gzip, bz2 and xz decompress with the standard library; zstd, lz4 and
brotli need pyarrow (the ``arrow`` extra).
"""

from __future__ import annotations

import contextlib
import importlib
import os
from pathlib import Path
from typing import BinaryIO, Iterator

from ..errors import InputError, MissingDependencyError

__all__ = ["compression", "open_bytes", "arrow_input", "COMPRESSIONS"]

#: Compressions read, by the name pyarrow gives them ("xz" and "zip" are read by the standard library only).
COMPRESSIONS = ("gzip", "bz2", "xz", "zstd", "lz4", "brotli", "zip")
#: Compression -> the standard-library module whose ``open`` reads it (imported for a compressed file only).
_STDLIB = {"gzip": "gzip", "bz2": "bz2", "xz": "lzma"}
_SUFFIXES = {".gz": "gzip", ".gzip": "gzip", ".bz2": "bz2", ".xz": "xz", ".lzma": "xz", ".zst": "zstd",
             ".zstd": "zstd", ".lz4": "lz4", ".br": "brotli", ".zip": "zip"}


def _magic(head: bytes) -> str | None:
    if head.startswith(b"\x1f\x8b"):
        return "gzip"
    if head.startswith(b"BZh") and head[3:4].isdigit() and head[4:10] in (b"1AY&SY", b"\x17rE8P\x90"):
        return "bz2"  # block header, or the end-of-stream marker of an empty stream
    if head.startswith(b"\xfd7zXZ\x00"):
        return "xz"
    if head.startswith(b"\x28\xb5\x2f\xfd"):
        return "zstd"
    if head.startswith(b"\x04\x22\x4d\x18"):
        return "lz4"  # the LZ4 frame format (lz4 command line, python lz4.frame, pyarrow)
    if head.startswith(b"PK\x03\x04"):
        return "zip"
    return None


def compression(path: str | os.PathLike) -> str | None:
    """The compression of a file (one of :data:`COMPRESSIONS`), or None for a plain file."""
    path = Path(path)
    with open(path, "rb") as f:
        found = _magic(f.read(16))
    if found is None and path.suffix.lower() == ".br":
        found = "brotli"
    return found


def _zip_member(path: Path) -> str:
    import zipfile

    with zipfile.ZipFile(path) as z:
        names = [n for n in z.namelist() if not n.endswith("/") and not n.startswith("__MACOSX/")]
    if len(names) != 1:
        shown = ", ".join(names[:5]) + (", ..." if len(names) > 5 else "")
        raise InputError(f"{path.name}: a zip archive holding {len(names)} files ({shown or 'none'}); "
                         "unzip it and give the recording itself")
    return names[0]


def _need_arrow(path: Path, name: str):
    try:
        import pyarrow as pa
    except ImportError:
        raise MissingDependencyError(
            f"{path.name} is {name}-compressed; reading it needs pyarrow: pip install 'gyrocal[arrow]' "
            "(or decompress the file first)") from None
    if not pa.Codec.is_available(name):
        raise InputError(f"{path.name} is {name}-compressed and this pyarrow build cannot read {name}; "
                         "decompress the file first")
    return pa


def open_bytes(path: str | os.PathLike, name: str | None) -> BinaryIO:
    """A binary stream of the file's decompressed content (the file itself when `name` is None)."""
    path = Path(path)
    if name is None:
        return open(path, "rb")
    import lzma
    import zipfile

    try:
        if name in _STDLIB:
            return importlib.import_module(_STDLIB[name]).open(path, "rb")
        if name == "zip":
            z = zipfile.ZipFile(path)
            return z.open(_zip_member(path))
        pa = _need_arrow(path, name)
        return pa.input_stream(str(path), compression=name)
    except (OSError, EOFError, zipfile.BadZipFile, lzma.LZMAError) as exc:
        raise InputError(f"{path.name}: cannot decompress it as {name} ({exc})") from None


@contextlib.contextmanager
def arrow_input(path: str | os.PathLike, name: str | None) -> Iterator:
    """What ``pyarrow.csv.read_csv`` reads, closed after the block: the path of a plain file, else a
    decompressing stream (pyarrow's own codec where it has one, the standard library's for xz and zip)."""
    if name is None:
        yield str(path)
        return
    if name in ("gzip", "bz2", "zstd", "lz4", "brotli"):
        stream = _need_arrow(Path(path), name).input_stream(str(path), compression=name)
    else:
        stream = open_bytes(path, name)
    with stream:
        yield stream
