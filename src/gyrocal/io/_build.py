"""From parsed columns to a checked :class:`~gyrocal.recording.Recording` in internal units."""

from __future__ import annotations

import math

import numpy as np

from .._arrays import distinct, median
from .._validation import positive
from .._white import robust_difference_std
from ..choices import AccelUnit, SaturationPolicy, values
from ..constants import STANDARD_GRAVITY
from ..errors import InputError, NonFiniteInputError, SaturationError, UnitError
from ..recording import Recording
from ..recording.breaks import BREAK_S, counter_breaks, find_counter, join_backward_parts
from ..recording.saturation import find_saturation, stuck_runs
from ..recording.timebase import nominal_period
from ..units import parse_input_unit, parse_rate_unit, unit_factor
from ._columns import ACCEL, NUMERIC
from ._rows import drop_nan_rows, time_in_seconds

#: No MEMS gyro measures beyond about 2000 deg/s (4000 for a few); above this, rad/s is a unit mistake.
MAX_PLAUSIBLE_RAD_S = math.radians(2000.0)
MAX_PLAUSIBLE_DEG_S = 5000.0
#: MEMS gyros sample at 0.5 Hz-100 kHz; a time step outside that is a time column not in seconds.
MIN_SAMPLE_RATE, MAX_SAMPLE_RATE = 0.5, 100e3
#: Per-sample noise [rad/s] above any MEMS gyro's (0.001-0.05 typical): deg/s data declared as rad/s.
#: It catches deg/s logs whose noise is at least 0.3 deg/s per sample; quieter ones need the peak test.
MAX_PLAUSIBLE_NOISE_RAD_S = 0.3
#: Beyond any sensor's readings in any unit (a 64-bit counter stays under 1e19): numbers a calibration
#: cannot even square without overflow, refused whatever --no-unit-check says.
MAX_MAGNITUDE = 1e20
#: Samples the noise estimate looks at: enough for a robust median, bounded on long logs.
NOISE_SAMPLES = 100_000


def _check_finite(data: dict, source: str, known_finite: tuple[str, ...] = ()) -> None:
    # a sum is one fast pass and is finite when every term is (bar overflow, rechecked below)
    if all(np.isfinite(np.sum(data[c])) for c in NUMERIC if c in data and c not in known_finite):
        return
    bad = None
    for c in NUMERIC:
        if c in data and not np.isfinite(data[c]).all():
            col_bad = ~np.isfinite(data[c])
            bad = col_bad if bad is None else bad | col_bad
    if bad is None:
        return  # the sum overflowed; every value is finite
    first = int(np.argmax(bad))
    cols = [c for c in NUMERIC if c in data and not np.isfinite(data[c][first])]
    raise NonFiniteInputError(
        f"{source}: {int(bad.sum())} row(s) hold NaN, inf or empty cells, first at data row {first + 1} "
        f"(column {', '.join(cols)}); remove or fill those rows first, or drop them ({{param}} drop)", param="nan"
    )


def _check_time(t: np.ndarray, source: str) -> float:
    """Check that time increases; return the nominal rate [Hz] (:func:`gyrocal.recording.timebase.nominal_period`)."""
    increasing = t[1:] > t[:-1]
    if not increasing.all():
        i = int(np.argmin(increasing))
        tied = t[i + 1] == t[i]
        ties = int(np.count_nonzero(t[1:] == t[:-1])) if tied else 0
        fix = ("sort the log and drop repeated rows" if ties * 20 < len(t) else
               # many ties: samples of one packet stamped with its receive time, not repeated rows
               f"{ties} rows share their time with the one before: samples of one packet stamped with its receive "
               "time? Leave the time column out (--columns without t) and give --sample-rate, or stamp each sample")
        raise InputError(
            # float(): plain numbers, not numpy reprs; str keeps every digit of epoch stamps
            f"{source}: {'a duplicated timestamp' if tied else 'time going backwards'} at data row {i + 2} "
            f"(t={float(t[i])} then {float(t[i + 1])}); times must increase strictly: {fix}"
        )
    # the mean step of the sensor clock, robust to gaps (gyrocal.recording.timebase): never the median step of bursty
    # receive-time stamps, and block means of 64 steps average away the 0.24 us quantum of epoch stamps
    step = nominal_period(t)
    fs = 1.0 / step
    # ms or ns stamps under a plain name (t, time, timestamp) read as seconds; the 1e-6 slack
    # lets stamps at exactly 0.5 Hz or 100 kHz through despite rounding
    if not MIN_SAMPLE_RATE * (1 - 1e-6) <= fs <= MAX_SAMPLE_RATE * (1 + 1e-6):
        raise InputError(
            f"{source}: the nominal time step is {step:.6g}, {fs:.3g} Hz if the times are seconds, "
            "outside the 0.5 Hz-100 kHz of a gyro; times in ms, us or ns need {param} ms, us or ns, or the unit "
            "in the column's name (e.g. time_ms)", param="time_units"
        )
    return fs


