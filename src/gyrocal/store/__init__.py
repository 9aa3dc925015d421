"""The calibration store: every result about every unit, append-only, on SQLite or PostgreSQL.

Needs the ``store`` extra (``pip install 'gyrocal[store]'``: SQLAlchemy, Alembic, psycopg 3); this
package imports them only when a store is opened, so ``import gyrocal.store`` works without them.

>>> from gyrocal.store import open_store                                  # doctest: +SKIP
>>> with open_store("calibrations.db") as store:                          # doctest: +SKIP
...     record_id = store.add("SN123", "calibration.servo", document, verdict="pass")
...     current = store.in_force("SN123")

Modules: :mod:`.urls` (store locations), :mod:`.records` (the record and its field checks),
:mod:`.schema` (tables, SQLAlchemy Core), :mod:`.migrate` (Alembic, bundled migrations),
:mod:`.engine` (connections, SQLite locking, retries, one-line errors), :mod:`.store` (the API).

Layer 8 (firmware, exports, simulation, figures and the store) of docs/architecture.md: imports nothing of
gyrocal but the package root.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import MissingDependencyError
from .records import CALIBRATION_FAMILIES, VERDICTS, Record, check_serial, is_calibration_kind
from .urls import StoreURL, parse_url

if TYPE_CHECKING:
    from .store import Store

__all__ = ["open_store", "Store", "Record", "StoreURL", "parse_url", "check_serial", "is_calibration_kind",
           "CALIBRATION_FAMILIES", "VERDICTS"]

_HINT = "the calibration store needs SQLAlchemy, Alembic and psycopg: pip install 'gyrocal[store]'"


def _store_class():
    try:
        from .store import Store
    except ImportError as exc:
        raise MissingDependencyError(f"{_HINT} ({exc})") from None
    return Store


def open_store(url: str | Path | StoreURL) -> Store:
    """Open (creating or upgrading its schema) the store at `url`; see :meth:`Store.open`.

    Raises
    ------
    gyrocal.errors.MissingDependencyError
        The ``store`` extra (or psycopg, for a PostgreSQL URL) is not installed.
    """
    parsed = url if isinstance(url, StoreURL) else parse_url(url)
    store_class = _store_class()
    if parsed.dialect == "postgresql":
        try:
            import psycopg  # noqa: F401
        except ImportError:
            raise MissingDependencyError(_HINT + " (psycopg is missing)") from None
    return store_class.open(parsed)


def __getattr__(name: str):
    if name == "Store":
        return _store_class()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
