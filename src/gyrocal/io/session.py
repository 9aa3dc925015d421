"""Sessions of several recordings: one file, or a folder with one file per part (for example
one per temperature point of a turntable session)."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError
from ..recording import Recording
from .reader import read_recording

__all__ = ["SESSION_SUFFIXES", "read_session"]

#: Files of a session folder that are read (sorted by name); anything else is left alone.
SESSION_SUFFIXES = (".csv", ".txt", ".parquet", ".pq", ".bag", ".mcap", ".db3")


def read_session(path: str | os.PathLike, *, units: str, **read_options) -> tuple[list[Recording], list[str]]:
    """Read a session: one file, or a folder with one file per part.

    Parameters
    ----------
    path : path
        A recording file or a folder of them (:data:`SESSION_SUFFIXES`; sorted by name).
    units : str
        Unit of the readings and of ``table_rate`` (``deg/s``, ``rad/s``, ``counts``).
    **read_options
        Passed to :func:`gyrocal.io.read_recording` (``columns``, ``sensitivity``, ...).

    Returns
    -------
    recordings : list of Recording
    names : list of str
        The file names, for messages.
    """
    p = Path(path)
    if p.is_dir():
        files = sorted(f for f in p.iterdir() if f.is_file() and f.suffix.lower() in SESSION_SUFFIXES)
        if not files:
            raise InputError(f"{p}: the folder holds no recordings ({', '.join(SESSION_SUFFIXES)})")
    elif p.exists():
        files = [p]
    else:
        raise InputError(f"{p}: no such file or folder")
    return [read_recording(f, units=units, **read_options) for f in files], [f.name for f in files]