def _noise(raw: np.ndarray) -> float:
    """Per-sample noise, robust to turns (:func:`~gyrocal._white.robust_difference_std`), on the quietest
    axis so that one shaking axis cannot make rad/s data look like deg/s."""
    return float(np.min(robust_difference_std(np.diff(raw[:NOISE_SAMPLES + 1], axis=0))))


def _check_units(raw: np.ndarray, unit: str, sensitivity: float | None, source: str, peak: float) -> None:
    if unit == "counts":
        if not np.array_equal(raw, np.round(raw)):
            i = int(np.argmax((raw != np.round(raw)).any(axis=1)))
            raise UnitError(
                f"{source}: units are counts but data row {i + 1} holds non-integer readings {raw[i].tolist()}",
                param="units", hint="raw counts are integers: declare the rate unit instead ({param} deg/s or rad/s)"
            )
    elif unit == "rad/s" and peak > MAX_PLAUSIBLE_RAD_S:
        raise UnitError(
            f"{source}: rates reach {peak:.4g} rad/s ({math.degrees(peak):.4g} deg/s), beyond any MEMS gyro's range",
            param="units", hint="the data are almost surely in deg/s: use {param} deg/s (or {param:check_units})"
        )
    elif unit == "rad/s" and (noise := _noise(raw)) > MAX_PLAUSIBLE_NOISE_RAD_S:
        # slow turns in deg/s stay under the peak test, but their noise is 57 times too large
        raise UnitError(
            f"{source}: the per-sample noise is {noise:.3g} rad/s, far above any MEMS gyro's (0.001-0.05)",
            param="units", hint="the data are almost surely in deg/s: use {param} deg/s (or {param:check_units})"
        )
    elif unit == "deg/s" and peak > MAX_PLAUSIBLE_DEG_S and np.array_equal(raw, np.round(raw)):
        raise UnitError(
            f"{source}: integer rates reach {peak:.6g} deg/s, beyond any MEMS gyro's range", param="units",
            hint="these look like raw counts: use {param} counts (with {param:sensitivity} if known)"
        )


#: A board at rest, or turned by hand, reads about one g; a median |a| outside this range [g] is a unit mistake.
PLAUSIBLE_G = (0.5, 2.0)


