"""Which unit a result belongs to: serial, part, station, operator, procedure, inputs, software, time.

The ``unit`` section of a result file::

    "unit": {"serial": "SN0042", "part": "IMU-7", "revision": "B", "station": "bench-3", "operator": "ak",
             "fixture": "servo-2", "procedure": {"name": "servo6", "version": "1.2"}, "device_id": 2490378,
             "software": "gyrocal 0.3.0", "inputs": [{"file": "run.csv", "sha256": "..."}],
             "created": "2026-12-02T13:45:07Z"}
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

from .._version import __version__
from ..errors import InputError

__all__ = ["Identity", "check_serial", "sha256_of", "unit_section", "utc_now"]

def check_serial(serial: str, flag: str = "--unit") -> str:
    """`serial` without surrounding blanks, checked by the store's rule (a file name must hold it)."""
    from ..store.records import check_serial as store_rule

    try:
        return store_rule(str(serial).strip())
    except InputError as exc:
        raise InputError(f"{flag}: {exc}") from None


def _procedure(text: str | None) -> dict | None:
    if text is None:
        return None
    name, sep, version = str(text).partition("@")
    if not name.strip() or (sep and not version.strip()):
        raise InputError(f"--procedure takes NAME@VERSION (for example servo6@1.2), got {text!r}")
    return {"name": name.strip(), "version": version.strip() or None}


@dataclass(frozen=True)
class Identity:
    """Who and what a result is about; everything but the serial is optional."""

    serial: str
    part: str | None = None
    revision: str | None = None
    station: str | None = None
    operator: str | None = None
    fixture: str | None = None
    procedure: str | None = None

    def __post_init__(self):
        object.__setattr__(self, "serial", check_serial(self.serial))
        _procedure(self.procedure)


def sha256_of(path: str | Path) -> str:
    """SHA-256 of a file's bytes, read in chunks (a long log does not have to fit in memory)."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def utc_now() -> datetime:
    return datetime.now(timezone.utc).replace(microsecond=0)


def iso_utc(when: datetime) -> str:
    return when.astimezone(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def unit_section(identity: Identity, inputs, *, device_id: int | None = None, created: datetime | None = None) -> dict:
    """The ``unit`` section of a result file: the identity, the inputs' hashes, the software and the time."""
    files = [Path(p) for p in inputs if p is not None]
    return {"serial": identity.serial, "part": identity.part, "revision": identity.revision,
            "station": identity.station, "operator": identity.operator, "fixture": identity.fixture,
            "procedure": _procedure(identity.procedure), "device_id": device_id, "software": f"gyrocal {__version__}",
            "inputs": [{"file": p.name, "sha256": sha256_of(p)} for p in files],
            "created": iso_utc(created or utc_now())}
