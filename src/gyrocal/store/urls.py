"""Where a calibration store lives: a store URL or a bare path, parsed without importing SQLAlchemy.

Accepted forms:

* a bare path (``calibrations.db``, ``/var/lib/gyrocal/store.db``): an SQLite file;
* ``sqlite:///relative/path.db`` and ``sqlite:////absolute/path.db``: an SQLite file (SQLAlchemy's spelling);
* ``postgresql://user[:password]@host[:port]/database`` (also ``postgres://`` and ``postgresql+psycopg://``):
  a PostgreSQL server, driven by psycopg 3. A ``host=/socket/dir`` query parameter reaches a Unix socket.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import urlsplit, urlunsplit

from ..errors import InputError

__all__ = ["StoreURL", "parse_url"]

_SCHEME = re.compile(r"^([A-Za-z][A-Za-z0-9+.\-]*)://")
_POSTGRES_SCHEMES = ("postgresql", "postgres", "postgresql+psycopg")
_SQLITE_SCHEMES = ("sqlite", "sqlite+pysqlite")


@dataclass(frozen=True)
class StoreURL:
    """A parsed store location.

    Attributes
    ----------
    dialect : {"sqlite", "postgresql"}
        The kind of database.
    sqlalchemy_url : str
        The URL handed to SQLAlchemy (``sqlite:////abs/path`` or ``postgresql+psycopg://...``).
    path : pathlib.Path or None
        The SQLite file (absolute), None for PostgreSQL.
    display : str
        The location with any password masked, for messages.
    """

    dialect: str
    sqlalchemy_url: str
    path: Path | None
    display: str


def _sqlite(path_text: str, original: str) -> StoreURL:
    if not path_text or path_text == ":memory:":
        raise InputError(f"store {original!r} names no file; give a path such as calibrations.db "
                         "(an in-memory database would forget every record)")
    path = Path(path_text).expanduser().absolute()
    if path.is_dir():
        raise InputError(f"store {original!r} is a directory; give a file name inside it such as {path}/store.db")
    return StoreURL("sqlite", f"sqlite:///{path}", path, str(path))


def _mask(parts) -> str:
    if parts.password is None:
        return urlunsplit(parts)
    netloc = parts.netloc.replace(f":{parts.password}@", ":***@", 1)
    return urlunsplit(parts._replace(netloc=netloc))


def _postgres(text: str) -> StoreURL:
    parts = urlsplit(text)
    try:
        parts.port  # noqa: B018 - validates the port
    except ValueError:
        raise InputError(f"store URL {_mask(parts)!r} has a port that is not a number") from None
    database = parts.path.lstrip("/")
    if not database or "/" in database:
        raise InputError(f"store URL {_mask(parts)!r} names no database; write postgresql://user@host:port/DATABASE")
    url = urlunsplit(parts._replace(scheme="postgresql+psycopg"))
    return StoreURL("postgresql", url, None, _mask(parts))


def parse_url(url: str | Path) -> StoreURL:
    """Parse a store location: a bare path or ``sqlite://`` URL (SQLite), or a ``postgresql://`` URL.

    Parameters
    ----------
    url : str or pathlib.Path
        The location, as the user wrote it.

    Returns
    -------
    StoreURL

    Raises
    ------
    gyrocal.errors.InputError
        The location is empty, a directory, in memory, or of an unknown scheme.
    """
    if isinstance(url, Path):
        return _sqlite(str(url), str(url))
    if not isinstance(url, str) or not url.strip():
        raise InputError("no store given; pass a file name (calibrations.db) or postgresql://user@host:port/db")
    text = url.strip()
    match = _SCHEME.match(text)
    if match is None:
        return _sqlite(text, url)
    scheme = match.group(1).lower()
    if scheme in _SQLITE_SCHEMES:
        # sqlite:///rel/path -> "rel/path"; sqlite:////abs/path -> "/abs/path"
        return _sqlite(text[match.end():].removeprefix("/"), url)
    if scheme in _POSTGRES_SCHEMES:
        return _postgres(text)
    raise InputError(f"store URL scheme {scheme!r} is not supported; use a file name, sqlite:///path "
                     "or postgresql://user@host:port/db")