def _check_accel_units(accel: dict, gravity: float, source: str) -> None:
    """Refuse accelerations whose typical size says another unit: m/s^2 read as g reads 9.8 g at rest."""
    if accel.get("accel_units") != "m/s^2":
        return  # counts without a sensitivity have no scale to check
    a = accel["accel"]
    level = float(median(np.linalg.norm(a[:: max(1, len(a) // NOISE_SAMPLES)], axis=1))) / gravity
    if PLAUSIBLE_G[0] <= level <= PLAUSIBLE_G[1]:
        return
    declared = accel["accel_source_units"]
    likely = {"g": "m/s^2", "m/s^2": "g"}.get(declared) if 7.0 < max(level, 1 / max(level, 1e-300)) < 14.0 else None
    if declared == "counts":
        fix = "check {param:accel_sensitivity} (LSB per g)"
    elif likely is not None and (level > 1) == (declared == "g"):
        fix = f"the data are almost surely in {likely}: use {{param}} {likely}"
    else:
        fix = "check {param} and the accelerometer columns"
    raise UnitError(f"{source}: the accelerometer reads {level:.3g} g in a typical sample (declared {declared}), "
                    "where a board at rest or turned by hand reads about 1 g", param="accel_units",
                    hint=f"{fix} (or {{param:check_units}})")


def _check_saturation(raw, full_scale, policy: str, source: str, extremes) -> np.ndarray | None:
    """Rows to keep (None: all); `extremes` are each axis's (max, min)."""
    if policy not in ("error", "drop", "ignore"):
        raise InputError(f"{{param}} {policy!r} is not accepted", param="saturation", value=policy,
                         hint="use 'error', 'drop' or 'ignore'")
    if policy == "ignore":
        return None
    mask = find_saturation(raw, full_scale) if full_scale is not None else stuck_runs(raw, *extremes)
    if not mask.any():
        return None
    if policy == "drop":
        return ~mask.any(axis=1)
    j = int(np.argmax(mask.any(axis=0)))
    rows = np.flatnonzero(mask[:, j])
    level = float(np.max(np.abs(raw[rows, j])))
    stop = rows[0] + int(np.argmax(np.r_[np.diff(rows) != 1, True]))
    raise SaturationError(
        f"{source}: axis {'xyz'[j]} is stuck at full scale (+-{level:.6g}) in {len(rows)} sample(s), "
        f"first at data rows {rows[0] + 1}-{stop + 1}; those readings are not measurements", param="saturation",
        hint="record again with a larger range or slower turns, or drop them ({param} drop)"
    )


def _rates_block(gx, gy, gz) -> np.ndarray:
    """Column-major (N, 3) rates: the transpose of the reader's own (3, N) block when gx, gy, gz
    are its rows, else a new copy.

    Column-major keeps every per-axis pass (checks, segmentation, window means) contiguous.
    """
    base = gx.base
    if (
        isinstance(base, np.ndarray) and base.ndim == 2 and base.shape == (3, len(gx)) and base.dtype == np.float64
        and base.flags.c_contiguous and all(c.base is base for c in (gy, gz))
        and [c.ctypes.data - base.ctypes.data for c in (gx, gy, gz)] == [0, 8 * len(gx), 16 * len(gx)]
    ):
        return base.T
    return np.array([gx, gy, gz], dtype=float).T


#: Standard gravity [m/s^2], the default value of one g.


def _accel_fields(data: dict, source: str, accel_units: str | None, accel_sensitivity: float | None,
                  gravity: float) -> dict:
    """The Recording's accelerometer fields from parsed ``ax, ay, az`` columns (none without `accel_units`)."""
    g0 = positive("gravity", gravity)  # a nonsense value is refused even where no g is used
    if accel_units is None:
        if any(c in data for c in ACCEL):
            raise InputError(f"{source}: accelerometer columns are mapped but their unit is not given",
                             param="accel_units", hint="give {param} m/s^2, g or counts")
        if accel_sensitivity is not None:
            raise UnitError("{param} needs {param:accel_units} counts", param="accel_sensitivity")
        return {}
    unit = accel_units.strip().lower().replace("m/s2", "m/s^2").replace("m/s/s", "m/s^2")
    if unit not in values(AccelUnit):
        raise UnitError(f"{{param}}={accel_units!r} is not a known unit; use one of {', '.join(values(AccelUnit))}",
                        param="accel_units", value=accel_units)
    if accel_sensitivity is not None:
        if unit != "counts":
            raise UnitError(f"{{param}} applies only to {{param:accel_units}} counts, not {accel_units}",
                            param="accel_sensitivity", value=accel_sensitivity, hint="leave it out, or give counts")
        accel_sensitivity = positive("accel_sensitivity", accel_sensitivity)
    raw = np.array([data["ax"], data["ay"], data["az"]], dtype=float).T
    if unit == "counts" and accel_sensitivity is None:
        return {"accel": raw, "accel_units": "counts", "accel_source_units": "counts"}
    factor = {"m/s^2": 1.0, "g": g0}.get(unit) or g0 / accel_sensitivity
    return {"accel": raw * factor, "accel_units": "m/s^2", "accel_source_units": unit,
            "accel_sensitivity": accel_sensitivity}


def _axis_labels(values) -> np.ndarray:
    """The axis column as text without surrounding blanks (one-letter labels have none to strip)."""
    labels = np.asarray(values, dtype=str)
    return labels if labels.dtype.itemsize == 4 else np.char.strip(labels)


def _reading_options(units: str, output_units: str | None, sensitivity: float | None,
                     sample_rate: float | None) -> tuple[str, str, float | None, float | None]:
    """The unit, output unit, sensitivity and sample rate, checked before any data is looked at."""
    unit = parse_input_unit(units, "units")
    out_unit = parse_rate_unit(output_units, "output_units") if output_units is not None else "deg/s"
    if sensitivity is not None:
        if unit != "counts":
            raise UnitError(f"{{param}} applies only to {{param:units}} counts, not {units}", param="sensitivity",
                            value=sensitivity, hint="leave it out, or give counts")
        sensitivity = positive("sensitivity", sensitivity)
    if sample_rate is not None:
        sample_rate = positive("sample_rate", sample_rate)  # refused even where a time column wins
    return unit, out_unit, sensitivity, sample_rate


def build_recording(
    data: dict,
    extra: dict,
    *,
    source: str,
    units: str,
    sample_rate: float | None = None,
    sensitivity: float | None = None,
    output_units: str | None = None,
    check_units: bool = True,
    saturation: SaturationPolicy = "error",
    full_scale: float | None = None,
    accel_units: str | None = None,
    accel_sensitivity: float | None = None,
    gravity: float = STANDARD_GRAVITY,
    time_units: str | None = None,
    nan: str = "error",
    notes: list | None = None,
) -> Recording:
    """Check parsed columns and convert them to a :class:`Recording` (see :func:`gyrocal.io.read_recording`)."""
    accel = _accel_fields(data, source, accel_units, accel_sensitivity, gravity)
    unit, out_unit, sensitivity, sample_rate = _reading_options(units, output_units, sensitivity, sample_rate)
    data, extra, rows = drop_nan_rows(data, extra, nan, source, [] if notes is None else notes)
    n = len(data["gx"])
    if n < 2:
        raise InputError(f"{source}: {'no data rows' if n == 0 else 'a single data row'}; a recording needs at least two samples")
    raw = _rates_block(data["gx"], data["gy"], data["gz"])
    # one pass for each axis's extremes serves the finiteness, unit and saturation checks (NaN propagates)
    hi, lo = raw.max(axis=0), raw.min(axis=0)
    rates_finite = bool(np.isfinite(hi).all() and np.isfinite(lo).all())
    _check_finite(data, source, known_finite=("gx", "gy", "gz") if rates_finite else ())
    if (peak := max(float(hi.max()), -float(lo.min()))) > MAX_MAGNITUDE:
        raise InputError(f"{source}: readings reach {peak:.3g}, beyond any sensor in any unit; the column "
                         "holds something else (an id, a time stamp, a checksum?)", param="columns",
                         hint="map the gyro's columns with {param} gx=NAME,gy=NAME,gz=NAME")
    t, has_time, fs, breaks = _time_column(data, extra, n, rows, sample_rate, time_units, source,
                                           [] if notes is None else notes)
    if check_units:
        _check_units(raw, unit, sensitivity, source, peak=peak)
        _check_accel_units(accel, gravity, source)
    keep = _check_saturation(raw, full_scale, saturation, source, (hi, lo))
    if unit == "counts":
        factor = 1.0 if sensitivity is None else unit_factor(out_unit) / sensitivity
        table_factor = unit_factor(out_unit)  # a table's rate is physical, never counts
    else:
        factor = table_factor = unit_factor(unit)
    gyro = raw
    if factor != 1.0:
        gyro *= factor  # raw is this function's own array
    fields = {
        "t": t,
        "gyro": gyro,
        "temp": data.get("temp"),
        "table_rate": None if "table_rate" not in data else data["table_rate"] * table_factor,
        "axis": None if "axis" not in data else _axis_labels(data["axis"]),
        "extra": dict(extra),
        **accel,
    }
    if keep is not None:
        fields = {k: (v[keep] if isinstance(v, np.ndarray) else v) for k, v in fields.items()}
        fields["extra"] = {k: np.asarray(v)[keep] for k, v in extra.items()}
        kept = np.flatnonzero(keep)
        breaks = tuple(b for b in distinct(np.searchsorted(kept, breaks)) if 0 < b < len(kept))
    return Recording(
        **fields,
        units="counts" if unit == "counts" and sensitivity is None else "rad/s",
        source_units=unit,
        sample_rate=fs,
        has_time=has_time,
        sensitivity=sensitivity,
        breaks=breaks,
    )


def _time_column(data: dict, extra: dict, n: int, rows, sample_rate, time_units, source: str, notes: list):
    """``(t, has_time, fs, breaks)``: the stamps [s] (parts glued out of order laid end to end), whether they
    came from the data, the nominal rate and the breaks (:mod:`gyrocal.recording.breaks`)."""
    breaks: tuple = ()
    if "t" in data:
        t, has_time = np.asarray(data["t"], dtype=float), True  # a time column wins over sample_rate
        t = time_in_seconds(t, time_units, sample_rate, source, notes)
        if (joined := join_backward_parts(t)) is not None:  # parts glued out of order: laid end to end
            t, breaks = joined[0], tuple(joined[1])
        fs = _check_time(t, source)
    elif sample_rate is not None:
        fs = sample_rate
        # rows dropped for NaN keep their row numbers: a gap in the time base, not samples glued together
        t, has_time = (np.arange(n) if rows is None else rows.astype(float)) / fs, False
    else:
        raise InputError(
            f"{source}: no time column (t, time, timestamp, ...)", param="sample_rate",
            hint="give the sample rate ({param} HZ) or map the time column ({param:columns} t=NAME)"
        )
    t, breaks = _counter_parts(extra, t, has_time, fs, breaks)
    return t, has_time, fs, breaks


def _counter_parts(extra: dict, t: np.ndarray, has_time: bool, fs: float, breaks: tuple):
    """Breaks read from a sample counter column, joined with `breaks`; without a time column the
    samples a counter says were lost also move the later stamps (a gap)."""
    found = find_counter(extra)
    if found is None:
        return t, breaks
    cut, lost = counter_breaks(found[1], BREAK_S * fs)
    if not has_time and lost.any():
        t = t + np.cumsum(lost) / fs
    return t, tuple(sorted({*breaks, *(int(b) for b in cut)}))
