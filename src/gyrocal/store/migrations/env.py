"""Alembic's environment for the calibration store, run by :func:`gyrocal.store.migrate.upgrade`.

The caller hands over an open connection, already inside the transaction that holds the store's
creation lock (``config.attributes["connection"]``); migrations run inside that transaction.
"""

from __future__ import annotations

from alembic import context

from gyrocal.store.schema import metadata


def _run() -> None:
    connection = context.config.attributes.get("connection")
    if connection is None:
        raise RuntimeError("gyrocal's store migrations run through gyrocal.store.migrate, which passes a connection")
    context.configure(connection=connection, target_metadata=metadata, render_as_batch=True,
                      transactional_ddl=True)
    with context.begin_transaction():
        context.run_migrations()


_run()
