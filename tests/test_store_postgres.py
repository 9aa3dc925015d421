"""What only PostgreSQL stores do: an unreachable server, the column types, the server's time zone.

References: a port nothing listens on (tests/pg_server.free_port), PostgreSQL's own catalogue
(information_schema) read with psycopg, and the session's server running in Europe/Berlin.
"""

from __future__ import annotations

from datetime import UTC, datetime

import psycopg
import pytest
from pg_server import free_port

from gyrocal.errors import StoreError
from gyrocal.store import open_store


def test_an_unreachable_server_is_one_clear_line():
    url = f"postgresql://gyrocal:hunter2@127.0.0.1:{free_port()}/nothing"
    with pytest.raises(StoreError) as caught:
        open_store(url)
    message = str(caught.value)
    assert message.startswith(f"cannot reach store postgresql://gyrocal:***@127.0.0.1:{url.split(':')[3]}")
    assert "refused" in message.lower() and "\n" not in message and "hunter2" not in message
    assert caught.value.__cause__ is None and caught.value.__suppress_context__


def test_a_missing_database_is_one_clear_line(pg_server):
    with pytest.raises(StoreError, match='database "no_such_db" does not exist') as caught:
        open_store(pg_server.url("no_such_db"))
    assert "\n" not in str(caught.value)


def test_columns_are_timestamptz_and_jsonb_and_times_come_back_in_utc(pg_url):
    with open_store(pg_url) as store:
        store.add("SN1", "imu", {"b": 1, "a": [1.5]}, created=datetime(2024, 1, 1, 23, 30, tzinfo=UTC))
        (record,) = store.history("SN1")
    assert record.created == datetime(2024, 1, 1, 23, 30, tzinfo=UTC) and record.created.utcoffset().total_seconds() == 0
    assert record.document == {"a": [1.5], "b": 1}
    with psycopg.connect(pg_url) as connection:
        types = dict(connection.execute("SELECT column_name, data_type FROM information_schema.columns "
                                        "WHERE table_name = 'records'").fetchall())
        zone = connection.execute("SHOW timezone").fetchone()[0]
        local = connection.execute("SELECT created::text FROM records").fetchone()[0]
    assert types["created"] == "timestamp with time zone" and types["document"] == "jsonb"
    assert zone == "Europe/Berlin" and local.startswith("2024-01-02 00:30:00+01")
