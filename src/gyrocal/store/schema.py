"""The store's tables, in SQLAlchemy Core: what the code reads and writes.

The migrations in ``gyrocal/store/migrations/versions`` create these tables; a change here needs a new
revision there (and :data:`HEAD` moved to it).
"""

from __future__ import annotations

from datetime import UTC, datetime

from sqlalchemy import JSON, CheckConstraint, Column, DateTime, Index, Integer, MetaData, String, Table, Text
from sqlalchemy.dialects.postgresql import JSONB
from sqlalchemy.types import TypeDecorator

__all__ = ["metadata", "records", "UTCDateTime", "DOCUMENT", "HEAD"]

#: The newest schema revision this gyrocal knows (the last migration's ``revision``).
HEAD = "0001"


class UTCDateTime(TypeDecorator):
    """An aware UTC datetime: ``timestamptz`` on PostgreSQL, fixed-width ISO-8601 UTC text on SQLite.

    The text form (``2024-05-01T12:00:00.000000+00:00``) sorts as the instants do, so ``ORDER BY`` and
    ``<=`` work on it. Values come back as aware UTC datetimes on both databases.
    """

    impl = DateTime(timezone=True)
    cache_ok = True

    def load_dialect_impl(self, dialect):
        if dialect.name == "sqlite":
            return dialect.type_descriptor(String(32))
        return dialect.type_descriptor(DateTime(timezone=True))

    def process_bind_param(self, value, dialect):
        if value is None:
            return None
        if value.tzinfo is None:
            raise ValueError("naive datetime reached the store")  # records.check_aware refuses it first
        value = value.astimezone(UTC)
        if dialect.name == "sqlite":
            return value.isoformat(timespec="microseconds")
        return value

    def process_result_value(self, value, dialect):
        if value is None:
            return None
        if isinstance(value, str):
            value = datetime.fromisoformat(value)
        if value.tzinfo is None:  # written by hand without an offset: the store's times are UTC
            value = value.replace(tzinfo=UTC)
        return value.astimezone(UTC)


#: A whole JSON document: JSONB on PostgreSQL, JSON (text) elsewhere.
DOCUMENT = JSON().with_variant(JSONB(), "postgresql")

metadata = MetaData()

records = Table(
    "records",
    metadata,
    Column("id", Integer, primary_key=True, autoincrement=True),
    Column("serial", Text, nullable=False),
    Column("kind", Text, nullable=False),
    Column("created", UTCDateTime(), nullable=False),
    Column("station", Text, nullable=True),
    Column("operator", Text, nullable=True),
    Column("verdict", String(4), nullable=True),
    Column("input_sha256", JSON, nullable=True),
    Column("input_sha256_key", Text, nullable=True),
    Column("job", Text, nullable=True),
    Column("args", Text, nullable=True),
    Column("document", DOCUMENT, nullable=False),
    CheckConstraint("verdict IN ('pass', 'fail')", name="ck_records_verdict"),
    Index("ix_records_serial_created", "serial", "created"),
    Index("ix_records_created", "created"),
    Index("ix_records_station", "station"),
    Index("ix_records_verdict", "verdict"),
    Index("ix_records_input_sha256_key", "input_sha256_key"),
)
