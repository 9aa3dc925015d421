"""Two reading choices applied to parsed columns: the time column's unit, and rows holding NaN."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..recording.timebase import nominal_period
from ._columns import NUMERIC

#: Seconds per unit of a time column.
TIME_FACTORS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
#: A time step within this fraction of 1000 or 1e6 declared periods is read as ms or us.
RECOGNISE = 0.1


def time_in_seconds(t: np.ndarray, time_units: str | None, sample_rate: float | None, source: str,
                    notes: list) -> np.ndarray:
    """`t` in seconds: scaled by `time_units`, else recognised from a declared `sample_rate`."""
    if time_units is not None:
        unit = time_units.strip().lower().replace("\u00b5s", "us")
        if unit not in TIME_FACTORS:
            raise InputError(f"{{param}} {time_units!r} is not accepted", param="time_units", value=time_units,
                             hint="use s, ms, us or ns")
        return t if unit == "s" else t * TIME_FACTORS[unit]
    if sample_rate is None or len(t) < 2:
        return t
    ratio = nominal_period(t) * sample_rate
    for unit in ("ms", "us"):
        if abs(ratio * TIME_FACTORS[unit] - 1.0) < RECOGNISE:
            notes.append(f"{source}: the time column steps by {ratio:.4g} periods of the declared {sample_rate:g} Hz; "
                         f"read as {unit} (say --time-units to choose)")
            return t * TIME_FACTORS[unit]
    return t


def drop_nan_rows(data: dict, extra: dict, policy: str, source: str, notes: list):
    """`data`, `extra` without the rows holding NaN or inf in a numeric column, and the kept row numbers
    (None when nothing is dropped); `policy` "error" leaves them to the finiteness check."""
    if policy not in ("error", "drop"):
        raise InputError(f"{{param}} {policy!r} is not accepted", param="nan", value=policy,
                         hint="use 'drop' (or leave it out to refuse such rows)")
    if policy == "error":
        return data, extra, None
    bad = None
    for c in NUMERIC:
        if c in data:
            col_bad = ~np.isfinite(np.asarray(data[c], dtype=float))
            bad = col_bad if bad is None else bad | col_bad
    if bad is None or not bad.any():
        return data, extra, None
    keep = ~bad
    first = int(np.argmax(bad))
    notes.append(f"{source}: {int(bad.sum())} row(s) with NaN, inf or empty cells dropped (--nan drop), first at "
                 "data row " f"{first + 1}; the time base treats them as gaps")
    data = {k: np.asarray(v)[keep] for k, v in data.items()}
    extra = {k: np.asarray(v)[keep] for k, v in extra.items()}
    return data, extra, np.flatnonzero(keep)
