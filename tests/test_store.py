"""The calibration store (gyrocal.store), each test on a real SQLite file and on a real PostgreSQL server.

References: the records the test itself wrote (counted, ordered and chosen by hand from their times),
the bare database drivers (sqlite3, psycopg) for what the store's API cannot do (update, stamp), and
spawned processes writing at once.
"""

from __future__ import annotations

import sqlite3
from datetime import UTC, datetime, timedelta, timezone

import psycopg
import pytest
from store_checks import T0, at, raw_execute, spawn, store_workers

from gyrocal.errors import InputError, StoreError
from gyrocal.store import Record, Store, open_store, parse_url

SHA_A, SHA_B = "a" * 64, "0123456789abcdef" * 4


def _add(store, serial, kind, hours, verdict=None, **fields):
    return store.add(serial, kind, {"kind": kind, "hours": hours}, created=at(hours), verdict=verdict, **fields)


def test_schema_is_created_on_first_use_and_records_survive_reopening(store_url):
    with open_store(store_url) as store:
        assert store.revision() == "0001" and store.count() == 0
        first = store.add("SN1", "calibration.servo", {"scale": [1.0, 2.0], "note": "é"}, station="bench-2",
                          operator="ana", verdict="pass", input_sha256=[SHA_A, SHA_B], job="batch", args="--x 1",
                          created=datetime(2024, 5, 1, 14, 0, tzinfo=timezone(timedelta(hours=2))))
    with open_store(store_url) as store:
        (record,) = store.history("SN1")
        assert store.count() == 1 and store.get(first) == record and store.get(first + 1000) is None
    assert isinstance(record, Record) and record.id == first
    assert record.created == T0 and record.created.tzinfo == UTC
    assert (record.serial, record.kind, record.station, record.operator, record.verdict) == (
        "SN1", "calibration.servo", "bench-2", "ana", "pass")
    assert record.input_sha256 == [SHA_A, SHA_B] and (record.job, record.args) == ("batch", "--x 1")
    assert record.document == {"scale": [1.0, 2.0], "note": "é"}
    assert set(record.as_dict()) == {"id", "serial", "kind", "created", "station", "operator", "input_sha256",
                                     "verdict", "job", "args", "document"}


def test_the_store_only_appends(store_url):
    with open_store(store_url) as store:
        _add(store, "SN1", "imu", 0, verdict="fail")
        assert not any(hasattr(Store, name) for name in ("update", "delete", "remove", "replace", "put"))
        for sql in ("UPDATE records SET verdict = 'pass'", "DELETE FROM records"):
            with pytest.raises((sqlite3.DatabaseError, psycopg.Error), match="append-only"):
                raw_execute(store_url, sql)
        (record,) = store.history("SN1")
        assert record.verdict == "fail"


def test_history_is_newest_first_and_per_unit(store_url):
    with open_store(store_url) as store:
        ids = [_add(store, "SN1", "imu", h) for h in (2, 0, 1)]
        same_time = _add(store, "SN1", "refusal", 2)
        _add(store, "SN2", "imu", 5)
        history = store.history("SN1")
        assert [r.id for r in history] == [same_time, ids[0], ids[2], ids[1]]
        assert [r.id for r in store.history("SN1", kind="imu")] == [ids[0], ids[2], ids[1]]
        assert store.history("SN3") == []


def test_in_force_without_verdicts_is_the_newest_calibration(store_url):
    with open_store(store_url) as store:
        first = _add(store, "SN1", "calibration.servo", 1)
        second = _add(store, "SN1", "thermal", 3)
        _add(store, "SN1", "refusal", 4)
        _add(store, "SN1", "acceptance", 5)
        _add(store, "SN1", "imuwrong", 6)  # "imu" is a family only before a dot
        _add(store, "SN2", "imu", 2)
        assert store.in_force("SN1", at(0)) is None
        assert store.in_force("SN1", at(1)).id == first  # created at `at` counts
        assert store.in_force("SN1", at(2.9)).id == first
        assert store.in_force("SN1", at(9)).id == second
        assert store.in_force("SN1").id == second  # now
        assert store.in_force("SN9", at(9)) is None


