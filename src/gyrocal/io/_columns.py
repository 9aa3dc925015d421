"""Which file column holds which quantity: canonical names, aliases and user mappings."""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

from ..errors import InputError

#: Accelerometer columns: read only when asked for (an accelerometer unit is given) or mapped by name.
ACCEL = ("ax", "ay", "az")
#: Canonical column names, in the order a recording uses them.
CANONICAL = ("t", "gx", "gy", "gz", "temp", "table_rate", "axis", *ACCEL)
REQUIRED = ("gx", "gy", "gz")
#: Columns parsed as numbers; ``axis`` is text.
NUMERIC = ("t", "gx", "gy", "gz", "temp", "table_rate", *ACCEL)

_RATE_STEMS = ("g", "gyr", "gyro", "gyroscope", "w", "omega", "rate", "angularvelocity", "angvel", "av")
_ALIASES: dict[str, set[str]] = {
    "t": {"t", "time", "times", "timestamp", "timestamps", "ts", "tsec", "timesec", "seconds", "sec", "elapsed", "elapsedtime"}
    | {f"{stem}{u}" for stem in ("t", "time", "timestamp", "stamp") for u in ("ms", "us", "ns", "µs")},
    "temp": {"temp", "temperature", "tempc", "temperaturec", "tdegc", "tempdegc", "gyrtemp", "gyrotemp", "imutemp", "dietemp"},
    "table_rate": {"tablerate", "tablespeed", "turntablerate", "tablew", "tableomega"},
    "axis": {"axis", "tableaxis"},
}
_RATE_SUFFIXES = ("", "dps", "degs", "degps", "rads", "radps", "raw", "lsb")
for _a in "xyz":
    _ALIASES[f"g{_a}"] = {f"{stem}{_a}{unit}" for stem in _RATE_STEMS for unit in _RATE_SUFFIXES} | {
        f"{_a}{stem}" for stem in ("gyr", "gyro", "rate")
    }

_ACCEL_STEMS = ("a", "acc", "accel", "accl", "acceleration", "accelerometer", "linacc", "linearacceleration", "la")
_ACCEL_SUFFIXES = ("", "g", "ms2", "mss", "mps2", "raw", "lsb")
for _a in "xyz":
    _ALIASES[f"a{_a}"] = {f"{stem}{_a}{unit}" for stem in _ACCEL_STEMS for unit in _ACCEL_SUFFIXES} | {
        f"{_a}{stem}" for stem in ("acc", "accel")
    }

_BRACKETS = re.compile(r"[\(\[\{].*?[\)\]\}]")
_SEPARATORS = re.compile(r"[\s_\-\.:/]+")


def normalise(name: str) -> str:
    """Lower case, units in brackets and separators removed: ``'Gyro_X [deg/s]'`` -> ``'gyrox'``."""
    return _SEPARATORS.sub("", _BRACKETS.sub("", str(name)).strip().lower())


def parse_columns(spec: str | Mapping[str, str] | None) -> dict[str, str]:
    """Turn ``'gx=gyroX,gy=gyroY'`` (the CLI syntax) or a mapping into ``{canonical: file name}``."""
    if spec is None:
        return {}
    if isinstance(spec, str):
        pairs: dict[str, str] = {}
        for item in filter(None, (s.strip() for s in spec.split(","))):
            key, sep, value = item.partition("=")
            if not sep or not key.strip() or not value.strip():
                raise InputError(f"{{param}} entry {item!r} is not NAME=COLUMN", param="columns", value=item,
                                 hint="write for example 'gx=gyroX,gy=gyroY,gz=gyroZ' (or column numbers, gx=2)")
            pairs[key.strip()] = value.strip()
        spec = pairs
    out = {}
    for key, value in dict(spec).items():
        canon = key.strip().lower()
        if canon not in CANONICAL:
            raise InputError(f"{{param}} key {key!r} is not a known quantity", param="columns", value=key,
                             hint=f"use one of {', '.join(CANONICAL)}")
        out[canon] = str(value)
    return out


def _found(names: Sequence[str]) -> str:
    shown = ", ".join(repr(n) for n in names[:40])
    return shown + (f", ... ({len(names)} in all)" if len(names) > 40 else "")


def _by_number(wanted: str, names: Sequence[str]) -> str | None:
    """The column at position `wanted` counting from 1, when `wanted` is such a number."""
    text = wanted.strip()
    if text.isdigit() and 1 <= int(text) <= len(names):
        return names[int(text) - 1]
    return None


