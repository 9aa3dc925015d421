"""Flight-controller logs: PX4 ULog (``.ulg``) and ArduPilot DataFlash (``.bin``), one IMU at a time."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Literal

from ..errors import InputError, UnitError
from ..recording import Recording
from ._build import SaturationPolicy, build_recording

__all__ = ["FLIGHT_SUFFIXES", "flight_log_kind", "read_flight_log"]

FLIGHT_SUFFIXES = (".ulg", ".bin")
FlightLogKind = Literal["ulog", "dataflash"]
_ULOG_MAGIC = b"ULog\x01\x12\x35"
_DATAFLASH_MAGIC = b"\xa3\x95\x80"  # a FORMAT message (type 128) opens every DataFlash log


def flight_log_kind(path: Path) -> FlightLogKind | None:
    """``ulog`` or ``dataflash`` by the file's first bytes (then its suffix); None for anything else."""
    with open(path, "rb") as f:
        magic = f.read(7)
    if magic.startswith(_ULOG_MAGIC):
        return "ulog"
    if magic.startswith(_DATAFLASH_MAGIC):
        return "dataflash"
    return {".ulg": "ulog", ".bin": "dataflash"}.get(path.suffix.lower())


def _choose(instances: dict, imu: int | None, source: str) -> int:
    if imu is None:
        if len(instances) == 1:
            return next(iter(instances))
        listed = ", ".join(f"{i}{_label(info)}" for i, (_, _, info) in sorted(instances.items()))
        raise InputError(f"{source}: {len(instances)} IMUs in this log ({listed})", param="imu",
                         hint="choose one with {param} N")
    if imu not in instances:
        raise InputError(f"{source}: no IMU {imu}; the log holds {', '.join(map(str, sorted(instances)))}",
                         param="imu", value=imu)
    return imu


def _label(info: dict) -> str:
    return f" (device id {info['device_id']})" if info.get("device_id") is not None else ""


def read_flight_log(path: str | os.PathLike, *, imu: int | None = None, units: str | None = "rad/s",
                    check_units: bool = True, saturation: SaturationPolicy = "error",
                    accel_units: str | None = None) -> tuple[Recording, dict]:
    """One IMU of a PX4 ULog or an ArduPilot DataFlash log, and what the log says about it.

    Parameters
    ----------
    path : path-like
        A ``.ulg`` or ``.bin`` file.
    imu : int, optional
        Instance (PX4 ``multi_id``, ArduPilot ``I``, both from 0); needed when there are several.
    units : {"rad/s", None}
        Both firmwares log rad/s; any other declared unit is refused.
    accel_units : {"m/s^2", None}
        Read the accelerometer too (both firmwares log m/s^2); without it, it is not read.

    Returns
    -------
    recording : Recording
    info : dict
        ``format``, ``instance`` and the reader's notes (PX4 ``device_id``; ArduPilot ``imu_number``
        (1 for the first IMU) and the corrections undone).
    """
    path = Path(path)
    if units not in (None, "rad/s"):
        raise UnitError(f"{path.name}: PX4 and ArduPilot log gyro rates in rad/s, not {units}", param="units",
                        value=units, hint="give {param} rad/s")
    if accel_units not in (None, "m/s^2"):
        raise UnitError(f"{path.name}: PX4 and ArduPilot log accelerations in m/s^2, not {accel_units}",
                        param="accel_units", value=accel_units, hint="give {param} m/s^2")
    kind = flight_log_kind(path)
    if kind == "ulog":
        from .ulog import read_ulog_columns

        instances = read_ulog_columns(path)
    elif kind == "dataflash":
        from .dataflash import read_dataflash_columns

        instances = read_dataflash_columns(path)
    else:
        raise InputError(f"{path.name}: neither a PX4 ULog nor an ArduPilot DataFlash log")
    chosen = _choose(instances, imu, path.name)
    data, extra, info = instances[chosen]
    if accel_units is None:
        data = {k: v for k, v in data.items() if k not in ("ax", "ay", "az")}
    elif "ax" not in data:
        raise InputError(f"{path.name}: IMU {chosen} has no accelerometer data in this log", param="accel_units",
                         hint="leave out {param}")
    rec = build_recording(data, extra, source=f"{path.name} IMU {chosen}", units="rad/s", check_units=check_units,
                          saturation=saturation, accel_units=accel_units)
    return rec, {"format": kind, "instance": chosen, **info}
