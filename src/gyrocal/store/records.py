"""A stored record and the checks on its fields, without importing SQLAlchemy.

A record is one result about one unit: a calibration, a refusal, an acceptance check. Its fields are
checked here before anything reaches the database, so a bad serial or a naive timestamp is refused
with one line whichever database holds the store.
"""

from __future__ import annotations

import json
import re
from dataclasses import asdict, dataclass
from datetime import UTC, datetime
from typing import Any

from ..errors import InputError

__all__ = ["Record", "CALIBRATION_FAMILIES", "VERDICTS", "is_calibration_kind", "check_serial", "check_aware",
           "check_verdict", "check_kind", "check_sha256", "sha256_key", "check_document", "check_text"]

#: A kind whose first dotted part is one of these is a calibration (``calibration.servo``, ``imu``,
#: ``thermal``, ``thermal.bias``); ``refusal``, ``acceptance`` and every other kind are not.
CALIBRATION_FAMILIES: frozenset[str] = frozenset({"calibration", "imu", "thermal"})
#: The verdicts a record may carry; None means no limits were checked.
VERDICTS: tuple[str, ...] = ("pass", "fail")

_BAD_SERIAL = re.compile(r'[/\\:*?"<>|\x00-\x1f\x7f]')
_KIND = re.compile(r"^[a-z][a-z0-9_\-]*(\.[a-z0-9_\-]+)*$")
_SHA256 = re.compile(r"^[0-9a-f]{64}$")
MAX_SERIAL = 200


@dataclass(frozen=True)
class Record:
    """One stored record, as read back.

    Attributes
    ----------
    id : int
        Assigned by the store, increasing in insertion order.
    serial : str
        The unit's serial number.
    kind : str
        ``"calibration.servo"``, ``"imu"``, ``"thermal"``, ``"refusal"``, ``"acceptance"``, ...
    created : datetime.datetime
        When the record was made, timezone-aware UTC.
    station, operator : str or None
        Who and where.
    input_sha256 : str or list of str or None
        SHA-256 of the input file(s), as given to :meth:`Store.add`.
    verdict : {"pass", "fail"} or None
        None when no limits were checked.
    job, args : str or None
        The batch job and its arguments, so a rerun can skip work already done.
    document : object
        The whole result document (JSON).
    """

    id: int
    serial: str
    kind: str
    created: datetime
    station: str | None
    operator: str | None
    input_sha256: str | list[str] | None
    verdict: str | None
    job: str | None
    args: str | None
    document: Any

    def as_dict(self) -> dict[str, Any]:
        """The record as a plain dict (``created`` stays a datetime)."""
        return asdict(self)


def is_calibration_kind(kind: str) -> bool:
    """Whether records of `kind` are calibrations (see :data:`CALIBRATION_FAMILIES`)."""
    return kind.split(".", 1)[0] in CALIBRATION_FAMILIES


def check_serial(serial: Any) -> str:
    """`serial` unchanged when a file name could hold it; InputError otherwise."""
    if not isinstance(serial, str) or not serial.strip():
        raise InputError(f"serial {serial!r} is empty; give the unit's serial number")
    bad = sorted(set(_BAD_SERIAL.findall(serial)))
    if bad:
        shown = " ".join(repr(c) for c in bad)
        raise InputError(f"serial {serial!r} holds {shown}, which a file name cannot hold; "
                         'use letters, digits, "-", "_" or "."')
    if serial != serial.strip() or serial in (".", ".."):
        raise InputError(f"serial {serial!r} is not usable as a file name (leading or trailing blanks, '.' or '..')")
    if len(serial) > MAX_SERIAL:
        raise InputError(f"serial of {len(serial)} characters is longer than {MAX_SERIAL}")
    return serial


def check_aware(value: Any, name: str) -> datetime:
    """`value` converted to UTC; InputError when it is not a timezone-aware datetime."""
    if not isinstance(value, datetime):
        raise InputError(f"{name} must be a datetime, got {type(value).__name__}")
    if value.tzinfo is None or value.utcoffset() is None:
        raise InputError(f"{name} {value.isoformat()} has no time zone; give an aware datetime "
                         "(datetime.now(timezone.utc))")
    return value.astimezone(UTC)


def check_verdict(verdict: Any) -> str | None:
    if verdict is not None and verdict not in VERDICTS:
        raise InputError(f"verdict {verdict!r} is not 'pass', 'fail' or None")
    return verdict


def check_kind(kind: Any) -> str:
    if not isinstance(kind, str) or not _KIND.match(kind):
        raise InputError(f"record kind {kind!r} is not a lower-case dotted name such as 'calibration.servo'")
    return kind


def check_sha256(value: Any) -> str | list[str] | None:
    """`value` with its hashes lower-cased: None, one hex SHA-256 or a non-empty list of them."""
    if value is None:
        return None
    many = not isinstance(value, str)
    items = list(value) if many else [value]
    if many and not items:
        raise InputError("input_sha256 is an empty list; give None when the record has no input file")
    out = []
    for item in items:
        if not isinstance(item, str) or not _SHA256.match(item.lower()):
            raise InputError(f"input_sha256 {item!r} is not a SHA-256 digest (64 hexadecimal digits)")
        out.append(item.lower())
    return out if many else out[0]


def sha256_key(value: str | list[str] | None) -> str | None:
    """The searchable text of checked hashes: the digest, or the digests joined with ``,`` in order."""
    if value is None:
        return None
    return value if isinstance(value, str) else ",".join(value)


def check_document(document: Any) -> Any:
    """`document` when it is JSON (no NaN or infinity, string keys); InputError otherwise."""
    try:
        json.dumps(document, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise InputError(f"record document is not JSON: {exc}") from None
    return document


def check_text(value: Any, name: str) -> str | None:
    if value is not None and not isinstance(value, str):
        raise InputError(f"{name} must be text or None, got {type(value).__name__}")
    if value is not None and "\x00" in value:
        raise InputError(f"{name} holds a NUL character")
    return value