def resolve(names: Sequence[str], columns: Mapping[str, str] | None, source: str, *, where: str = "",
            header: bool = True, accel: bool = False) -> dict[str, str]:
    """Map canonical names to the file's column names.

    Explicit `columns` win, by name (exact, then in any case) or by position counting from 1
    (``gx=2``; a column named ``2`` wins over the second column); then an exact canonical name
    (any case); then an alias, only when a single file column matches it. A table without a
    `header` (names ``"1" .. "n"``) is mapped by `columns` alone. The accelerometer columns
    ``ax, ay, az`` are looked for only with `accel` (otherwise they stay other columns, unless mapped).

    Raises
    ------
    InputError
        A mapped column is absent, an alias is ambiguous, ``gx, gy, gz`` cannot be found, or
        a column used is named twice in the header.
    """
    names = [str(n) for n in names]
    by_lower = {}
    for n in names:
        by_lower.setdefault(n.strip().lower(), n)
    found = f"columns found{' (' + where + ')' if where else ''}: {_found(names)}"
    mapping: dict[str, str] = {}
    for canon, wanted in parse_columns(columns).items():
        hit = wanted if wanted in names else by_lower.get(wanted.strip().lower()) or _by_number(wanted, names)
        if hit is None:
            raise InputError(f"{source}: column {wanted!r} (given for {canon}) is not in the file; {found}",
                             param="columns", value=wanted, hint=f"in {{param}}, give a name or a number from 1 to {len(names)}")
        if hit in mapping.values():
            other = next(c for c, n in mapping.items() if n == hit)
            raise InputError(f"{source}: column {hit!r} is given for both {other} and {canon}", param="columns",
                             hint="each quantity needs its own column")
        mapping[canon] = hit
    taken = set(mapping.values())
    for canon in CANONICAL if header else ():
        if canon in mapping or (canon in ACCEL and not accel):
            continue
        if canon in by_lower and by_lower[canon] not in taken:
            mapping[canon] = by_lower[canon]
            taken.add(mapping[canon])
            continue
        hits = [n for n in names if n not in taken and normalise(n) in _ALIASES[canon]]
        if len(hits) == 1:
            mapping[canon] = hits[0]
            taken.add(hits[0])
        elif len(hits) > 1 and (canon in REQUIRED or canon == "t" or canon in ACCEL):
            raise InputError(f"{source}: several columns could be {canon} ({_found(hits)})", param="columns",
                             hint=f"say which with {{param}} {canon}={hits[0]}")
    missing = [c for c in REQUIRED if c not in mapping]
    accel_missing = [c for c in ACCEL if c not in mapping]
    if (accel or len(accel_missing) < 3) and accel_missing and not missing:
        raise InputError(
            f"{source}: no accelerometer column for {', '.join(accel_missing)}; {found}",
            param="columns", hint="map them with {param} ax=NAME,ay=NAME,az=NAME")
    if missing:
        how = ("give them by number, e.g. {param} gx=2,gy=3,gz=4" if not header else
               "map them with {param} gx=NAME,gy=NAME,gz=NAME (or by number, gx=2), or, if the header is further "
               "down, skip the lines above it with {param:skip_rows} N")
        raise InputError(f"{source}: no column for {', '.join(missing)}; {found}", param="columns", hint=how)
    for canon, name in mapping.items():
        if names.count(name) > 1:  # readers would silently keep one of the copies
            raise InputError(
                f"{source}: column name {name!r} (used for {canon}) appears {names.count(name)} times in the header; "
                "rename the copies so that every name is unique"
            )
    return mapping


_TIME_UNITS = {"ms": 1e-3, "msec": 1e-3, "us": 1e-6, "usec": 1e-6, "µs": 1e-6, "ns": 1e-9, "nsec": 1e-9}
_TIME_UNIT_TOKEN = re.compile(r"(?:^|[\s_\-\[\(\{])(ms|msec|us|usec|µs|ns|nsec)(?:$|[\s_\-\]\)\}])", re.IGNORECASE)


def time_scale(name: str) -> float:
    """Seconds per unit of a time column, read from its name (``time_ms``, ``t [us]``, ``stamp_ns``); 1 otherwise."""
    hit = _TIME_UNIT_TOKEN.search(str(name))
    return _TIME_UNITS[hit.group(1).lower()] if hit else 1.0
