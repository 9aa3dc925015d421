"""One entry point for every recording format."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError
from ..recording import Recording
from ._build import STANDARD_GRAVITY, SaturationPolicy, build_recording
from ._source import compression

__all__ = ["read_recording", "read_header_comment", "TEXT_SUFFIXES", "BAG_SUFFIXES"]

TEXT_SUFFIXES = (".csv", ".txt", ".tsv", ".dat")
BAG_SUFFIXES = (".bag", ".db3", ".mcap")


def _kind(path: Path) -> str:
    if path.is_dir():
        if (path / "metadata.yaml").is_file() or any(path.glob("*.db3")) or any(path.glob("*.mcap")):
            return "bag"
        raise InputError(f"{path}: a folder, but not a ROS 2 bag (no metadata.yaml, .db3 or .mcap inside)")
    suffix = path.suffix.lower()
    from .flightlog import flight_log_kind

    if flight_log_kind(path) is not None:
        return "flight"
    if suffix in (".parquet", ".pq"):
        return "parquet"
    if suffix in BAG_SUFFIXES:
        return "bag"
    with open(path, "rb") as f:
        magic = f.read(13)
    if compression(path) is not None:
        return "text"  # a compressed table (.csv.gz, .csv.zst, ...)
    if magic.startswith(b"PAR1"):
        return "parquet"
    if magic.startswith((b"#ROSBAG V2.0", b"\x89MCAP", b"SQLite format")):
        return "bag"
    if magic.lstrip().startswith((b"{", b"[")):
        _refuse_json(path)
    return "text"  # .csv, .txt, .tsv, .dat and anything else that reads as a table


def _refuse_json(path: Path) -> None:
    """A JSON file given where a recording belongs: name what it is (a table never starts with '{')."""
    import json

    try:
        doc = json.loads(path.read_text(encoding="utf-8")) if path.stat().st_size < 50_000_000 else None
    except (UnicodeDecodeError, ValueError):
        return  # not JSON after all: let the table reader say what it finds
    fmt = doc.get("format") if isinstance(doc, dict) else None
    what = f"a gyrocal file ({fmt})" if isinstance(fmt, str) and fmt.startswith("gyrocal.") else "JSON"
    raise InputError(f"{path.name} holds {what}, not a recording; give the log of the sensor's readings (CSV, "
                     "Parquet, a bag or a flight log)")


def read_recording(
    path: str | os.PathLike,
    *,
    units: str,
    columns: dict[str, str] | str | None = None,
    sample_rate: float | None = None,
    sensitivity: float | None = None,
    output_units: str | None = None,
    topic: str | None = None,
    check_units: bool = True,
    saturation: SaturationPolicy = "error",
    full_scale: float | None = None,
    skip_rows: int | None = None,
    accel_units: str | None = None,
    accel_sensitivity: float | None = None,
    gravity: float = STANDARD_GRAVITY,
    need_accel: bool = False,
    imu: int | None = None,
    time_units: str | None = None,
    nan: str = "error",
    notes: list | None = None,
) -> Recording:
    """Read a gyro recording from a file and check it.

    Parameters
    ----------
    path : path-like
        A delimited text table (``.csv .txt .tsv .dat``, plain or compressed: gzip, bz2, xz,
        zstd, lz4, brotli or a zip holding one file), a ``.parquet`` file, a ROS 1 ``.bag``, a
        ROS 2 bag folder or its ``.db3`` / ``.mcap`` file, a PX4 ULog (``.ulg``) or an ArduPilot
        DataFlash log (``.bin``). The format is chosen by suffix, then by the file's first bytes.
    units : {"rad/s", "deg/s", "counts"}
        Unit of the rate columns as written in the file.
    columns : dict or str, optional
        File column for each quantity, ``{"gx": "gyroX", ...}`` or ``"gx=gyroX,gy=gyroY"``, by
        name or by number counting from 1 (``"gx=2,gy=3,gz=4"``; a table without a header row
        needs numbers).
        Quantities: ``t`` [s], ``gx gy gz``, ``temp`` [degC], ``table_rate`` (signed, rate
        units of the data), ``axis`` (x/y/z). Unmapped ones are found by name or by an
        unambiguous alias (``time``, ``gyr_x``, ``gyro_x``, ``wx``, ...).
    sample_rate : float, optional
        Sampling rate [Hz]; required when there is no time column. A time column wins
        when both are present.
    sensitivity : float, optional
        For counts: LSB per `output_units`. Converts counts to rad/s; without it the
        recording keeps raw counts (``Recording.units == "counts"``).
    output_units : {"rad/s", "deg/s"}, optional
        Physical unit behind counts (default deg/s): the unit of `sensitivity` and of a
        ``table_rate`` column in a counts file.
    topic : str, optional
        Bag topic, needed when several topics carry ``sensor_msgs/Imu``.
    check_units : bool
        Refuse likely unit mistakes: rad/s data beyond 2000 deg/s or with a per-sample
        noise above 0.3 rad/s, integer "deg/s" data beyond 5000 deg/s, non-integer counts.
    saturation : {"error", "drop", "ignore"}
        What to do with samples stuck at full scale (see :func:`find_saturation`).
    full_scale : float, optional
        Sensor limit in the file's units; without it, saturation is recognised by runs
        of identical readings at the largest magnitude.
    skip_rows : int, optional
        Text tables: lines to skip above the header row (or above the first data row of a
        table without a header). Default: metadata lines such as ``Fs,100`` are recognised
        (fewer fields than the table, or not followed by data) and skipped.
    accel_units : {"m/s^2", "g", "counts"}, optional
        Unit of the accelerometer columns ``ax, ay, az`` (found by name or alias: ``acc_x``,
        ``accel_x``, ``ax``, ..., or mapped with `columns`). Without it they are not read
        (they pass through as other columns), unless mapped in `columns`, which is refused.
    accel_sensitivity : float, optional
        For ``accel_units="counts"``: LSB per g. Without it accelerometer counts stay counts.
    gravity : float
        One g [m/s^2], for ``g`` and for counts with a sensitivity (default 9.80665).
    need_accel : bool
        Refuse a call without `accel_units` (for commands that need the accelerometer).
    imu : int, optional
        For a PX4 ULog or ArduPilot DataFlash log (:func:`gyrocal.io.read_flight_log`): which
        IMU instance, needed when the log holds several.
    time_units : {"s", "ms", "us", "ns"}, optional
        Unit of the time column. Default: seconds, except that with `sample_rate` given, steps of
        about 1000 or 1e6 declared periods are read as ms or us (with a line in `notes`).
    nan : {"error", "drop"}
        Rows with NaN, inf or empty cells in the columns used: refuse (default) or drop them; dropped
        rows leave a gap in the time stamps (or, without a time column, in the row numbers used as time).
    notes : list, optional
        Receives one line per thing done that the data did not say (ms stamps recognised, rows dropped).

    Returns
    -------
    Recording
        Rates in rad/s (or counts), ``source_units`` = `units`, extra columns as text.

    Raises
    ------
    InputError, NonFiniteInputError, UnitError, SaturationError, MissingDependencyError
        With one sentence naming the file, the column or row, and what to do.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(f"recording {str(path)!r} does not exist")
    if need_accel and accel_units is None:
        raise InputError(f"{path.name}: the accelerometer's unit is not given", param="accel_units",
                         hint="give {param} m/s^2, g or counts (with the accelerometer sensitivity for counts)")
    accel = accel_units is not None
    kind = _kind(path)
    if topic is not None and kind != "bag":
        raise InputError(f"{{param}} applies to ROS bags only; {path.name} is a {kind} file", param="topic")
    if kind == "flight":
        from .flightlog import read_flight_log

        if columns or skip_rows is not None or sample_rate is not None:
            raise InputError(f"{path.name}: columns, skip_rows and sample_rate do not apply to PX4 and ArduPilot logs "
                             "(their IMU fields and time stamps are used)")
        return read_flight_log(path, imu=imu, units=units, check_units=check_units, saturation=saturation,
                               accel_units=accel_units)[0]
    if imu is not None:
        raise InputError(f"{{param}} applies only to PX4 ULog and ArduPilot DataFlash logs, not to {path.name}",
                         param="imu")
    if skip_rows is not None:
        if kind != "text":
            raise InputError(f"{{param}} applies to text tables only; {path.name} is a {kind} file", param="skip_rows")
        if isinstance(skip_rows, bool) or not isinstance(skip_rows, int) or skip_rows < 0:
            raise InputError(f"{{param}} must be a whole number >= 0, got {skip_rows!r}", param="skip_rows",
                             value=skip_rows)
    if kind == "bag":
        from .rosbag import read_bag_columns

        if columns:
            raise InputError("{param} does not apply to ROS bags (angular_velocity and header stamps are used)",
                             param="columns")
        data, extra = read_bag_columns(path, topic, accel=accel)
    elif kind == "parquet":
        from .parquet import read_parquet_columns

        data, extra = read_parquet_columns(path, columns, accel=accel)
    else:
        from .csvfile import read_csv_columns

        data, extra = read_csv_columns(path, columns, skip_rows=skip_rows, accel=accel)
    return build_recording(
        data,
        extra,
        source=path.name,
        units=units,
        sample_rate=sample_rate,
        sensitivity=sensitivity,
        output_units=output_units,
        check_units=check_units,
        saturation=saturation,
        full_scale=full_scale,
        accel_units=accel_units,
        accel_sensitivity=accel_sensitivity,
        gravity=gravity,
        time_units=time_units,
        nan=nan,
        notes=notes,
    )


def read_header_comment(path: str | os.PathLike) -> str | None:
    """The first line of a text table when it is a ``#`` comment (without the ``#``), else None.

    ``gyrocal apply`` and ``gyrocal simulate`` say there what wrote the file; Parquet files and
    bags have no such line.
    """
    from ._source import open_bytes

    path = Path(path)
    if not path.is_file() or _kind(path) != "text":
        return None
    try:
        with open_bytes(path, compression(path)) as f:
            head = f.read(4096)
    except (OSError, EOFError, InputError):
        return None
    line = head.decode("utf-8-sig", errors="replace").lstrip("\n\r").split("\n", 1)[0].strip()
    return line[1:].strip() if line.startswith("#") else None