def test_in_force_with_verdicts_is_the_newest_pass(store_url):
    with open_store(store_url) as store:
        unchecked = _add(store, "SN1", "imu", 0)
        passed = _add(store, "SN1", "imu.accel", 1, verdict="pass")
        _add(store, "SN1", "calibration.servo", 2, verdict="fail")
        _add(store, "SN1", "calibration", 3)  # no verdict once limits were used: not in force
        _add(store, "SN1", "acceptance", 4, verdict="pass")
        _add(store, "SN1", "refusal", 5, verdict="fail")
        assert store.in_force("SN1", at(0.5)).id == unchecked  # no verdict yet at 0.5
        for hours in (1, 2, 9):
            assert store.in_force("SN1", at(hours)).id == passed
        _add(store, "SN2", "thermal", 0, verdict="fail")
        assert store.in_force("SN2", at(1)) is None
        _add(store, "SN3", "refusal", 0)
        assert store.in_force("SN3", at(1)) is None


def test_list_filters_by_time_and_verdict(store_url):
    with open_store(store_url) as store:
        a = _add(store, "SN1", "imu", 0, verdict="pass", station="s1")
        b = _add(store, "SN2", "imu", 1, verdict="fail", station="s2")
        c = _add(store, "SN3", "refusal", 2, station="s1")
        d = _add(store, "SN1", "thermal", 3, verdict="pass", station="s2")
        assert [r.id for r in store.list()] == [d, c, b, a]
        assert [r.id for r in store.list(since=at(1))] == [d, c, b]
        assert [r.id for r in store.list(verdict="pass")] == [d, a]
        assert [r.id for r in store.list(since=at(0.5), verdict="fail")] == [b]
        assert [r.id for r in store.list(kind="imu", station="s2")] == [b]
        assert [r.id for r in store.list(limit=2)] == [d, c]
        with pytest.raises(InputError, match="verdict 'ok'"):
            store.list(verdict="ok")
        with pytest.raises(InputError, match="no time zone"):
            store.list(since=datetime(2024, 1, 1))


def test_find_tells_a_rerun_what_was_done(store_url):
    with open_store(store_url) as store:
        one = _add(store, "SN1", "imu", 0, input_sha256=SHA_A, job="j1", args="--fast")
        many = _add(store, "SN2", "imu", 1, input_sha256=[SHA_A, SHA_B], job="j1", args=None)
        assert store.find(SHA_A.upper(), "j1", "--fast").id == one
        assert store.find([SHA_A, SHA_B], "j1", None).id == many
        assert store.find([SHA_B, SHA_A], "j1", None) is None  # order matters
        assert store.find(SHA_A, "j1", "--slow") is None and store.find(SHA_A, "j2", "--fast") is None
        assert store.find(SHA_A, "j1", None) is None and store.find(SHA_B, "j1", "--fast") is None
        again = _add(store, "SN1", "refusal", 2, input_sha256=SHA_A, job="j1", args="--fast")
        assert store.find(SHA_A, "j1", "--fast").id == again
        with pytest.raises(InputError, match="not a SHA-256"):
            store.find("abc", "j1", None)


@pytest.mark.parametrize("serial", ["", "  ", "a/b", "a\\b", "nul\x00", "tab\tx", "c:d", "x*", "q?", 'say"',
                                    "<a>", "p|q", "..", " lead"])
def test_a_serial_a_file_name_cannot_hold_is_refused(tmp_path, serial):
    with open_store(tmp_path / "s.db") as store:
        with pytest.raises(InputError, match="serial") as caught:
            store.add(serial, "imu", {})
        assert "\n" not in str(caught.value)
        with pytest.raises(InputError, match="serial"):
            store.history(serial)
        assert store.count() == 0


