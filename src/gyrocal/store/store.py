"""The calibration store: append-only records of results per unit, on SQLite or PostgreSQL.

There is no update and no delete: a correction is a newer record. The database refuses ``UPDATE`` and
``DELETE`` on the table too (triggers created by the first migration).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from sqlalchemy import ColumnElement, and_, exists, func, insert, or_, select
from sqlalchemy.engine import Connection, Engine

from ..errors import InputError, StoreError
from .engine import make_engine, read, write
from .migrate import current_revisions, upgrade
from .records import (
    CALIBRATION_FAMILIES,
    Record,
    check_aware,
    check_document,
    check_kind,
    check_serial,
    check_sha256,
    check_text,
    check_verdict,
    sha256_key,
)
from .schema import records
from .urls import StoreURL, parse_url

__all__ = ["Store"]

_FIELDS = ("serial", "kind", "document", "created", "station", "operator", "verdict", "input_sha256", "job", "args")
_NEWEST = (records.c.created.desc(), records.c.id.desc())


def _row(serial, kind, document, created=None, station=None, operator=None, verdict=None, input_sha256=None,
         job=None, args=None) -> dict[str, Any]:
    hashes = check_sha256(input_sha256)
    return {
        "serial": check_serial(serial), "kind": check_kind(kind), "document": check_document(document),
        "created": datetime.now(UTC) if created is None else check_aware(created, "created"),
        "station": check_text(station, "station"), "operator": check_text(operator, "operator"),
        "verdict": check_verdict(verdict), "input_sha256": hashes, "input_sha256_key": sha256_key(hashes),
        "job": check_text(job, "job"), "args": check_text(args, "args"),
    }


def _record(row) -> Record:
    values = dict(row._mapping)
    values.pop("input_sha256_key", None)
    return Record(**values)


def _calibration() -> ColumnElement[bool]:
    kind = records.c.kind
    return or_(kind.in_(sorted(CALIBRATION_FAMILIES)), *(kind.like(f"{family}.%") for family in
                                                          sorted(CALIBRATION_FAMILIES)))


class Store:
    """An open calibration store; make one with :meth:`Store.open` (or :func:`gyrocal.store.open_store`).

    Every method runs in its own transaction. A store is used from one process; several processes
    may each open the same store and write at once.
    """

    def __init__(self, url: StoreURL, engine: Engine):
        self.url = url
        self._engine = engine

    @classmethod
    def open(cls, url: str | Path | StoreURL) -> Store:
        """Open the store at `url`, creating its schema on first use or upgrading an older one.

        Parameters
        ----------
        url : str, pathlib.Path or StoreURL
            A file name or ``sqlite:///path`` (SQLite), or ``postgresql://user@host:port/db``.

        Returns
        -------
        Store

        Raises
        ------
        gyrocal.errors.InputError
            `url` is malformed, or its SQLite file's folder does not exist.
        gyrocal.errors.StoreError
            The store is unreachable, not a database, or of a newer schema than this gyrocal knows.
        """
        parsed = url if isinstance(url, StoreURL) else parse_url(url)
        if parsed.path is not None and not parsed.path.parent.is_dir():
            raise InputError(f"store {parsed.display}: folder {parsed.path.parent} does not exist")
        engine = make_engine(parsed)
        try:
            upgrade(engine, parsed)
        except BaseException:
            engine.dispose()
            raise
        return cls(parsed, engine)

    def close(self) -> None:
        """Release the store's connections."""
        self._engine.dispose()

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"Store({self.url.display!r})"

    def add(self, serial: str, kind: str, document: Any, *, created: datetime | None = None,
            station: str | None = None, operator: str | None = None, verdict: str | None = None,
            input_sha256: str | list[str] | None = None, job: str | None = None, args: str | None = None) -> int:
        """Append one record.

        Parameters
        ----------
        serial : str
            The unit's serial number: non-empty, and nothing a file name cannot hold
            (``/ \\ : * ? " < > |``, NUL or control characters).
        kind : str
            Lower-case dotted name: ``"calibration.servo"``, ``"imu"``, ``"thermal"``, ``"refusal"``, ...
        document : object
            The whole result as JSON (no NaN or infinity).
        created : datetime.datetime, optional
            Timezone-aware; now (UTC) by default.
        station, operator : str, optional
        verdict : {"pass", "fail"}, optional
            None when no limits were checked.
        input_sha256 : str or list of str, optional
            SHA-256 hex digest(s) of the input file(s), in order.
        job, args : str, optional
            The batch job and its arguments (see :meth:`find`).

        Returns
        -------
        int
            The new record's id.

        Raises
        ------
        gyrocal.errors.InputError
            A field is malformed; nothing is written.
        gyrocal.errors.StoreError
            The store could not be written.
        """
        return self.add_many([dict(serial=serial, kind=kind, document=document, created=created, station=station,
                                   operator=operator, verdict=verdict, input_sha256=input_sha256, job=job,
                                   args=args)])[0]

    def add_many(self, items: Iterable[Mapping[str, Any]]) -> list[int]:
        """Append several records in one transaction: all or none.

        Parameters
        ----------
        items : iterable of mapping
            Each with the keyword arguments of :meth:`add` (``serial``, ``kind``, ``document`` required).

        Returns
        -------
        list of int
            The new ids, in the order of `items`.
        """
        rows = []
        for item in items:
            unknown = set(item) - set(_FIELDS)
            if unknown:
                raise InputError(f"unknown record field(s) {', '.join(sorted(unknown))}; known: {', '.join(_FIELDS)}")
            rows.append(_row(**item))
        if not rows:
            return []
        statement = insert(records).returning(records.c.id, sort_by_parameter_order=True)
        return write(self._engine, self.url, lambda c: [r.id for r in c.execute(statement, rows)])

    def _select(self, statement) -> list[Record]:
        return read(self._engine, self.url, lambda c: [_record(row) for row in c.execute(statement)])

    def get(self, record_id: int) -> Record | None:
        """The record with id `record_id`, or None."""
        rows = self._select(select(records).where(records.c.id == int(record_id)))
        return rows[0] if rows else None

    def history(self, serial: str, *, kind: str | None = None) -> list[Record]:
        """Every record of unit `serial` (of `kind` only, when given), newest first.

        "Newest" is by ``created``, then by id for records created at the same instant.
        """
        statement = select(records).where(records.c.serial == check_serial(serial))
        if kind is not None:
            statement = statement.where(records.c.kind == check_kind(kind))
        return self._select(statement.order_by(*_NEWEST))

    def in_force(self, serial: str, at: datetime | None = None) -> Record | None:
        """The calibration of unit `serial` in force at `at` (default: now), or None.

        Only calibration records count (kind ``calibration``, ``imu`` or ``thermal``, or one of those
        followed by ``.`` and more, see :data:`gyrocal.store.CALIBRATION_FAMILIES`); refusals,
        acceptance checks and other kinds are never in force. Among the unit's calibration records
        created at or before `at`:

        * when any has a verdict (limits were checked), the newest with verdict ``"pass"``, or None
          when none passed; a record without a verdict is then not in force;
        * when none has a verdict (no limits were used), the newest of them.

        Records created after `at` never count, so the answer for a past instant does not change when
        records are added later.
        """
        at = datetime.now(UTC) if at is None else check_aware(at, "at")
        scope = and_(records.c.serial == check_serial(serial), records.c.created <= at, _calibration())

        def work(connection: Connection) -> Record | None:
            newest = select(records).order_by(*_NEWEST).limit(1)
            passed = connection.execute(newest.where(scope, records.c.verdict == "pass")).first()
            if passed is not None:
                return _record(passed)
            judged = select(exists().where(scope, records.c.verdict.is_not(None)))
            if connection.execute(judged).scalar():
                return None
            row = connection.execute(newest.where(scope)).first()
            return None if row is None else _record(row)

        return read(self._engine, self.url, work)

    def list(self, since: datetime | None = None, verdict: str | None = None, *, kind: str | None = None,
             station: str | None = None, limit: int | None = None) -> list[Record]:
        """Records of every unit, newest first, filtered.

        Parameters
        ----------
        since : datetime.datetime, optional
            Only records created at or after this instant (timezone-aware).
        verdict : {"pass", "fail"}, optional
            Only records with this verdict.
        kind, station : str, optional
            Only records of this kind / from this station.
        limit : int, optional
            At most this many (the newest).
        """
        statement = select(records)
        if since is not None:
            statement = statement.where(records.c.created >= check_aware(since, "since"))
        if verdict is not None:
            statement = statement.where(records.c.verdict == check_verdict(verdict))
        if kind is not None:
            statement = statement.where(records.c.kind == check_kind(kind))
        if station is not None:
            statement = statement.where(records.c.station == station)
        statement = statement.order_by(*_NEWEST)
        if limit is not None:
            if int(limit) < 1:
                raise InputError(f"limit {limit!r} must be at least 1")
            statement = statement.limit(int(limit))
        return self._select(statement)

    def find(self, input_sha256: str | list[str], job: str | None, args: str | None) -> Record | None:
        """The newest record made from the same input(s) by the same job with the same arguments, or None.

        A batch rerun skips an input when this returns a record. `job` and `args` match exactly (None
        matches only None); `input_sha256` matches the same digest, or the same digests in the same order.
        """
        key = sha256_key(check_sha256(input_sha256))
        if key is None:
            raise InputError("find needs the input's SHA-256 digest(s)")
        statement = select(records).where(records.c.input_sha256_key == key,
                                          records.c.job.is_not_distinct_from(check_text(job, "job")),
                                          records.c.args.is_not_distinct_from(check_text(args, "args")))
        rows = self._select(statement.order_by(*_NEWEST).limit(1))
        return rows[0] if rows else None

    def count(self) -> int:
        """How many records the store holds."""
        return read(self._engine, self.url, lambda c: int(c.execute(select(func.count()).select_from(records))
                                                          .scalar_one()))

    def revision(self) -> str:
        """The store's schema revision."""
        heads = read(self._engine, self.url, current_revisions)
        if len(heads) != 1:
            raise StoreError(f"store {self.url.display} has {len(heads)} schema heads")
        return heads[0]
