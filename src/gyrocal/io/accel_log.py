"""An accelerometer kept in a log of its own, joined to the gyro's recording.

imu_tk, the tool of the multi-position method of Tedaldi et al., keeps each sensor in its own
file (``time x y z``, whitespace, no header); many loggers do the same. The accelerometer's
file is read with the same reader, its columns mapped by ``ax, ay, az`` (and ``t``), and its
samples are put on the gyro's time stamps: taken as they are when both logs share their stamps,
linearly interpolated otherwise, over the time both logs cover.
"""

from __future__ import annotations

import dataclasses
import os

import numpy as np

from ..constants import STANDARD_GRAVITY
from ..errors import InputError
from ..recording import Recording
from ._columns import parse_columns
from .reader import read_recording

__all__ = ["attach_accelerometer"]

_TO_GYRO_NAMES = {"ax": "gx", "ay": "gy", "az": "gz"}


def _gyro_style_columns(columns) -> dict[str, str]:
    """``ax=2,ay=3,az=4[,t=1]`` as the reader's ``gx gy gz`` names (the reader reads three columns and a time)."""
    if columns is None:
        return {"gx": "ax", "gy": "ay", "gz": "az"}
    spec = dict(item.split("=", 1) for item in columns.split(",") if "=" in item) if isinstance(columns, str) \
        else dict(columns)
    bad = set(k.strip().lower() for k in spec) - {"ax", "ay", "az", "t"}
    if bad:
        raise InputError(f"accelerometer log columns map ax, ay, az and t only, got {sorted(bad)}",
                         param="accel_columns", hint="write for example {param} t=1,ax=2,ay=3,az=4")
    return parse_columns({_TO_GYRO_NAMES.get(k.strip().lower(), k.strip().lower()): v for k, v in spec.items()})


def attach_accelerometer(rec: Recording, path: str | os.PathLike, *, accel_units: str, columns=None,
                         skip_rows: int | None = None, sample_rate: float | None = None,
                         accel_sensitivity: float | None = None, gravity: float = STANDARD_GRAVITY) -> Recording:
    """`rec` with the accelerometer of the log at `path` (and, when the logs' times differ, only their overlap).

    Parameters
    ----------
    rec : Recording
        The gyro's recording.
    path : path-like
        The accelerometer's log (any format :func:`read_recording` reads).
    accel_units : {"m/s^2", "g", "counts"}
    columns : str or dict, optional
        ``t=..,ax=..,ay=..,az=..`` in that log (names or column numbers); default: columns named ax, ay, az.
    skip_rows, sample_rate :
        As for :func:`read_recording`, for that log.
    accel_sensitivity : float, optional
        LSB per g, for counts.
    gravity : float
        One g [m/s^2], for g and counts with a sensitivity.
    """
    acc = read_recording(path, units="rad/s", columns=_gyro_style_columns(columns), skip_rows=skip_rows,
                         sample_rate=sample_rate or rec.sample_rate, check_units=False, saturation="ignore")
    if accel_units not in ("m/s^2", "g", "counts"):
        raise InputError(f"{{param}}={accel_units!r} is not one of m/s^2, g, counts", param="accel_units")
    if accel_units == "counts" and accel_sensitivity is None:
        scale, internal = 1.0, "counts"
    elif accel_units == "counts":
        scale, internal = gravity / accel_sensitivity, "m/s^2"
    else:
        scale, internal = (1.0 if accel_units == "m/s^2" else gravity), "m/s^2"
    values = np.asarray(acc.gyro) * scale
    period = 1.0 / rec.sample_rate
    if len(acc) == len(rec) and np.max(np.abs(np.asarray(acc.t) - rec.t)) <= 0.5 * period:
        joined, keep = values, slice(None)
    else:
        lo, hi = max(rec.t[0], acc.t[0]), min(rec.t[-1], acc.t[-1])
        if hi - lo < 0.5 * (rec.t[-1] - rec.t[0]):
            raise InputError(f"the accelerometer log covers t = {acc.t[0]:.6g} to {acc.t[-1]:.6g} s and the gyro log "
                             f"{rec.t[0]:.6g} to {rec.t[-1]:.6g} s; they share less than half the session",
                             param="accel_log", hint="check that both logs are of the same session and clock")
        keep = (rec.t >= lo) & (rec.t <= hi)
        joined = np.stack([np.interp(rec.t[keep], acc.t, values[:, j]) for j in range(3)], axis=1)
    base = rec if isinstance(keep, slice) else _slice(rec, keep)
    return dataclasses.replace(base, accel=joined, accel_units=internal, accel_source_units=accel_units,
                               accel_sensitivity=accel_sensitivity if accel_units == "counts" else None)


def _slice(rec: Recording, keep: np.ndarray) -> Recording:
    """The samples of `rec` where `keep` is true (a contiguous run)."""
    idx = np.flatnonzero(keep)
    a, b = int(idx[0]), int(idx[-1]) + 1
    fields = {"t": rec.t[a:b], "gyro": rec.gyro[a:b]}
    for name in ("temp", "table_rate", "axis", "accel"):
        value = getattr(rec, name)
        if value is not None:
            fields[name] = value[a:b]
    fields["extra"] = {k: v[a:b] for k, v in rec.extra.items()}
    return dataclasses.replace(rec, **fields)
