"""PX4 ULog files (``.ulg``), read with ``pyulog`` (``ulog`` extra).

Each ``sensor_gyro`` instance (``multi_id``) is one IMU: ``x, y, z`` [rad/s] in the sensor's
frame before any calibration (the frame PX4's ``TC_G`` thermal parameters apply in),
``temperature`` [degC], ``timestamp_sample`` [us] and ``device_id``. The ``sensor_accel``
instance logged with the same ``device_id`` pairing (``vehicle_imu``) or the same
``multi_id`` gives ``x, y, z`` [m/s^2]. PX4 logs these topics at full rate only with the
logger profiles for thermal calibration or high-rate sensors (``SDLOG_PROFILE``).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .._arrays import median
from ..errors import InputError, MissingDependencyError

__all__ = ["read_ulog_columns"]


def _topics(path: Path):
    try:
        from pyulog import ULog
    except ImportError:
        raise MissingDependencyError("reading PX4 ULog files needs pyulog: pip install 'gyrocal[ulog]'") from None
    try:
        return ULog(str(path), ["sensor_gyro", "sensor_accel"]).data_list
    except Exception as exc:  # pyulog's own errors: not a ULog, truncated, corrupt
        raise InputError(f"{path.name}: cannot read the ULog ({type(exc).__name__}: {exc})") from None


def _stamps(d) -> np.ndarray:
    us = d.data["timestamp_sample"] if "timestamp_sample" in d.data else d.data["timestamp"]
    return np.asarray(us, dtype=np.int64)


def _unique(us: np.ndarray) -> np.ndarray:
    """Indices that sort the samples by time and keep the first of each repeated stamp."""
    order = np.argsort(us, kind="stable")
    keep = np.concatenate(([True], np.diff(us[order]) > 0))
    return order[keep]


def read_ulog_columns(path: str | os.PathLike) -> dict[int, tuple[dict, dict, dict]]:
    """Columns of every gyro instance of a ULog.

    Returns
    -------
    dict
        ``{instance: (data, extra, info)}``: ``data`` holds ``t`` [s], ``gx gy gz`` [rad/s],
        ``temp`` [degC] and, when the paired accelerometer is logged, ``ax ay az`` [m/s^2]
        (interpolated onto the gyro's stamps when they differ); ``extra`` is empty; ``info``
        holds ``device_id``, ``accel_device_id`` and ``duplicates`` (repeated stamps dropped).
    """
    path = Path(path)
    topics = _topics(path)
    gyros = {d.multi_id: d for d in topics if d.name == "sensor_gyro"}
    accels = {d.multi_id: d for d in topics if d.name == "sensor_accel"}
    if not gyros:
        raise InputError(f"{path.name}: no sensor_gyro topic in this ULog; PX4 logs it with the thermal-calibration "
                         "or high-rate-sensors logger profile (SDLOG_PROFILE)")
    out = {}
    for inst, d in sorted(gyros.items()):
        us = _stamps(d)
        keep = _unique(us)
        data = {"t": us[keep] * 1e-6, "gx": np.asarray(d.data["x"], float)[keep],
                "gy": np.asarray(d.data["y"], float)[keep], "gz": np.asarray(d.data["z"], float)[keep]}
        if "temperature" in d.data:
            data["temp"] = np.asarray(d.data["temperature"], float)[keep]
        dev = int(median(d.data["device_id"])) if "device_id" in d.data else None
        info = {"device_id": dev, "accel_device_id": None, "duplicates": int(len(us) - len(keep))}
        acc = next((a for a in accels.values() if dev is not None and "device_id" in a.data
                    and int(median(a.data["device_id"])) == dev), accels.get(inst))
        if acc is not None and len(acc.data["x"]) > 1:
            aus = _stamps(acc)
            akeep = _unique(aus)
            for col, name in (("x", "ax"), ("y", "ay"), ("z", "az")):
                data[name] = np.interp(data["t"], aus[akeep] * 1e-6, np.asarray(acc.data[col], float)[akeep])
            info["accel_device_id"] = int(median(acc.data["device_id"])) if "device_id" in acc.data else None
        out[int(inst)] = (data, {}, info)
    return out