def test_malformed_fields_are_refused_before_writing(tmp_path):
    with open_store(tmp_path / "s.db") as store:
        for fields, message in [
            ({"verdict": "PASS"}, "verdict"), ({"created": datetime(2024, 1, 1)}, "no time zone"),
            ({"input_sha256": "xyz"}, "SHA-256"), ({"input_sha256": []}, "empty list"),
            ({"document": {"x": float("nan")}}, "not JSON"), ({"kind": "Calibration Servo"}, "kind"),
            ({"station": 3}, "station must be text"),
        ]:
            values = {"serial": "SN1", "kind": "imu", "document": {}, **fields}
            with pytest.raises(InputError, match=message):
                store.add(**values)
        with pytest.raises(InputError, match="unknown record field"):
            store.add_many([{"serial": "SN1", "kind": "imu", "document": {}, "colour": "red"}])
        assert store.count() == 0
        assert store.add_many([]) == []
        ids = store.add_many([{"serial": f"SN{i}", "kind": "imu", "document": {"i": i}} for i in range(5)])
        assert [store.get(i).serial for i in ids] == [f"SN{i}" for i in range(5)]


def test_a_store_of_a_newer_schema_is_refused(store_url):
    with open_store(store_url) as store:
        _add(store, "SN1", "imu", 0)
    raw_execute(store_url, "UPDATE alembic_version SET version_num = '9999'")
    with pytest.raises(StoreError, match="schema revision 9999, newer than this gyrocal") as caught:
        open_store(store_url)
    assert "\n" not in str(caught.value) and "upgrade gyrocal" in str(caught.value)
    raw_execute(store_url, "UPDATE alembic_version SET version_num = '0001'")
    with open_store(store_url) as store:  # nothing was changed
        assert store.count() == 1


def test_four_processes_writing_at_once_lose_and_duplicate_nothing(store_url):
    open_store(store_url).close()
    results = spawn(store_workers.insert_many, [(store_url, worker, 50) for worker in range(4)])
    ids = [i for _, worker_ids in results for i in worker_ids]
    assert len(ids) == 200 and len(set(ids)) == 200
    with open_store(store_url) as store:
        assert store.count() == 200
        for worker in range(4):
            history = store.history(f"SN-{worker}")
            assert sorted(r.document["i"] for r in history) == list(range(50))
            assert {r.id for r in history} == set(results[worker][1])


def test_two_processes_creating_a_fresh_store_at_once_both_succeed(store_url):
    results = spawn(store_workers.create_and_add, [(store_url, 0), (store_url, 1)])
    assert [(worker, revision) for worker, _, revision in results] == [(0, "0001"), (1, "0001")]
    with open_store(store_url) as store:
        assert store.count() == 2 and {r.serial for r in store.list()} == {"SN-0", "SN-1"}


@pytest.mark.parametrize("text, dialect, tail", [
    ("cal.db", "sqlite", "/cal.db"), ("sqlite:///rel/cal.db", "sqlite", "/rel/cal.db"),
    ("sqlite:////abs/cal.db", "sqlite", "sqlite:////abs/cal.db"),
    ("postgresql://u@h:5433/db", "postgresql", "postgresql+psycopg://u@h:5433/db"),
    ("postgres://u:secret@h/db", "postgresql", "postgresql+psycopg://u:secret@h/db"),
])
def test_store_urls(text, dialect, tail):
    url = parse_url(text)
    assert url.dialect == dialect and url.sqlalchemy_url.endswith(tail)
    assert "secret" not in url.display
    if dialect == "sqlite":
        assert url.path.is_absolute() and url.sqlalchemy_url == f"sqlite:///{url.path}"


@pytest.mark.parametrize("text, message", [
    ("", "no store given"), ("sqlite://", "names no file"), (":memory:", "names no file"),
    ("mysql://u@h/db", "scheme 'mysql' is not supported"), ("postgresql://u@h:x/db", "port"),
    ("postgresql://u@h:5432/", "names no database"),
])
def test_malformed_store_urls_are_refused(text, message):
    with pytest.raises(InputError, match=message):
        parse_url(text)


def test_a_file_that_is_not_a_store_gives_one_line(tmp_path):
    (tmp_path / "notes.db").write_text("not a database " * 100)
    with pytest.raises(StoreError, match="not a database") as caught:
        open_store(tmp_path / "notes.db")
    assert "\n" not in str(caught.value)
    with pytest.raises(InputError, match="does not exist"):
        open_store(tmp_path / "missing" / "s.db")
