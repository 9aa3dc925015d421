"""Connections to a store: the SQLAlchemy engine, SQLite's locking settings, retries and one-line errors.

SQLite runs in WAL mode (readers never wait for the writer) with a busy timeout; every write
transaction starts with ``BEGIN IMMEDIATE``, so it takes the file's write lock at once and waits for
it there (a deferred transaction that upgrades its lock later can fail with "database is locked"
whatever the timeout). A transaction that still finds the file locked is retried from the start.
PostgreSQL runs each call in one transaction.
"""

from __future__ import annotations

import random
import time
from collections.abc import Callable
from typing import TypeVar

from sqlalchemy import create_engine, event
from sqlalchemy.engine import Connection, Engine
from sqlalchemy.exc import DBAPIError, OperationalError

from ..errors import StoreError
from .urls import StoreURL

__all__ = ["make_engine", "write", "read", "BUSY_TIMEOUT_S", "ATTEMPTS"]

T = TypeVar("T")

#: Seconds SQLite waits for the write lock before reporting "database is locked".
BUSY_TIMEOUT_S = 30.0
#: Transactions tried in all when SQLite still reports the file locked or busy.
ATTEMPTS = 8
#: Seconds PostgreSQL may take to accept a connection.
CONNECT_TIMEOUT_S = 10
_READ = "gyrocal_read_only"


def _sqlite_engine(url: StoreURL) -> Engine:
    engine = create_engine(url.sqlalchemy_url, connect_args={"timeout": BUSY_TIMEOUT_S})

    @event.listens_for(engine, "connect")
    def _on_connect(dbapi_connection, _record):
        dbapi_connection.isolation_level = None  # no implicit BEGIN from sqlite3: the "begin" hook below says which
        cursor = dbapi_connection.cursor()
        try:
            cursor.execute(f"PRAGMA busy_timeout = {int(BUSY_TIMEOUT_S * 1000)}")
            cursor.execute("PRAGMA journal_mode = WAL")
            cursor.execute("PRAGMA synchronous = FULL")
        finally:
            cursor.close()

    @event.listens_for(engine, "begin")
    def _on_begin(connection):
        read_only = connection.get_execution_options().get(_READ, False)
        connection.exec_driver_sql("BEGIN" if read_only else "BEGIN IMMEDIATE")

    return engine


def make_engine(url: StoreURL) -> Engine:
    """An engine for `url`: SQLite with WAL and immediate write transactions, or PostgreSQL via psycopg 3."""
    if url.dialect == "sqlite":
        return _sqlite_engine(url)
    return create_engine(url.sqlalchemy_url, pool_pre_ping=True,
                         connect_args={"connect_timeout": CONNECT_TIMEOUT_S, "application_name": "gyrocal"})


def _locked(exc: BaseException) -> bool:
    text = str(getattr(exc, "orig", exc)).lower()
    return "database is locked" in text or "database is busy" in text or "database table is locked" in text


def _first_line(exc: BaseException) -> str:
    text = str(getattr(exc, "orig", None) or exc).strip()
    line = text.splitlines()[0] if text else type(exc).__name__
    return line.removeprefix("connection failed: ").strip()


def store_error(url: StoreURL, exc: BaseException) -> StoreError:
    """One line for a database error: which store, and what the driver said."""
    if isinstance(exc, OperationalError) and url.dialect == "postgresql":
        return StoreError(f"cannot reach store {url.display}: {_first_line(exc)}",
                          hint="check that the PostgreSQL server runs and the URL's host, port and database")
    if _locked(exc):
        return StoreError(f"store {url.display} stayed locked by another writer ({ATTEMPTS} tries, each waiting "
                          f"up to {BUSY_TIMEOUT_S:g} s)")
    return StoreError(f"cannot use store {url.display}: {_first_line(exc)}")


def _transaction(engine: Engine, url: StoreURL, work: Callable[[Connection], T], read_only: bool) -> T:
    for attempt in range(ATTEMPTS):
        try:
            with engine.connect() as connection:
                if read_only:
                    connection = connection.execution_options(**{_READ: True})
                with connection.begin():
                    return work(connection)
        except DBAPIError as exc:
            if url.dialect == "sqlite" and _locked(exc) and attempt + 1 < ATTEMPTS:
                time.sleep(random.uniform(0.01, 0.05) * (attempt + 1))
                continue
            raise store_error(url, exc) from None
    raise AssertionError("unreachable")  # the last attempt returns or raises


def write(engine: Engine, url: StoreURL, work: Callable[[Connection], T]) -> T:
    """`work(connection)` in one write transaction (SQLite: ``BEGIN IMMEDIATE``), retried while locked."""
    return _transaction(engine, url, work, read_only=False)


def read(engine: Engine, url: StoreURL, work: Callable[[Connection], T]) -> T:
    """`work(connection)` in one read transaction, retried while locked."""
    return _transaction(engine, url, work, read_only=True)
