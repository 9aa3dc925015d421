"""ArduPilot DataFlash logs (``.bin``), read with ``pymavlink`` (``dataflash`` extra).

``IMU`` messages carry ``TimeUS`` [us], the instance ``I``, ``GyrX/Y/Z`` [rad/s],
``AccX/Y/Z`` [m/s^2] and ``T`` [degC] (older logs: ``IMU2``, ``IMU3`` messages for the
second and third IMU). ArduPilot logs them *corrected*: in the sensor frame it subtracts the
temperature correction (when ``INS_TCALn_ENABLE`` is 1) and the offsets ``INS_GYROFFS``,
then rotates by ``AHRS_ORIENTATION`` (``AP_InertialSensor_Backend::_rotate_and_correct_gyro``).
As ArduPilot's ``Tools/scripts/tempcal_IMU.py`` does, this reader undoes the rotation and
the temperature correction from the log's ``PARM`` messages, and adds the offsets back, so
the gyro columns are the raw readings in the frame the ``INS_TCAL`` parameters apply in. The
accelerometer likewise (``_rotate_and_correct_accel``: the ``ACC`` temperature terms about
``INS_ACCn_CALTEMP``, then ``INS_ACCOFFS`` and ``INS_ACCSCAL``).
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np

from ..errors import GyrocalWarning, InputError, MissingDependencyError

__all__ = ["DataFlashWarning", "read_dataflash_columns"]

_TYPES = ("IMU", "IMU2", "IMU3", "PARM")


class DataFlashWarning(GyrocalWarning):
    """A parameter the reader relies on changed during the log."""


def _reader(path: Path):
    try:
        from pymavlink.DFReader import DFReader_binary
    except ImportError:
        raise MissingDependencyError("reading ArduPilot DataFlash logs needs pymavlink: pip install "
                                     "'gyrocal[dataflash]'") from None
    try:
        return DFReader_binary(str(path), zero_time_base=False)
    except Exception as exc:  # pymavlink's own errors: not a DataFlash log, truncated
        raise InputError(f"{path.name}: cannot read the DataFlash log ({type(exc).__name__}: {exc})") from None


def _next(log, path: Path):
    try:
        return log.recv_match(type=list(_TYPES))
    except Exception as exc:  # a truncated or corrupt message
        raise InputError(f"{path.name}: cannot read the DataFlash log ({type(exc).__name__}: {exc})") from None


def _messages(path: Path) -> tuple[dict[int, list], dict, list[str]]:
    """IMU rows per instance, the parameters before the first IMU row, and parameters changed later."""
    log = _reader(path)
    rows: dict[int, list] = {}
    params: dict[str, float] = {}
    changed: list[str] = []
    try:
        while (msg := _next(log, path)) is not None:
            kind = msg.get_type()
            if kind == "PARM":
                if rows and params.get(msg.Name) != msg.Value:
                    changed.append(msg.Name)
                elif not rows:
                    params[msg.Name] = float(msg.Value)
                continue
            inst = int(getattr(msg, "I", 0)) if kind == "IMU" else int(kind[-1]) - 1
            rows.setdefault(inst, []).append((msg.TimeUS, msg.GyrX, msg.GyrY, msg.GyrZ, msg.AccX, msg.AccY, msg.AccZ,
                                              getattr(msg, "T", np.nan)))
    finally:
        log.close()
    return rows, params, changed


def _orientation(rot_id: int) -> np.ndarray:
    """The matrix of ArduPilot's inverse board rotation ``rot_id`` (pymavlink's table)."""
    from pymavlink.rotmat import Vector3

    cols = [Vector3(*e).rotate_by_inverse_id(rot_id) for e in np.eye(3)]
    if any(c is None for c in cols):
        raise InputError(f"AHRS_ORIENTATION = {rot_id} is not a rotation pymavlink knows; cannot undo it")
    return np.array([[c.x, c.y, c.z] for c in cols]).T


def _tcal(params: dict, n: int, temp: np.ndarray, sensor: str = "GYR") -> np.ndarray | None:
    """What ``correct_sensor`` subtracted (N, 3) for IMU number n (GYR [rad/s] or ACC [m/s^2]), or None when off."""
    if params.get(f"INS_TCAL{n}_ENABLE") != 1:
        return None
    lo, hi = params.get(f"INS_TCAL{n}_TMIN", 0.0), params.get(f"INS_TCAL{n}_TMAX", 70.0)
    c = np.array([[params.get(f"INS_TCAL{n}_{sensor}{k}_{ax}", 0.0) for ax in "XYZ"] for k in (1, 2, 3)]) * 1e-6

    def poly(x):
        x = np.asarray(x, float)[..., None]
        return (c[0] + (c[1] + c[2] * x) * x) * x

    cal = np.clip(params.get(f"INS_{sensor}{n}_CALTEMP", lo), lo, hi)
    return poly(np.clip(temp, lo, hi) - 35.0) - poly(cal - 35.0)


def _raw_accel(params: dict, n: int, acc: np.ndarray, temp: np.ndarray, undone: list) -> np.ndarray:
    """The accelerometer before ``_rotate_and_correct_accel``'s temperature correction, offsets and scale."""
    suffix = "" if n == 1 else str(n)
    scale = np.array([params.get(f"INS_ACC{suffix}SCAL_{ax}", 1.0) or 1.0 for ax in "XYZ"])
    offsets = np.array([params.get(f"INS_ACC{suffix}OFFS_{ax}", 0.0) for ax in "XYZ"])
    tcal = _tcal(params, n, temp, "ACC") if np.isfinite(temp).all() else None
    if np.any(scale != 1) or np.any(offsets != 0):
        acc = acc / scale + offsets
        undone.append(f"INS_ACC{suffix}SCAL, INS_ACC{suffix}OFFS")
    if tcal is not None and np.any(tcal != 0):
        acc = acc + tcal
        undone.append(f"INS_TCAL{n} accelerometer temperature correction")
    return acc


