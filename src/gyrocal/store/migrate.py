"""Create or upgrade a store's schema with the Alembic migrations bundled in ``gyrocal/store/migrations``.

No ``alembic.ini`` is read: the configuration is built here. The revision check and the migrations run
in one transaction that first takes a lock (SQLite: ``BEGIN IMMEDIATE``, the file's write lock;
PostgreSQL: a transaction-scoped advisory lock), so two processes creating the same fresh store at once
both succeed: the second waits, then finds the schema current. A store stamped with a revision this
gyrocal does not know (written by a newer gyrocal) is refused before anything is changed.
"""

from __future__ import annotations

import functools
from pathlib import Path

from alembic import command
from alembic.config import Config
from alembic.runtime.migration import MigrationContext
from alembic.script import ScriptDirectory
from sqlalchemy import text
from sqlalchemy.engine import Connection, Engine

from ..errors import StoreError
from .engine import write
from .urls import StoreURL

__all__ = ["MIGRATIONS", "known_revisions", "current_revisions", "upgrade"]

#: The bundled migration scripts (env.py, versions/).
MIGRATIONS = Path(__file__).with_name("migrations")
#: Key of PostgreSQL's advisory lock held while the schema is checked and migrated ("gyrocal" in ASCII).
_PG_LOCK = 0x6779726F63616C


def _config(connection: Connection | None = None) -> Config:
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    config.set_main_option("path_separator", "os")
    if connection is not None:
        config.attributes["connection"] = connection
    return config


@functools.cache
def _scripts() -> ScriptDirectory:
    """The bundled migrations, read once per process (a store is opened for every unit of a batch)."""
    return ScriptDirectory.from_config(_config())


@functools.cache
def known_revisions() -> frozenset[str]:
    """Every schema revision this gyrocal's migrations define."""
    return frozenset(script.revision for script in _scripts().walk_revisions())


def current_revisions(connection: Connection) -> tuple[str, ...]:
    """The revisions stamped in the store (empty for a fresh one)."""
    return tuple(MigrationContext.configure(connection).get_current_heads())


def _migrate(connection: Connection, url: StoreURL) -> tuple[str, ...]:
    if connection.dialect.name == "postgresql":
        connection.execute(text("SELECT pg_advisory_xact_lock(:key)"), {"key": _PG_LOCK})
    current = current_revisions(connection)
    script = _scripts()
    unknown = [rev for rev in current if rev not in known_revisions()]
    if unknown:
        from .._version import __version__

        raise StoreError(f"store {url.display} has schema revision {', '.join(unknown)}, newer than this gyrocal "
                         f"{__version__} knows (newest: {script.get_current_head()})",
                         hint="upgrade gyrocal to use it; nothing was changed")
    if set(current) != {script.get_current_head()}:
        command.upgrade(_config(connection), "head")
    return current_revisions(connection)


def upgrade(engine: Engine, url: StoreURL) -> tuple[str, ...]:
    """Create the schema of a fresh store, or bring an older one to the newest revision.

    Parameters
    ----------
    engine : sqlalchemy.engine.Engine
    url : StoreURL
        For messages.

    Returns
    -------
    tuple of str
        The store's revision(s) afterwards.

    Raises
    ------
    gyrocal.errors.StoreError
        The store is of a newer schema, unreachable or not a database.
    """
    return write(engine, url, lambda connection: _migrate(connection, url))