def read_dataflash_columns(path: str | os.PathLike) -> dict[int, tuple[dict, dict, dict]]:
    """Raw gyro (and accelerometer) columns of every IMU instance of a DataFlash log.

    Returns
    -------
    dict
        ``{instance: (data, extra, info)}`` with ``t`` [s], ``gx gy gz`` [rad/s] (raw: see the
        module note), ``ax ay az`` [m/s^2] (rotation undone), ``temp`` [degC]; ``info`` says
        what was undone.
    """
    path = Path(path)
    rows, params, changed = _messages(path)
    if not rows:
        raise InputError(f"{path.name}: no IMU messages in this DataFlash log")
    watched = {"AHRS_ORIENTATION", "INS_GYROFFS_X", "INS_GYROFFS_Y", "INS_GYROFFS_Z"}
    late = sorted({name for name in changed if name in watched or name.startswith(("INS_TCAL", "INS_GYR"))})
    if late:
        warnings.warn(f"{path.name}: {', '.join(late)} changed during the log; the values in force at its first IMU "
                      "sample were used to undo ArduPilot's corrections", DataFlashWarning, stacklevel=2)
    R = _orientation(int(params.get("AHRS_ORIENTATION", 0)))
    out = {}
    for inst, raw in sorted(rows.items()):
        a = np.array(raw, dtype=float)
        a = a[np.argsort(a[:, 0], kind="stable")]
        a = a[np.concatenate(([True], np.diff(a[:, 0]) > 0))]
        gyro, acc, temp = a[:, 1:4] @ R.T, a[:, 4:7] @ R.T, a[:, 7]
        n = inst + 1
        undone = [] if np.allclose(R, np.eye(3)) else [f"AHRS_ORIENTATION {int(params['AHRS_ORIENTATION'])}"]
        tcal = _tcal(params, n, temp)
        if tcal is not None:
            gyro = gyro + tcal
            undone.append(f"INS_TCAL{n} temperature correction")
        offs = "INS_GYROFFS" if n == 1 else f"INS_GYR{n}OFFS"
        offsets = np.array([params.get(f"{offs}_{ax}", 0.0) for ax in "XYZ"])
        if np.any(offsets != 0):
            gyro = gyro + offsets
            undone.append(offs)
        acc = _raw_accel(params, n, acc, temp, undone)
        data = {"t": a[:, 0] * 1e-6, "gx": gyro[:, 0], "gy": gyro[:, 1], "gz": gyro[:, 2],
                "ax": acc[:, 0], "ay": acc[:, 1], "az": acc[:, 2]}
        if np.isfinite(temp).all():
            data["temp"] = temp
        out[inst] = (data, {}, {"imu_number": n, "undone": undone, "duplicates": int(len(raw) - len(a))})
    return out
